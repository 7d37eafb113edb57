"""Modeled and experimental quantities of one foot for a :class:`~nmsm.tools.gcp.state.Design`.

With CasADi symbols in the design the results are MX expressions (a task's problem);
with numbers they are DM values (outputs, scoring). Shapes (``T`` frames, ``n`` springs):

* ``coordinates``/``rates`` (7, T): ``q = (N (base * C))^T`` and ``qdot = (N' (base * C))^T``.
* ``markers``/``marker_velocities`` (3, 5T): frame ``t`` in columns ``5t .. 5t+4``.
* ``forces``/``moments`` (3, T): modeled ground reaction (N) and its moment (N m) about the
  modeled midfoot-superior marker projected on the floor.
* ``spring_positions`` (3, nT): frame ``t`` in columns ``nt .. nt+n-1``.
* ``experimental_forces``/``experimental_moments`` (3, T): the plate's reactions moved to
  the experimental midfoot point at the resting-spring-length height, plus
  ``shift x F`` for an electrical-center shift, then rotated about ground y by the plate
  rotation ``theta`` (nmsm uses the current ``theta``, not the previous
  task's, so the derivative is exact).
"""

from __future__ import annotations

from typing import Any

import attrs
import casadi as cs
import numpy as np
import scipy.sparse

from nmsm.core.threads import thread_map
from nmsm.tools.gcp.inputs import FootInputs
from nmsm.tools.gcp.state import Design



@attrs.frozen(eq=False)
class FootValues:
    """One foot's quantities (module docstring)."""

    coordinates: Any
    rates: Any
    markers: Any
    marker_velocities: Any
    forces: Any
    moments: Any
    spring_positions: Any
    experimental_forces: Any
    experimental_moments: Any


def _cross_rows(a: Any, b: Any) -> Any:
    """Column-wise cross products of (3, T) arrays ``a`` and ``b`` (``a`` may be (3, 1))."""
    if a.shape[1] == 1 and b.shape[1] > 1:
        a = cs.repmat(a, 1, b.shape[1])
    return cs.vertcat(a[1, :] * b[2, :] - a[2, :] * b[1, :],
                      a[2, :] * b[0, :] - a[0, :] * b[2, :],
                      a[0, :] * b[1, :] - a[1, :] * b[0, :])


def plate_rotation_matrix(theta: Any) -> Any:
    """Rotation about ground y by ``theta`` rad: ``[[c, 0, s], [0, 1, 0], [-s, 0, c]]``."""
    c, s = cs.cos(theta), cs.sin(theta)
    return cs.vertcat(cs.horzcat(c, 0, s), cs.horzcat(0, 1, 0), cs.horzcat(-s, 0, c))


def experimental_reactions(foot: FootInputs, resting_length: Any, shift: Any, theta: Any) -> tuple[Any, Any]:
    """``(forces, moments)`` (3, T) of the plate in the frame the model is compared in."""
    forces = cs.DM(foot.reactions.forces.T)
    moments = cs.DM(foot.plate_moments_about_midfoot.T)
    lever = cs.vertcat(0, -resting_length, 0) + shift
    moments = moments + _cross_rows(lever, forces)
    rotation = plate_rotation_matrix(theta)
    return cs.mtimes(rotation, forces), cs.mtimes(rotation, moments)


def foot_coordinates(foot: FootInputs, coefficients: Any) -> tuple[Any, Any]:
    """``(q, qdot)`` (7, T) of the foot for kinematic coefficients ``coefficients`` (m, 7)."""
    nodes = cs.DM(foot.base_nodes) * coefficients
    return cs.mtimes(sparse_dm(foot.basis), nodes).T, cs.mtimes(sparse_dm(foot.basis_rate), nodes).T


def foot_values(foot: FootInputs, design: Design, index: int, *, coordinates: tuple[Any, Any] | None = None
                ) -> FootValues:
    """The :class:`FootValues` of ``foot`` (position ``index`` in the design's foot lists).

    ``coordinates``: ``(q, qdot)`` (7, T) to use instead of :func:`foot_coordinates` of the
    design's coefficients (symbols standing for them: see :mod:`nmsm.core.backends.lifted_least_squares`).
    """
    q, qdot = coordinates if coordinates is not None else foot_coordinates(foot, design.coefficients[index])
    frames = foot.n_frames
    mapped = thread_map(foot.frame_function, frames, shared=(2,), name="frames")
    parameters = design.contact_parameters(foot.surface.belt_speed)
    markers, velocities, per_k, offset, springs = mapped(q, qdot, parameters)
    n = foot.springs.n_springs
    loads = cs.mtimes(cs.kron(cs.reshape(design.spring_constants, 1, n), cs.DM.eye(6)),
                      cs.reshape(per_k, 6 * n, frames)) + offset
    forces, moments = loads[0:3, :], loads[3:6, :]
    exp_forces, exp_moments = experimental_reactions(
        foot, design.resting_spring_length, design.electrical_center_shifts[index], design.plate_rotations[index])
    return FootValues(q, qdot, markers, velocities, forces, moments, springs, exp_forces, exp_moments)


def sparse_dm(matrix: np.ndarray) -> cs.DM:
    """A DM keeping only the nonzero entries of ``matrix`` (structural sparsity for
    Jacobians; a dense DM makes every entry a dependency)."""
    return cs.DM(scipy.sparse.csc_matrix(np.asarray(matrix, dtype=float)))


def as_array(value: Any) -> np.ndarray:
    """A DM value as a numpy array."""
    return np.array(cs.DM(value))
