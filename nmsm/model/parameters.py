"""Symbolic model parameters: the quantities Joint Model Personalization optimizes.

A :class:`ModelParameters` object maps model quantities to CasADi SX expressions built
from its own symbols; :class:`~nmsm.model.casadi_model.CasadiModel` uses an expression
wherever one is registered and the file's value elsewhere, so kinematics (marker
positions, body poses, ...) are differentiable w.r.t. the symbols exactly.

Registrable quantities (each call creates symbols for the chosen components and returns
the full expression; unselected components keep the file's value):

* ``frame_translation(frame_path, components)`` / ``frame_orientation(...)``: a
  PhysicalOffsetFrame's translation (m) / body-fixed X-Y-Z orientation (rad) in its
  parent frame. ``joint_frame_translation(joint, "parent" | "child", ...)`` and
  ``joint_frame_orientation`` pick a joint's parent or child offset frame.
* ``marker_location(marker, components)``: location (m) in the marker's frame.
* ``body_scale(body)``: a uniform scale factor (1 = unscaled) of a body. Scaling a body
  scales, as OpenSim's ``Model.scale`` does with uniform factors: translations of offset
  frames attached to it, the translation functions (not the coordinate axes) of
  CustomJoints whose parent frame is on it, locations of markers (and, through
  ``point_in_ground``, any point given in its frame), its centre of mass; its inertia by
  ``s**2`` (mass unchanged) or its mass by ``s**3`` and inertia by ``s**5`` with
  ``scale_mass=True``.

``symbols`` stacks every symbol (a column ``SX``) in creation order, ``names`` labels them
(``"<frame path>/translation/y"``, ``"<marker>/location/x"``, ``"<body>/scale"``), and
``initial_values`` holds the file's values. Example::

    params = ModelParameters(model)
    params.joint_frame_orientation("knee_r", "parent", components=(0, 2))
    params.body_scale("pelvis")
    cm = CasadiModel(model, params)
    f = cm.marker_function()                 # (q, p) -> 3 x n_markers
    f(q_values, params.initial_values)       # the file's model
"""

from __future__ import annotations

from collections.abc import Sequence

import casadi as cs
import numpy as np

from nmsm.errors import ModelError
from nmsm.model.components import Model

_AXES = "xyz"


class ModelParameters:
    """Symbols standing for model quantities (see module docstring)."""

    def __init__(self, model: Model) -> None:
        self.model = model
        self._symbols: list[cs.SX] = []
        self._names: list[str] = []
        self._initial: list[float] = []
        self.translations: dict[str, cs.SX] = {}  # frame path -> 3x1
        self.orientations: dict[str, cs.SX] = {}  # frame path -> 3x1
        self.marker_locations: dict[str, cs.SX] = {}  # marker name -> 3x1
        self.scales: dict[str, cs.SX] = {}  # body name -> scalar
        self.scale_mass = False

    # ------------------------------------------------------------------ symbols
    @property
    def symbols(self) -> cs.SX:
        """All symbols, stacked in creation order (``(n, 1)``)."""
        return cs.vertcat(*self._symbols) if self._symbols else cs.SX(0, 1)

    @property
    def names(self) -> list[str]:
        return list(self._names)

    @property
    def initial_values(self) -> np.ndarray:
        """The file's values of the symbols (``(n,)``)."""
        return np.array(self._initial, dtype=float)

    @property
    def size(self) -> int:
        return len(self._symbols)

    def __len__(self) -> int:
        return self.size

    def _new(self, name: str, value: float) -> cs.SX:
        if name in self._names:
            raise ValueError(f"model parameter '{name}' is already defined")
        sym = cs.SX.sym(name)
        self._symbols.append(sym)
        self._names.append(name)
        self._initial.append(float(value))
        return sym

    def _vector(self, label: str, values: np.ndarray, components: Sequence[int], quantity: str) -> cs.SX:
        components = tuple(components)
        if not components or any(c not in (0, 1, 2) for c in components) or len(set(components)) != len(components):
            raise ValueError(f"components of {label} {quantity} must be distinct indices 0, 1, 2; got {components}")
        parts = []
        for i in range(3):
            if i in components:
                parts.append(self._new(f"{label}/{quantity}/{_AXES[i]}", values[i]))
            else:
                parts.append(cs.SX(float(values[i])))
        return cs.vertcat(*parts)

    # ------------------------------------------------------------------ frames
    def _offset_frame(self, frame_path: str):
        frame = self.model.frames.get(frame_path)
        if frame is None:
            raise ModelError(f"no frame '{frame_path}'", file=self.model.file, expected="a frame path of the model")
        if frame.kind != "offset":
            raise ModelError(
                f"frame '{frame_path}' is a {frame.kind}, not a PhysicalOffsetFrame, so it has no translation or "
                "orientation to personalize", file=self.model.file, element=frame_path,
                expected="a joint whose parent/child frame is a PhysicalOffsetFrame")
        return frame

    def frame_translation(self, frame_path: str, components: Sequence[int] = (0, 1, 2)) -> cs.SX:
        """Make the chosen components of an offset frame's translation symbolic (m)."""
        frame = self._offset_frame(frame_path)
        if frame_path in self.translations:
            raise ValueError(f"translation of '{frame_path}' is already parameterized")
        expr = self._vector(frame_path, frame.translation, components, "translation")
        self.translations[frame_path] = expr
        return expr

    def frame_orientation(self, frame_path: str, components: Sequence[int] = (0, 1, 2)) -> cs.SX:
        """Make the chosen components of an offset frame's orientation symbolic (rad)."""
        frame = self._offset_frame(frame_path)
        if frame_path in self.orientations:
            raise ValueError(f"orientation of '{frame_path}' is already parameterized")
        expr = self._vector(frame_path, frame.orientation, components, "orientation")
        self.orientations[frame_path] = expr
        return expr

    def joint_frame_path(self, joint: str, which: str) -> str:
        if which not in ("parent", "child"):
            raise ValueError(f"which must be 'parent' or 'child', not '{which}'")
        try:
            j = self.model.joint(joint)
        except KeyError as exc:
            raise ModelError(str(exc.args[0]), file=self.model.file, expected="a joint of the model") from None
        return j.parent_frame if which == "parent" else j.child_frame

    def joint_frame_translation(self, joint: str, which: str, components: Sequence[int] = (0, 1, 2)) -> cs.SX:
        """Translation (m) of a joint's parent or child offset frame, chosen components symbolic."""
        return self.frame_translation(self.joint_frame_path(joint, which), components)

    def joint_frame_orientation(self, joint: str, which: str, components: Sequence[int] = (0, 1, 2)) -> cs.SX:
        """Orientation (rad) of a joint's parent or child offset frame, chosen components symbolic."""
        return self.frame_orientation(self.joint_frame_path(joint, which), components)

    # ------------------------------------------------------------------ markers, scales
    def marker_location(self, marker: str, components: Sequence[int] = (0, 1, 2)) -> cs.SX:
        """Location (m) of a marker in its frame, chosen components symbolic."""
        try:
            m = self.model.marker(marker)
        except KeyError as exc:
            raise ModelError(str(exc.args[0]), file=self.model.file, expected="a marker of the model") from None
        if marker in self.marker_locations:
            raise ValueError(f"location of marker '{marker}' is already parameterized")
        expr = self._vector(marker, m.location, components, "location")
        self.marker_locations[marker] = expr
        return expr

    def body_scale(self, body: str) -> cs.SX:
        """A uniform scale factor of ``body`` (initial value 1)."""
        if body not in self.model.bodies:
            raise ModelError(f"no body '{body}'", file=self.model.file, expected="a body of the model")
        if body in self.scales:
            raise ValueError(f"scale of body '{body}' is already parameterized")
        sym = self._new(f"{body}/scale", 1.0)
        self.scales[body] = sym
        return sym

    # ------------------------------------------------------------------ values
    def value_map(self, values: Sequence[float]) -> dict[str, float]:
        """Name -> value for a numeric parameter vector (e.g. an optimization result)."""
        values = np.asarray(values, dtype=float).reshape(-1)
        if values.size != self.size:
            raise ValueError(f"expected {self.size} parameter values, got {values.size}")
        return dict(zip(self._names, values.tolist()))
