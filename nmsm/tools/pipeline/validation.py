"""Checking a stage's settings before anything is run, emptied or written.

The runner validates every selected stage (and ``nmsm pipeline --check`` every enabled one)
before it touches the results tree, so a typo in a later stage's settings stops the run
before an earlier stage runs and before the stage's finished results are emptied.

A stage's settings are validated as the runner will hand them to its tool (inputs rewired,
paths absolute), read by the stage kind's settings class from the *user's* tree: the
elements keep the line numbers of the file they were written in, so an error names the
stage's settings file (or the pipeline file, for embedded settings) and the line there, not
the copy the runner writes into the results tree. Paths are not required to exist yet (an
earlier stage makes them); the tool checks them when it runs.

Beyond what the settings class checks (elements, numbers, required values), a kind may name
a ``validate`` function (:class:`~nmsm.tools.pipeline.kinds.StageKind`) taking the parsed
settings: the built-in ones below build every enabled cost and constraint term from the
term registry for the tool that will evaluate it (unknown and disallowed term types,
unreadable term fields), and
for TO/VO/DO read the solver settings file and the DO's model functions.

``nmsm pipeline --check`` also *binds* the terms of every stage that would run
(:func:`bind_stage`, the kind's ``bind`` function): each term is checked against the
stage's model and data as the tool checks it before solving (a coordinate, load, muscle,
control or marker the model or controllers lack; a plugin term's own ``bind``), without
solving and without OpenSim. For TO, VO and DO (:func:`bind_treatment`) that is the tool's
own :func:`~nmsm.tools.treatment.tool.prepare`: model, data files, controllers, then every
term bound while the problem is assembled (0.2-3 s a stage on the kicking tutorials). A stage whose model or data an
earlier stage of the run makes is bound when it runs (the runner says so); JMP, MTP, NCP and
GCP bind their terms to the problem they build from their data (MTP after its length
initialization), so their terms are bound when they run too.
"""

from __future__ import annotations

import warnings
from typing import Any

from nmsm.errors import InputError
from nmsm.io.settings.document import SettingsDocument
from nmsm.io.settings.schema import read_block
from nmsm.tools.pipeline.pipeline_file import StageSpec
from nmsm.tools.pipeline.stage_settings import StageSettings


def parse_settings(settings: StageSettings) -> Any:
    """The settings object the stage's settings class reads from ``settings`` (errors at the
    file and line the elements were written in; paths need not exist)."""
    doc = SettingsDocument(path=settings.origin, root=settings.root, tool_element=settings.tool,
                           version=settings.root.get("Version", ""), check_paths=False)
    cls = settings.settings_class
    reader = getattr(cls, "from_document", None)
    return reader(doc) if reader is not None else read_block(cls, doc, doc.tool_element)


def validate_stage(stage: StageSpec, settings: StageSettings, *, quiet: bool = True) -> None:
    """:class:`InputError` when the stage's tool would refuse ``settings`` (see module
    docstring). ``quiet``: hide the settings' warnings (the tool repeats them when it runs)."""
    with warnings.catch_warnings():
        if quiet:
            warnings.simplefilter("ignore")
        parsed = parse_settings(settings)
        check = stage.kind.load_validate()
        if check is not None:
            check(parsed)


def bind_stage(stage: StageSpec, settings: StageSettings) -> None:
    """Bind the stage's terms to its model and data (its kind's ``bind``, module docstring);
    :class:`InputError` (or the term's :class:`~nmsm.errors.NmsmError`) at the term's
    settings file and line. Warnings are hidden (the tool repeats them when it runs)."""
    bind = stage.kind.load_bind()
    if bind is None:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bind(parse_settings(settings))


# ---- the built-in kinds' checks ----------------------------------------------------------------
def _terms(specs: Any, tool: str) -> None:
    from nmsm.core.registry import build_terms

    build_terms(list(specs or ()), tool)


def _mtli_terms(settings: Any) -> None:
    mtli = getattr(settings, "muscle_tendon_length_initialization", None)
    if mtli is not None and mtli.is_enabled:
        _terms(mtli.cost_terms, "MTLI")


def mtp(settings: Any) -> None:
    """MTP: each task's terms, synergy extrapolation's and MTLI's when enabled."""
    for task in settings.tasks:
        _terms(task.cost_terms, "MTP")
    if settings.synergy_extrapolation.is_enabled:
        _terms(settings.synergy_extrapolation.cost_terms, "SynX")
    _mtli_terms(settings)


def ncp(settings: Any) -> None:
    """NCP: its terms and MTLI's when enabled."""
    _terms(settings.cost_terms, "NCP")
    _mtli_terms(settings)


def gcp(settings: Any) -> None:
    """GCP: each task's terms."""
    for task in settings.tasks:
        _terms(task.cost_terms, "GCP")


def treatment(settings: Any) -> None:
    """TO, VO, DO: cost and constraint terms, the solver settings file, DO's model functions."""
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.solver import OptimalControlSolverSettings

    _terms(settings.cost_terms, settings.tool_code)
    _terms(settings.constraint_terms, settings.tool_code)
    solver = settings.optimal_control_solver_settings_file
    if solver is None or not solver.is_file():
        raise InputError(f"the solver settings file {solver} does not exist", file=settings.settings_file,
                         element="<optimal_control_solver_settings_file>",
                         expected="an existing solver settings file (nmsm print-xml solver)")
    OptimalControlSolverSettings.from_document(read_settings_document(solver))
    if settings.tool_code == "DO":
        from nmsm.tools.treatment.design import model_modifiers

        model_modifiers(settings)


def bind_treatment(settings: Any) -> None:
    """TO, VO, DO: the tool's own preparation (model, data, controllers; every term bound
    while the problem is assembled), not solved."""
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.solver import OptimalControlSolverSettings
    from nmsm.tools.treatment.tool import TreatmentOptions, prepare

    solver = OptimalControlSolverSettings.from_document(
        read_settings_document(settings.optimal_control_solver_settings_file))
    declare_extra = None
    if settings.tool_code == "DO":
        from nmsm.tools.treatment.design import design_extras

        declare_extra = design_extras(settings)
    prepare(settings, solver, TreatmentOptions(parallel=1, write_results=False), declare_extra=declare_extra)
