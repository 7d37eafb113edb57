"""``nmsm example --batch``: the synthetic subject's Design Optimization swept on Dask.

In ``<folder>/batch/`` (the subject generated into ``<folder>`` as ``nmsm example`` does):

* ``pipeline.xml``: the example's pipeline up to the Verification Optimization;
* ``do.xml``: the example's DO with a second model function, every synergy's activation
  scaled (``scaleSynergyActivations``), reading the pipeline run's results;
* ``batch.xml``: the run ``subject`` (that pipeline) and the sweep ``do`` of the DO over
  :data:`STRENGTHS` (the plantarflexors' strength) x :data:`SYNERGY_SCALES`, every variant
  warm-started from the pipeline's VO (``subject/vo``);

then runs the batch into ``<folder>/batch/results`` (:func:`nmsm.batch.run`) and writes its
report (``report.html`` there).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from nmsm.examples.subject_settings import PLANTARFLEXORS, STAGES

#: plantarflexor strength (max isometric force scale) of the sweep's 5 weakness levels
STRENGTHS = (0.5, 0.6, 0.7, 0.8, 0.9)
#: synergy activation scales of the sweep (1: the VO's drive; more: a stronger drive)
SYNERGY_SCALES = (1.0, 1.1)
PIPELINE_RUN = "subject"
SWEEP = "do"
RESULTS = "results"
_STRENGTH_TERM = "RCNLParameterTermSet/RCNLParameterTerm[type='max_isometric_force_scale']"
_SCALE_TERM = "RCNLParameterTermSet/RCNLParameterTerm[type='synergy_activation_scale']"


def _parameter(name: str, term: str, values: tuple[float, ...]) -> str:
    elements = "".join(f"\n          <element>{term}/{field}</element>"
                       for field in ("initial_values", "lower_bounds", "upper_bounds"))
    return f"""
        <Parameter name="{name}">{elements}
          <values>{" ".join(f"{v:g}" for v in values)}</values>
        </Parameter>"""


def batch_xml(strengths: tuple[float, ...] = STRENGTHS, synergy_scales: tuple[float, ...] = SYNERGY_SCALES) -> str:
    """The text of ``batch.xml`` (module docstring)."""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- The built-in example's batch (docs/batch.md): the DO swept over the plantarflexors'
     ({", ".join(PLANTARFLEXORS)}) strength and the synergies' activation scale, from one VO. -->
<NMSMPipelineDocument Version="1.5.3">
  <BatchTool name="synthetic subject: weakness x synergy drive">
    <results_directory>{RESULTS}</results_directory>
    <RunList>
      <Run name="{PIPELINE_RUN}" patient="synthetic">
        <pipeline_file>pipeline.xml</pipeline_file>
      </Run>
      <Sweep name="{SWEEP}" patient="synthetic">
        <settings_file>do.xml</settings_file>
        <warm_start_from>{PIPELINE_RUN}/vo</warm_start_from>{_parameter("strength", _STRENGTH_TERM, strengths)}{
        _parameter("synergy_scale", _SCALE_TERM, synergy_scales)}
      </Sweep>
    </RunList>
  </BatchTool>
</NMSMPipelineDocument>
"""


def _in_pipeline_run(text: str) -> str:
    """``text`` with the example's ``results`` folder (``<results_directory>results</...>``,
    ``results/<stage>`` of later stages) moved to the pipeline run's folder in the batch's results."""
    return text.replace(">results/", f">{RESULTS}/{PIPELINE_RUN}/").replace(">results<", f">{RESULTS}/{PIPELINE_RUN}<")


def write_example_batch(folder: str | os.PathLike[str], *, strengths: tuple[float, ...] = STRENGTHS,
                        synergy_scales: tuple[float, ...] = SYNERGY_SCALES, log: Callable[[str], None] | None = None,
                        ) -> Path:
    """Generate the subject into ``folder`` unless it is there, write ``<folder>/batch/``'s
    files (module docstring); returns the batch file."""
    from nmsm.examples.subject import make_subject, subject_in
    from nmsm.examples.subject_settings import treatment_xml, write_example_pipeline
    from nmsm.examples.subject_truth import N_SYNERGIES

    folder = Path(folder)
    subject = subject_in(folder) or make_subject(folder, log=log)
    batch = folder / "batch"
    pipeline = write_example_pipeline(subject, batch, n_synergies=N_SYNERGIES,
                                      stages=STAGES[: STAGES.index("vo") + 1])
    pipeline.write_text(_in_pipeline_run(pipeline.read_text(encoding="utf-8")), encoding="utf-8")
    do = _in_pipeline_run(treatment_xml("do", subject, batch, N_SYNERGIES, synergy_scale=synergy_scales[0]))
    (batch / "do.xml").write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<NMSMPipelineDocument Version="1.5.3">
  {do}
</NMSMPipelineDocument>
""", encoding="utf-8")
    path = batch / "batch.xml"
    path.write_text(batch_xml(strengths, synergy_scales), encoding="utf-8")
    return path


def run_example_batch(folder: str | os.PathLike[str] = "nmsm_example", *, workers: int | None = None,
                      rebuild: bool = False, log: Callable[[str], None] | None = print, **options: Any):
    """Write (:func:`write_example_batch`) and run the example's batch; returns the
    :class:`~nmsm.batch.execute.BatchRun`. ``rebuild``: as ``nmsm example --rebuild``."""
    from nmsm.batch import run
    from nmsm.examples.example_run import prepare_example_folder
    from nmsm.report.html import write_report

    folder = prepare_example_folder(folder, rebuild=rebuild)
    batch = write_example_batch(folder, log=log)
    outcome = run(batch, workers=workers, log=log, **options)
    write_report(outcome.spec.results_directory, title="nmsm example --batch: synthetic subject's DO sweep", log=None)
    return outcome
