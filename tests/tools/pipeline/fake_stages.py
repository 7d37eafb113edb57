"""Two fake stage kinds for runner tests: a model *maker* (like JMP) and a *fitter* that
reads the model and a data folder (like MTP). Each run is logged in :data:`CALLS`; a fitter
run can be made to stop (``KeyboardInterrupt``) after writing part of its results, or to fail
as a solver does (``SolverError`` after saving a last iterate)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import attrs

from nmsm.errors import SolverError

from nmsm.io.settings.schema import setting
from nmsm.tools.pipeline.kinds import StageKind, Wire, register_stage_kind, unregister_stage_kind
from nmsm.tools.pipeline.stage_settings import StageSettings

#: (kind code, settings file) of every fake run, in order
CALLS: list[tuple[str, Path]] = []
#: stage codes whose next run stops half-way
STOP_NEXT: set[str] = set()
#: stage codes whose next run fails like a solver, saving ``last_iterate/`` in its results
FAIL_NEXT: set[str] = set()


@attrs.frozen(kw_only=True)
class MakerSettings:
    results_directory: Path = setting("results_directory", kind="path", output=True, default=None, doc="out")
    input_model_file: Path = setting("input_model_file", kind="path", path_kind="file", required=True, doc="in")
    output_model_file: str = setting("output_model_file", kind="text", required=True, doc="name")
    offset: float = setting("offset", kind="number", default=0.0, doc="a number the maker writes")


@attrs.frozen(kw_only=True)
class FitterSettings:
    results_directory: Path = setting("results_directory", kind="path", output=True, default=None, doc="out")
    input_model_file: Path = setting("input_model_file", kind="path", path_kind="file", required=True, doc="in")
    data_directory: Path = setting("data_directory", kind="path", path_kind="dir", empty_is_base=True,
                                   default=None, doc="data")
    degree: int = setting("degree", kind="integer", default=1, doc="an integer the fitter does not use")


def _tool(settings_file: Path) -> tuple[Path, dict[str, str]]:
    from lxml import etree

    root = etree.parse(str(settings_file)).getroot()
    tool = next(iter(root))
    values = {child.tag: (child.text or "").strip() for child in tool}
    folder = Path(settings_file).parent
    return folder, values


def run_maker(settings_file: Path, **options: object) -> str:
    """Writes the model with the offset; an ``<output_model_file>`` ending in ``.bad`` is
    refused as a tool refuses bad input: an InputError at that element's line of the file it read."""
    CALLS.append(("maker", Path(settings_file)))
    folder, values = _tool(settings_file)
    if values["output_model_file"].endswith(".bad"):
        from lxml import etree

        from nmsm.errors import InputError

        element = etree.parse(str(settings_file)).getroot().find("FakeMakerTool/output_model_file")
        raise InputError("the maker cannot write .bad files", file=settings_file, line=element.sourceline,
                         element="<output_model_file>", expected="a .osim name")
    results = folder / values["results_directory"]
    model = Path(values["input_model_file"])
    model = model if model.is_absolute() else folder / model
    text = model.read_text() + f"<!-- offset {values.get('offset', '0')} -->\n"
    results.mkdir(parents=True, exist_ok=True)
    (results / values["output_model_file"]).write_text(text)
    return "made"


def run_fitter(settings_file: Path, **options: object) -> str:
    CALLS.append(("fitter", Path(settings_file)))
    folder, values = _tool(settings_file)
    results = folder / values["results_directory"]
    model = Path(values["input_model_file"])
    model = model if model.is_absolute() else folder / model
    data = Path(values["data_directory"])
    data = data if data.is_absolute() else folder / data
    results.mkdir(parents=True, exist_ok=True)
    (results / "part1.txt").write_text(model.read_text())
    if "fitter" in STOP_NEXT:
        STOP_NEXT.discard("fitter")
        raise KeyboardInterrupt
    if "fitter" in FAIL_NEXT:
        FAIL_NEXT.discard("fitter")
        (results / "part1.txt").unlink()
        (results / "last_iterate").mkdir()
        (results / "last_iterate" / "diagnosis.txt").write_text("did not converge\n")
        raise SolverError("the fit did not converge", last_iterate_path=str(results / "last_iterate"))
    listing = "\n".join(sorted(p.name for p in data.iterdir()))
    (results / "fit_mtp.osimx").write_text(f"<fit>{listing}</fit>\n")
    return "fitted"


def maker_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    return {"model": results / settings.tool.findtext("output_model_file").strip()}


def fitter_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    return {"osimx": results / "fit_mtp.osimx", "mtp_results": results}


MAKER = StageKind("maker", "Fake model maker", "FakeMakerTool", 10, MakerSettings, run_maker, maker_outputs,
                  requires=("model",), produces=("model",), wires=(Wire("model", "input_model_file"),))
FITTER = StageKind("fitter", "Fake fitter", "FakeFitterTool", 40, FitterSettings, run_fitter, fitter_outputs,
                   requires=("model", "data_directory"), produces=("osimx", "mtp_results"),
                   wires=(Wire("model", "input_model_file"), Wire("data_directory", "data_directory")))


@contextlib.contextmanager
def fake_kinds() -> Iterator[None]:
    """Register the fake kinds for the duration of a test."""
    CALLS.clear()
    STOP_NEXT.clear()
    FAIL_NEXT.clear()
    register_stage_kind(MAKER)
    register_stage_kind(FITTER)
    try:
        yield
    finally:
        unregister_stage_kind(MAKER.tool_element)
        unregister_stage_kind(FITTER.tool_element)
