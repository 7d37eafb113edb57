"""What a controller receives when it is built (:meth:`nmsm.core.plugin_bases.Controller.from_settings`),
filled by the treatment tool.

Times: the controller's control guesses are wanted at ``collocation_times`` and its state
guesses (controllers with states) at ``node_times`` (s, on the reference time base:
normalized time x ``reference_duration``); references are sampled later at any such times.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import attrs
import numpy as np

from nmsm.errors import InputError

if TYPE_CHECKING:  # named in annotations only
    from nmsm.core.ocp_model import TreatmentModel
    from nmsm.core.splines import ReferenceSplines


@attrs.define
class ControllerSetup:
    """Data shared by the controllers of one problem.

    ``references``: tracked data splines (``coordinates``, ``loads``, ...);
    ``initial_guess``: splines of the initial-guess files by kind (``torqueControls``,
    ``synergyCommands``, ``combinedActivations``, ``loads`` = initial ID, ...);
    ``synergy_weights``: the initial ``synergyWeights.sto`` as (labels of rows, muscle
    labels, (S, M) values) when present; ``osimx``: the parsed ``.osimx`` (or None);
    ``model_file``: the ``.osim`` path (surrogate fitting, muscle parameters).
    ``guess`` / ``guess_times``: splines of the files the *starting point* is read from
    (by default the initial-guess files) and the collocation times on their time base
    (``guess_node_times``: the mesh nodes);
    controllers take their controls' starting values from there and their references
    from ``initial_guess``.
    """

    tool: str
    model: TreatmentModel
    collocation_times: np.ndarray
    reference_duration: float
    references: Mapping[str, ReferenceSplines]
    initial_guess: Mapping[str, ReferenceSplines]
    settings_file: Path | None = None
    model_file: Path | None = None
    osimx: Any = None
    synergy_weights: tuple[tuple[str, ...], tuple[str, ...], np.ndarray] | None = None
    trial_name: str = ""
    guess: Mapping[str, ReferenceSplines] | None = None
    guess_times: np.ndarray | None = None
    node_times: np.ndarray | None = None
    guess_node_times: np.ndarray | None = None
    #: controllers may write files (a fitted surrogate the settings ask to save); False when
    #: nothing is to be written (``write_results=False``, ``nmsm pipeline --check``)
    save_files: bool = True
    extras: dict[str, Any] = attrs.field(factory=dict)

    def starting_splines(self) -> Mapping[str, ReferenceSplines]:
        return self.initial_guess if self.guess is None else self.guess

    def starting_times(self) -> np.ndarray:
        return self.collocation_times if self.guess_times is None else self.guess_times

    def starting_node_times(self) -> np.ndarray:
        """(K + 1,) times (s) of the mesh nodes on the starting point's time base."""
        times = self.node_times if self.guess_node_times is None else self.guess_node_times
        if times is None:
            raise ValueError("the controller setup has no mesh node times")
        return times

    def error(self, message: str, *, element: str | None = None, expected: str | None = None) -> InputError:
        return InputError(message, file=self.settings_file, element=element, expected=expected)


def setting(settings: Any, name: str, default: Any = None) -> Any:
    """``settings.name`` or ``settings[name]`` (attrs objects or mappings), else ``default``."""
    if settings is None:
        return default
    if isinstance(settings, Mapping):
        value = settings.get(name, default)
    else:
        value = getattr(settings, name, default)
    return default if value is None else value


def name_list(value: Any) -> tuple[str, ...]:
    """A space-separated string or a sequence of names -> tuple of names."""
    if value is None:
        return ()
    if isinstance(value, str):
        return tuple(value.split())
    return tuple(str(v) for v in value)
