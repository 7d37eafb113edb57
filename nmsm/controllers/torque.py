"""Torque controller (``<RCNLTorqueController>``): one torque control per listed coordinate.

Settings: ``coordinate_list`` (coordinates actuated), ``torque_controls_range_scale_factor``
[1], ``torque_controls_minimum_range`` [0]. Each control ``u_c`` (N·m, or N for
translational coordinates) is applied as a generalized force on ``c``. Bounds follow the
range rule on the tracked inverse-dynamics load of ``c``; the guess and the
``controller_tracking`` reference are the initial guess's ``<trial>_torqueControls.sto``
column ``c`` when present, else the initial inverse dynamics.

Differs from the original: in TO the original's reference for controller terms on torque
controls is 0 (it never splines the initial torque controls there); here it is the initial
guess in TO, VO and DO alike.

Control names accepted in ``<controller_list>``: ``c``, ``c_moment``/``c_force``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from nmsm.core.plugin_bases import ControlSpec, Controller
from nmsm.core.bounds import RangeRule, range_bounds
from nmsm.interop.moco_trajectory import MocoColumns, torque_actuator_path
from nmsm.core.controller_setup import ControllerSetup, name_list, setting

PREFIX = "torque:"


class TorqueController(Controller):
    """Torque actuators on listed coordinates (controls in N·m or N)."""

    type: ClassVar[str] = "torque"
    settings_element: ClassVar[str] = "RCNLTorqueController"

    def __init__(self, coordinates: tuple[str, ...], setup: ControllerSetup, rule: RangeRule) -> None:
        self.coordinates = coordinates
        self.setup = setup
        self.rule = rule
        model = setup.model
        element = "<RCNLTorqueController><coordinate_list>"
        if not coordinates:
            raise setup.error("the torque controller lists no coordinates", element=element,
                              expected="a space-separated list of model coordinates")
        for c in coordinates:
            if c not in model.coordinate_names:
                raise setup.error(f"coordinate '{c}' is not in the model", element=element,
                                  expected="one of " + ", ".join(model.coordinate_names))
        self._load_labels = {c: model.load_label(c) for c in coordinates}
        loads = setup.references.get("loads")
        self._bounds: dict[str, tuple[float, float]] = {}
        for c in coordinates:
            label = self._find(loads, c)
            if label is None:
                raise setup.error(
                    f"torque-controlled coordinate '{c}' has no column in the tracked inverse dynamics "
                    "(IDData), needed for its control bounds", element=element,
                    expected=f"a column '{self._load_labels[c]}' in the tracked IDData file"
                             + (f" {loads.source}" if loads is not None and getattr(loads, "source", None) else ""))
            lo, hi = range_bounds(loads.values(loads.time, 0, [label]), rule)
            self._bounds[c] = (float(lo[0]), float(hi[0]))
        self._reference = {}
        initial = setup.initial_guess.get("torqueControls")
        fallback = setup.initial_guess.get("loads") or loads
        for c in coordinates:
            label = self._find(initial, c)
            if label is not None:
                self._reference[c] = (initial, label)
            else:
                self._reference[c] = (fallback, self._find(fallback, c))

    @staticmethod
    def _find(splines: Any, coordinate: str) -> str | None:
        if splines is None:
            return None
        for label in (coordinate, f"{coordinate}_moment", f"{coordinate}_force"):
            if splines.has(label):
                return label
        return None

    @classmethod
    def from_settings(cls, settings: Any, setup: ControllerSetup) -> TorqueController:
        coords = name_list(setting(settings, "coordinate_list"))
        rule = RangeRule(float(setting(settings, "torque_controls_range_scale_factor", 1.0)),
                         float(setting(settings, "torque_controls_minimum_range", 0.0)))
        return cls(coords, setup, rule)

    # ---- declaration -------------------------------------------------------------------
    def _starting_values(self, c: str) -> np.ndarray:
        splines = self.setup.starting_splines()
        for kind in ("torqueControls", "loads"):
            label = self._find(splines.get(kind), c)
            if label is not None:
                return splines[kind].values(self.setup.starting_times(), 0, [label]).ravel()
        return self.control_reference(PREFIX + c, self.setup.collocation_times).ravel()

    def control_specs(self) -> list[ControlSpec]:
        specs = []
        for c in self.coordinates:
            lo, hi = self._bounds[c]
            guess = self._starting_values(c)
            specs.append(ControlSpec(PREFIX + c, c, lo, hi, guess, aliases=(c, self._load_labels[c])))
        return specs

    def controlled_coordinates(self) -> tuple[str, ...]:
        return self.coordinates

    # ---- quantities ----------------------------------------------------------------------
    def applied_loads(self, view: Any) -> Mapping[str, Any]:
        return {c: view.control(PREFIX + c) for c in self.coordinates}

    def control_reference(self, name: str, times: np.ndarray) -> np.ndarray:
        c = name[len(PREFIX):] if name.startswith(PREFIX) else name
        if c not in self._reference:
            raise KeyError(f"torque controller has no control '{name}'")
        splines, label = self._reference[c]
        return splines.values(np.asarray(times, dtype=float), 0, [label])

    # ---- outputs -------------------------------------------------------------------------
    def output_tables(self, solution: Any) -> dict[str, tuple[tuple[str, ...], np.ndarray]]:
        values = np.hstack([solution.control(PREFIX + c) for c in self.coordinates])
        return {f"{solution.trial_name}_torqueControls.sto": (self.coordinates, values)}

    def moco_columns(self, solution: Any) -> MocoColumns:
        return MocoColumns(controls={torque_actuator_path(c): solution.control(PREFIX + c) for c in self.coordinates})
