"""Force-plate corrections: ``electrical_center_regularization``,
``force_plate_rotation_regularization``."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.terms.gcp._base import FootCostTerm

_AXES = "xyz"


def _check_axes(instance: Any, attribute: Any, value: str) -> None:
    letters = [c for c in value.lower() if not c.isspace() and c != ","]
    if not letters or any(c not in _AXES for c in letters) or len(set(letters)) != len(letters):
        raise ValueError(f"<axes> must name distinct axes among x, y, z (got '{value}')")


@attrs.frozen(kw_only=True)
class ElectricalCenterRegularization(FootCostTerm):
    """The electrical-center shift (m) along ``axes`` (default all three)."""

    type: ClassVar[str] = "electrical_center_regularization"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    axes: str = attrs.field(default="xyz", validator=_check_axes)

    @property
    def axis_indices(self) -> list[int]:
        return [_AXES.index(c) for c in self.axes.lower() if c in _AXES]

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        shift = ctx.electrical_center_shift(foot)
        return shift[self.axis_indices]


@attrs.frozen(kw_only=True)
class ForcePlateRotationRegularization(FootCostTerm):
    """The force-plate rotation about ground y (rad)."""

    type: ClassVar[str] = "force_plate_rotation_regularization"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.plate_rotation(foot)
