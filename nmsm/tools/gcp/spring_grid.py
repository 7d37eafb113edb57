"""Where the contact springs sit: a grid over the sole placed from the foot markers, or the
locations of an existing ``.osimx``.

The original pipeline keeps grid points inside a shoe outline (``shoeCurve.mat``), which
is not distributed. nmsm places the grid as follows (all in the hindfoot frame with the
toes joint at 0, heights ignored):

1. Foot axis ``u``: unit vector from the heel marker to the toe marker in the hindfoot
   x-z plane; ``n`` the in-plane normal pointing from the medial to the lateral marker.
   Foot length ``l = (toe - heel) . u``, width ``w = (lateral - medial) . n``.
2. Normalized grid (``W = grid_width`` across, ``H = grid_height`` along)::

       a_i = (i - 1/2) / W     (0 medial .. 1 lateral)
       b_j = (j - 1/2) / H     (0 heel   .. 1 toe)

   the point ``heel + b l u + (medial . n + a w - heel . n) n``: rows run from the heel
   marker to the toe marker, columns from the medial to the lateral marker line.
3. A point is kept when it lies inside the sole outline :data:`SOLE_OUTLINE`: for each
   ``b`` an interval ``[a_min(b), a_max(b)]`` (linear in ``b`` between the table's rows):
   a narrower heel, the medial arch cut, the full width at the ball of the foot (where the
   medial and lateral forefoot markers are), toes tapering on the lateral side. The rows
   cover the whole sole from the heel to the toe marker. About 85 % of the grid is kept
   (5 x 11: 47 springs, 8 x 15: 106, 5 x 15: 65; the original's shoe outline keeps 37, 83
   and 55 and starts about 10 % of the foot length ahead of the heel marker; a tighter
   outline of that kind fitted the tutorial worse, docs/developing.md, "GCP: measurements").
4. Height: every spring sits at ``y = -(hindfoot origin height in the model's default
   pose)`` in the hindfoot frame, i.e. on the floor in the default pose.
5. Points beyond the toes joint axis (on the toe side of the axis line in the x-z plane)
   belong to the toes body and are expressed in its frame; the others to the hindfoot.

Springs are named ``spring_marker_<i>`` in column-major order (medial column first, heel
to toe within a column). Both feet get the same count and matching indices because the
grid is defined in medial/lateral, heel/toe coordinates.
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.tools.gcp.foot_model import FootModel

#: sole outline: rows ``(b, a_min, a_max)`` in normalized grid coordinates (module docstring)
SOLE_OUTLINE = np.array([
    (0.00, 0.20, 0.80),
    (0.15, 0.10, 0.90),
    (0.35, 0.15, 0.95),
    (0.55, 0.00, 1.00),
    (0.80, 0.00, 1.00),
    (1.00, 0.00, 0.75),
])


@attrs.frozen
class SpringLayout:
    """Springs of one foot: ``bodies`` (n,), ``locations`` (n, 3) m in those bodies' frames."""

    bodies: tuple[str, ...]
    locations: np.ndarray
    names: tuple[str, ...]

    @property
    def n_springs(self) -> int:
        return len(self.bodies)

    def points(self) -> list[tuple[str, np.ndarray]]:
        return list(zip(self.bodies, self.locations))


def inside_outline(a: np.ndarray, b: np.ndarray, outline: np.ndarray = SOLE_OUTLINE) -> np.ndarray:
    """Boolean mask of normalized points ``(a, b)`` inside the sole outline."""
    lo = np.interp(b, outline[:, 0], outline[:, 1])
    hi = np.interp(b, outline[:, 0], outline[:, 2])
    eps = 1e-9
    return (a >= lo - eps) & (a <= hi + eps) & (b >= outline[0, 0] - eps) & (b <= outline[-1, 0] + eps)


def normalized_grid(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Normalized grid points ``(a, b)`` (each (width*height,)) in column-major order."""
    a = (np.arange(1, width + 1) - 0.5) / width
    b = (np.arange(1, height + 1) - 0.5) / height
    aa, bb = np.meshgrid(a, b, indexing="ij")
    return aa.ravel(), bb.ravel()


def place_springs(foot: FootModel, width: int, height: int, *, spring_height: float,
                  settings_file: str | None = None) -> SpringLayout:
    """Springs of ``foot`` on a ``width`` x ``height`` grid (module docstring).

    ``spring_height`` is the y coordinate (m) of every spring in the hindfoot frame.
    """
    markers = foot.points_in_hindfoot(foot.marker_points)  # (5, 3) in MARKER_ROLES order
    toe, medial, lateral, heel = (markers[i][[0, 2]] for i in range(4))
    axis = toe - heel
    length = float(np.linalg.norm(axis))
    if length < 1e-3:
        raise InputError(f"toe and heel markers of '{foot.hindfoot_body}' coincide", file=settings_file,
                         element="<toe_marker>/<heel_marker>", expected="markers at the two ends of the foot")
    u = axis / length
    n = np.array([-u[1], u[0]])
    if (lateral - medial) @ n < 0:
        n = -n
    foot_width = float((lateral - medial) @ n)
    if foot_width < 1e-3:
        raise InputError(f"medial and lateral markers of '{foot.hindfoot_body}' are not across the foot",
                         file=settings_file, element="<medial_marker>/<lateral_marker>",
                         expected="markers on the two sides of the forefoot")
    a, b = normalized_grid(width, height)
    keep = inside_outline(a, b)
    a, b = a[keep], b[keep]
    across0 = float((medial - heel) @ n)
    xz = heel[None, :] + (b * length)[:, None] * u[None, :] + (across0 + a * foot_width)[:, None] * n[None, :]
    axis_point, axis_direction = foot.toe_axis_in_hindfoot()
    toes_side = _beyond_axis(xz, axis_point[[0, 2]], axis_direction[[0, 2]], toe)
    bodies, locations = [], []
    for (x, z), on_toes in zip(xz, toes_side):
        location = np.array([x, spring_height, z])
        if on_toes:
            bodies.append(foot.toes_body)
            locations.append(foot.hindfoot_to_toes(location))
        else:
            bodies.append(foot.hindfoot_body)
            locations.append(location)
    names = tuple(f"spring_marker_{i}" for i in range(1, len(bodies) + 1))
    return SpringLayout(tuple(bodies), np.array(locations).reshape(-1, 3), names)


def _beyond_axis(points: np.ndarray, axis_point: np.ndarray, axis_direction: np.ndarray,
                 toe: np.ndarray) -> np.ndarray:
    """Mask of 2-D ``points`` on the same side of the axis line as the ``toe`` marker."""
    d = axis_direction / max(np.linalg.norm(axis_direction), 1e-12)
    normal = np.array([-d[1], d[0]])
    side = (points - axis_point) @ normal
    toe_side = (toe - axis_point) @ normal
    return np.sign(side) == np.sign(toe_side)


def layout_from_osimx(springs: Sequence[object], foot: FootModel, *, source: str | None = None) -> SpringLayout:
    """Springs of an ``.osimx`` contact surface (:class:`~nmsm.io.osimx.GcpSpring` list)."""
    bodies, locations, names = [], [], []
    for spring in springs:
        if spring.parent_body not in (foot.hindfoot_body, foot.toes_body):
            raise InputError(f"spring '{spring.name}' is on body '{spring.parent_body}'", file=source,
                             element="<GCPSpring>/<parent_body>",
                             expected=f"'{foot.hindfoot_body}' or '{foot.toes_body}'")
        bodies.append(spring.parent_body)
        locations.append(np.asarray(spring.location, dtype=float))
        names.append(spring.name)
    if not bodies:
        raise InputError("the contact surface has no springs", file=source, element="<GCPSpringSet>",
                         expected="at least one <GCPSpring>")
    return SpringLayout(tuple(bodies), np.array(locations).reshape(-1, 3), tuple(names))

