"""Where each kind of stage leaves its outputs, found after its tool returned.

Each function takes the stage's :class:`~nmsm.tools.pipeline.stage_settings.StageSettings`
and its results folder and returns ``{artifact: path}``; an expected output that is not
there is an :class:`~nmsm.errors.InputError` naming the folder and the file.
"""

from __future__ import annotations

from pathlib import Path

from nmsm.errors import InputError
from nmsm.io.paths import normalize_separators
from nmsm.tools.pipeline.stage_settings import StageSettings


def _one(folder: Path, pattern: str, what: str) -> Path:
    found = sorted(folder.glob(pattern))
    if len(found) != 1:
        listing = ", ".join(p.name for p in found) or "none"
        raise InputError(f"the stage finished but {len(found)} files match '{pattern}' ({listing})", file=folder,
                         expected=f"exactly one {what}")
    return found[0]


def jmp_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    name = Path(normalize_separators(settings.tool.findtext("output_model_file", ""))).name
    model = results / name
    if not model.is_file():
        raise InputError(f"the stage finished but its model '{name}' is missing", file=results,
                         expected="the personalized model named by <output_model_file>")
    return {"model": model}


def analysis_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    if not (results / "IKData").is_dir():
        raise InputError("the stage finished but wrote no IKData folder", file=results, expected="IKData/")
    return {"motion_data": results}


def preprocess_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    if not (results / "IDData").is_dir() and not (results / "IKData").is_dir():
        raise InputError("the stage finished but wrote no IKData/IDData folder", file=results,
                         expected="a data folder (IKData, IDData, ...)")
    return {"data_directory": results}


def mtp_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    return {"osimx": _one(results, "*_mtp.osimx", "personalized .osimx"), "mtp_results": results}


def ncp_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    return {"osimx": _one(results, "*_ncp.osimx", "personalized .osimx"), "ncp_results": results}


def gcp_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    return {"osimx": _one(results, "*_gcp.osimx", "personalized .osimx"), "gcp_results": results}


def surrogate_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    if not (results / "MAData").is_dir():
        raise InputError("the stage finished but wrote no MAData folder", file=results, expected="MAData/")
    return {"surrogate_data": results}


def treatment_outputs(settings: StageSettings, results: Path) -> dict[str, Path]:
    if not any(results.glob("*_states.sto")):
        raise InputError("the stage finished but wrote no <trial>_states.sto", file=results,
                         expected="the solution's states file")
    return {"treatment_results": results}
