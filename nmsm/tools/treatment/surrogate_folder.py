"""A treatment settings file whose surrogate data folder does not exist.

:func:`check_surrogate_data_folder` stops before anything is built with an ``InputError``
that names the settings file, the line and ``<surrogate_model_data_directory>`` and prints,
on the message's last line, the ``nmsm surrogate`` command that makes the folder from the settings' own model
(``input_model_file``), motion (``tracked_quantities_directory``/``IKData/<trial_name>``)
and coordinates (``surrogate_model_coordinate_list``)::

    nmsm surrogate --model M.osim --motion TRACKED/IKData/TRIAL.sto --coordinates c1 c2 ...
        --degree D --write-samples FOLDER -o SETTINGS_FOLDER/surrogateMuscles.json

``FOLDER`` is where the settings look first (relative paths: the settings file's folder);
``-o`` is where ``<load_surrogate_model>`` reads a fitted surrogate from.
"""

from __future__ import annotations

import shlex
from pathlib import Path

from nmsm.errors import InputError
from nmsm.io.settings.document import SettingsDocument
from nmsm.model.surrogate_fitting import DEFAULT_FILE_NAME, surrogate_model_path

#: controllers with a surrogate data folder
CONTROLLERS = ("RCNLSynergyController", "RCNLMuscleController")
ELEMENT = "surrogate_model_data_directory"


def _motion(doc: SettingsDocument) -> Path:
    """The tracked motion (``IKData/<trial_name>``) as the settings name it; the expected
    ``.sto`` path when the folder or file is missing too."""
    from nmsm.io.trials import find_trial_file

    tool = doc.tool_element
    tracked = doc.resolved_path(tool, "tracked_quantities_directory", kind="dir", must_exist=False)
    trial = doc.text(tool, "trial_name", "") or "TRIAL"
    folder = (Path(tracked).resolve() if tracked is not None else Path(doc.path).resolve().parent) / "IKData"
    try:
        return find_trial_file(folder, trial)
    except (InputError, OSError):
        return folder / f"{trial}.sto"


def surrogate_command(doc: SettingsDocument, controller: object, folder: Path) -> str:
    """The ``nmsm surrogate`` command making ``folder`` for ``controller`` (module docstring)."""
    tool = doc.tool_element
    model = doc.resolved_path(tool, "input_model_file", kind="file", must_exist=False)
    coordinates = doc.names(controller, "surrogate_model_coordinate_list") or ("COORDINATES",)
    degree = doc.integer(controller, "surrogate_model_polynomial_degree", 5)
    fitted = surrogate_model_path(doc.path, doc.text(controller, "surrogate_model_file_name", DEFAULT_FILE_NAME))
    words = ["nmsm", "surrogate", "--model", str(Path(model).resolve() if model is not None else "MODEL.osim"),
             "--motion", str(_motion(doc)), "--coordinates", *coordinates, "--degree", str(degree),
             "--write-samples", str(folder), "-o", str(fitted)]
    return shlex.join(words)


def check_surrogate_data_folder(doc: SettingsDocument) -> None:
    """``InputError`` with the making command when a controller's surrogate data folder is
    named but does not exist (module docstring)."""
    tool = doc.tool_element
    for name in CONTROLLERS:
        controller = doc.find(tool, name)
        if controller is None or not (doc.text(controller, ELEMENT, "") or "").strip():
            continue
        try:
            doc.resolved_path(controller, ELEMENT, kind="dir")
            continue
        except InputError as missing:
            folder = doc.resolved_path(controller, ELEMENT, kind="dir", must_exist=False)
            command = surrogate_command(doc, controller, Path(folder).resolve())
            raise InputError(
                f"{missing.detail}: no surrogate samples (IKData/, MAData/); make them from this file's "
                f"model, motion and coordinates with:\n  {command}",
                file=missing.file, line=missing.line, element=f"<{ELEMENT}>") from None
