"""Legendre-Gauss-Radau (LGR) nodes, quadrature weights and differentiation matrices.

Computed with numpy/scipy for any number of points (CasADi's ``collocation_points``
stops at degree 9; the kicking tutorials ask for 50 points in one interval).

Conventions (flipped Radau, as GPOPS-II): on the reference interval ``tau in [-1, 1]`` the
``n`` collocation points are ``tau_1 = -1 < tau_2 < ... < tau_n < 1`` (the roots of
``P_{n-1}(tau) + P_n(tau)``); the interval end ``tau_{n+1} = 1`` is an extra,
non-collocated node. A state polynomial of degree ``n`` interpolates the ``n + 1`` nodes;
its derivative at the collocation points is ``D @ X`` with ``D`` of shape ``(n, n + 1)``.
"""

from __future__ import annotations

from functools import lru_cache

import attrs
import numpy as np
import scipy.special


@attrs.frozen
class RadauRule:
    """LGR rule with ``n`` collocation points on ``[-1, 1]``.

    ``nodes``        (n + 1,) collocation points then the end point 1.
    ``weights``      (n,) quadrature weights on ``[-1, 1]`` (sum 2), exact to degree 2n - 2.
    ``derivative``   (n, n + 1) ``D[k, j] = l_j'(tau_k)`` of the Lagrange basis on ``nodes``.
    ``extrapolate``  (n,) Lagrange basis of the collocation points evaluated at ``tau = 1``:
                     the end value of a degree ``n - 1`` polynomial through collocation values.
    """

    n: int
    nodes: np.ndarray
    weights: np.ndarray
    derivative: np.ndarray
    extrapolate: np.ndarray

    @property
    def collocation(self) -> np.ndarray:
        """The ``n`` collocation points (without the end point)."""
        return self.nodes[:-1]


def _barycentric_weights(x: np.ndarray) -> np.ndarray:
    diff = x[:, None] - x[None, :]
    np.fill_diagonal(diff, 1.0)
    # product of differences in log form avoids overflow for large n
    sign = np.prod(np.sign(diff), axis=1)
    logmag = np.sum(np.log(np.abs(diff)), axis=1)
    logmag -= logmag.max()
    return sign / np.exp(logmag)


def differentiation_matrix(x: np.ndarray) -> np.ndarray:
    """``D[i, j] = l_j'(x_i)`` for the Lagrange basis on the distinct points ``x`` (m, m)."""
    x = np.asarray(x, dtype=float)
    b = _barycentric_weights(x)
    diff = x[:, None] - x[None, :]
    np.fill_diagonal(diff, 1.0)
    D = (b[None, :] / b[:, None]) / diff
    np.fill_diagonal(D, 0.0)
    np.fill_diagonal(D, -D.sum(axis=1))
    return D


def lagrange_basis_at(x: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Values ``L[p, j] = l_j(points[p])`` of the Lagrange basis on ``x`` (barycentric form)."""
    x = np.asarray(x, dtype=float)
    points = np.atleast_1d(np.asarray(points, dtype=float))
    b = _barycentric_weights(x)
    out = np.zeros((points.size, x.size))
    for p, value in enumerate(points):
        d = value - x
        hit = np.flatnonzero(np.abs(d) < 1e-14)
        if hit.size:
            out[p, hit[0]] = 1.0
            continue
        terms = b / d
        out[p] = terms / terms.sum()
    return out


@lru_cache(maxsize=64)
def radau_rule(n: int) -> RadauRule:
    """The LGR rule with ``n >= 1`` collocation points (see module docstring)."""
    if n < 1:
        raise ValueError(f"an LGR rule needs at least 1 collocation point, got {n}")
    if n == 1:
        tau = np.array([-1.0])
    else:
        # interior points are the roots of the Jacobi polynomial P^(0,1)_{n-1}
        interior, _ = scipy.special.roots_jacobi(n - 1, 0.0, 1.0)
        tau = np.concatenate([[-1.0], np.sort(interior)])
    # quadrature weights: w_1 = 2/n^2, w_k = (1 - tau_k) / (n^2 P_{n-1}(tau_k)^2)
    p = scipy.special.eval_legendre(n - 1, tau)
    weights = (1.0 - tau) / (n**2 * p**2)
    weights[0] = 2.0 / n**2
    nodes = np.concatenate([tau, [1.0]])
    D = differentiation_matrix(nodes)[:-1, :]
    extrapolate = lagrange_basis_at(tau, np.array([1.0]))[0] if n > 1 else np.array([1.0])
    for arr in (nodes, weights, D, extrapolate):
        arr.setflags(write=False)
    return RadauRule(n, nodes, weights, D, extrapolate)
