"""Surrogate settings of a synergy-driven treatment optimization (``RCNLSynergyController``).

Elements read (the original's settings; defaults in brackets):
``surrogate_model_coordinate_list`` (required), ``surrogate_model_data_directory``
(required), ``epsilon`` [1e-4], ``surrogate_model_polynomial_degree`` [5],
``load_surrogate_model`` [false], ``save_surrogate_model`` [false],
``surrogate_model_file_name`` [surrogateMuscles.mat]. The model is the tool's
``input_model_file``. The result, a :class:`~nmsm.model.surrogate_fitting.SurrogateSettings`,
is what :func:`~nmsm.model.surrogate_fitting.surrogate_from_settings` fits or loads; the
fitted model is kept as JSON next to the settings file
(:func:`~nmsm.model.surrogate_fitting.surrogate_model_path`).
``perform_latin_hypercube_sampling`` and its two options are parsed by the original
but unused by its treatment tools; nmsm ignores them with a warning when true.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

from nmsm.model.surrogate_fitting import DEFAULT_FILE_NAME, SurrogateSettings, surrogate_model_path

if TYPE_CHECKING:
    from nmsm.io.settings.document import SettingsDocument

CONTROLLER = "RCNLSynergyController"


def surrogate_settings_from_document(doc: SettingsDocument) -> SurrogateSettings:
    """The surrogate settings of a TO/VO/DO document (its ``RCNLSynergyController``)."""
    tool = doc.tool_element
    controller = doc.find(tool, CONTROLLER)
    if controller is None:
        raise doc.error(tool, f"no <{CONTROLLER}> in <{tool.tag}>", element=f"<{CONTROLLER}>",
                        expected=f"a <{CONTROLLER}> holding the surrogate model settings")
    model_holder = doc.find(tool, "input_model_file")
    if model_holder is None:
        raise doc.error(tool, "required element <input_model_file> is missing", element="<input_model_file>",
                        expected="the model file")
    model_file = doc.resolved_path(model_holder.getparent(), "input_model_file", required=True, kind="file")
    data = doc.resolved_path(controller, "surrogate_model_data_directory", required=True, kind="dir")
    coords = tuple(doc.names(controller, "surrogate_model_coordinate_list", required=True))
    degree = doc.integer(controller, "surrogate_model_polynomial_degree", 5)
    if degree < 0:
        raise doc.error(doc.child(controller, "surrogate_model_polynomial_degree"), f"degree {degree} is negative",
                        expected="an integer >= 0")
    epsilon = doc.number(controller, "epsilon", 1e-4)
    if doc.boolean(controller, "perform_latin_hypercube_sampling", False):
        warnings.warn(f"{doc.path}: <perform_latin_hypercube_sampling> is ignored (unused by the original's "
                      "treatment tools); sample with `nmsm surrogate --motion ...` instead", stacklevel=2)
    model_path = surrogate_model_path(doc.path, doc.text(controller, "surrogate_model_file_name", DEFAULT_FILE_NAME))
    return SurrogateSettings(
        model_file=Path(model_file),
        data_directory=Path(data),
        coordinates=coords,
        epsilon=float(epsilon),
        degree=int(degree),
        load=bool(doc.boolean(controller, "load_surrogate_model", False)),
        save=bool(doc.boolean(controller, "save_surrogate_model", False)),
        model_path=model_path,
        settings_file=Path(doc.path),
    )


def read_surrogate_settings(path: str | os.PathLike[str]) -> SurrogateSettings:
    """Read the surrogate settings from a TO/VO/DO settings file."""
    from nmsm.io.settings.reader import read_settings_document

    return surrogate_settings_from_document(read_settings_document(path))
