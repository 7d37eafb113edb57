"""What an MTP run read before optimizing (:class:`MtpSetup`) and what it produced
(:class:`MtpOutcome`, one :class:`TaskOutcome` per task): made by :mod:`nmsm.tools.mtp.run`,
read by its console summary (:mod:`nmsm.tools.mtp.summary`) and by callers of ``run_settings``."""

from __future__ import annotations

from pathlib import Path

import attrs

from nmsm.core.convergence import ConvergenceHistory
from nmsm.core.term import CostTerm
from nmsm.io.osimx import OsimxModel
from nmsm.io.settings.mtp import MuscleTendonPersonalizationSettings
from nmsm.tools.mtp.evaluation import ModeledValues
from nmsm.tools.mtp.mtli import MtliResult
from nmsm.tools.mtp.mtli_model import PassiveTrial
from nmsm.tools.mtp.muscles import MuscleParameters
from nmsm.tools.mtp.problem import MtpData, MtpState, TaskSettings


@attrs.frozen(eq=False)
class MtpSetup:
    """Everything read from the settings, model and data, before any optimization."""

    settings: MuscleTendonPersonalizationSettings
    model_name: str
    input_osimx: OsimxModel | None
    model_muscles: MuscleParameters
    data: MtpData
    passive_trials: tuple[PassiveTrial, ...]
    tasks: tuple[TaskSettings, ...]
    mtli_terms: tuple[CostTerm, ...]


@attrs.frozen(eq=False)
class TaskOutcome:
    index: int
    cost: float
    term_costs: dict[str, float]
    status: str
    iterations: int
    wall_time: float
    history: ConvergenceHistory | None = None
    converged: bool = True


@attrs.frozen(eq=False)
class MtpOutcome:
    """Final parameters, modeled values and where results went.

    ``start_data``: the data the first task started from (muscles after MTLI);
    ``data``: with the final l_o, l_ts (scale factors absorbed, ``state`` scales are 1).
    """

    setup: MtpSetup
    start_data: MtpData
    data: MtpData
    state: MtpState
    mtli: MtliResult | None
    tasks: tuple[TaskOutcome, ...]
    plain: ModeledValues
    synx: ModeledValues | None
    results_directory: Path
    wall_time: float

    @property
    def final_muscles(self) -> MuscleParameters:
        return self.data.muscles
