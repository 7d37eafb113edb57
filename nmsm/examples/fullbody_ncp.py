"""Synergies of the full-body stress case: NCP on the static-optimization activations.

:func:`write_muscle_osimx` writes the case's personalized muscles (tendon slack lengths of
:func:`nmsm.examples.fullbody_activations.tendon_slack_lengths`) as an ``.osimx``;
:func:`ncp_settings_xml` the NCP settings: both legs' 43 muscles (ForceSet groups
``right_leg`` and ``left_leg``) with ``synergies`` synergies each, tracking the ID moments of
the 14 leg coordinates and the synthetic activations (``mtp_results_directory``). NCP's
``.osimx`` output then holds the muscles and the ``RCNLSynergySet``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from nmsm.examples import fullbody_data as fd
from nmsm.examples.subject_settings import _relative, _term
from nmsm.io.osimx import OsimxModel, OsimxMuscle, write_osimx

#: NCP tracking tolerances: moments (N·m) and activations (-)
MOMENT_ERROR = 1.0
ACTIVATION_ERROR = 0.02


def write_muscle_osimx(path: str | os.PathLike[str], model_file: str | os.PathLike[str],
                       tendon_slack_lengths: Mapping[str, float]) -> Path:
    """An ``.osimx`` with the tendon slack lengths (m) of ``tendon_slack_lengths``."""
    muscles = {name: OsimxMuscle(name, tendon_slack_length=float(v)) for name, v in tendon_slack_lengths.items()}
    return write_osimx(path, OsimxModel(name=Path(model_file).stem, associated_osim_model=str(model_file),
                                        muscles=muscles))


def ncp_settings_xml(folder: Path, *, model: Path, osimx: Path, data: Path, activations: Path, results: Path,
                     synergies: int) -> str:
    """NCP settings (paths relative to ``folder``, where the file goes)."""
    r = lambda p: _relative(p, folder)  # noqa: E731
    groups = "".join(f"<RCNLSynergy><muscle_group_name>{fd.LEG_GROUPS[s]}</muscle_group_name>"
                     f"<num_synergies>{synergies}</num_synergies></RCNLSynergy>" for s in fd.SIDES)
    terms = _term("moment_tracking", MOMENT_ERROR) + _term("activation_tracking", ACTIVATION_ERROR)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- Full-body gait case: NCP of both legs on static-optimization activations (synthetic). -->
<NMSMPipelineDocument Version="1.5.3">
  <NeuralControlPersonalizationTool>
    <results_directory>{r(results)}</results_directory>
    <input_model_file>{r(model)}</input_model_file>
    <input_osimx_file>{r(osimx)}</input_osimx_file>
    <data_directory>{r(data)}</data_directory>
    <coordinate_list>{" ".join(fd.muscle_coordinates())}</coordinate_list>
    <activation_muscle_groups/>
    <normalized_fiber_length_muscle_groups/>
    <MuscleTendonLengthInitialization><is_enabled>false</is_enabled></MuscleTendonLengthInitialization>
    <mtp_results_directory>{r(activations)}</mtp_results_directory>
    <RCNLCostTermSet>{terms}</RCNLCostTermSet>
    <RCNLSynergySet>{groups}</RCNLSynergySet>
  </NeuralControlPersonalizationTool>
</NMSMPipelineDocument>
"""
