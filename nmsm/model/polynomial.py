"""Multivariate polynomials in monomial form, evaluated with numpy or CasADi.

A polynomial in ``k`` variables of total degree ``<= p`` is ``sum_e c_e * prod_i x_i**e_i``
over the exponent rows ``e`` of :func:`monomial_exponents` (all terms of
``(1 + x_1 + ... + x_k)**p`` without their coefficients). Every monomial is built from a
*parent* of degree one less (``x**e = x**(e - u_j) * x_j``, ``j`` its first non-zero
exponent), so evaluating all ``n_terms`` monomials costs ``n_terms`` multiplications and
derivatives are the same monomials with shifted coefficients.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from functools import lru_cache

import attrs
import numpy as np


def monomial_exponents(n_variables: int, degree: int) -> np.ndarray:
    """Exponent rows of every monomial of total degree ``<= degree``.

    Shape ``(n_terms, n_variables)``, ``n_terms = C(n_variables + degree, degree)``; graded
    order (constant first, then degree 1, 2, ...), lexicographic inside a degree.
    """
    return _exponents(int(n_variables), int(degree)).copy()


@lru_cache(maxsize=64)
def _exponents(n: int, p: int) -> np.ndarray:
    if n < 0 or p < 0:
        raise ValueError("number of variables and degree must be >= 0")
    rows: list[tuple[int, ...]] = []
    for d in range(p + 1):
        for combo in itertools.combinations_with_replacement(range(n), d):
            e = [0] * n
            for i in combo:
                e[i] += 1
            rows.append(tuple(e))
    return np.array(rows, dtype=int).reshape(len(rows), n)


@attrs.frozen(eq=False)
class MonomialBasis:
    """The monomials of a set of exponent rows, with their parents and derivative maps.

    ``exponents`` ``(n_terms, k)``; must contain, for each row, the row minus one in any
    non-zero position (true for :func:`monomial_exponents`).
    """

    exponents: np.ndarray
    parent: np.ndarray  # (n_terms,) index of x**e / x_j, -1 for the constant
    factor: np.ndarray  # (n_terms,) the j of that division, -1 for the constant
    lowered: np.ndarray  # (k, n_terms) index of e - u_j, -1 where e_j == 0

    @classmethod
    def from_exponents(cls, exponents: np.ndarray) -> MonomialBasis:
        exps = np.asarray(exponents, dtype=int)
        if exps.ndim != 2:
            raise ValueError(f"exponents must be 2-D (n_terms, n_variables), got shape {exps.shape}")
        n_terms, k = exps.shape
        where = {tuple(row): i for i, row in enumerate(exps.tolist())}
        if len(where) != n_terms:
            raise ValueError("exponent rows are not unique")
        parent = np.full(n_terms, -1, dtype=int)
        factor = np.full(n_terms, -1, dtype=int)
        lowered = np.full((k, n_terms), -1, dtype=int)
        for i, row in enumerate(exps.tolist()):
            for j in range(k):
                if row[j] > 0:
                    down = list(row)
                    down[j] -= 1
                    idx = where.get(tuple(down))
                    if idx is None:
                        raise ValueError(f"exponent set lacks {tuple(down)}, needed by {tuple(row)}")
                    lowered[j, i] = idx
                    if factor[i] < 0:
                        parent[i], factor[i] = idx, j
        if np.any(parent >= np.arange(n_terms)):
            raise ValueError("exponent rows must be in graded order (each row after the rows it divides into)")
        return cls(exps, parent, factor, lowered)

    @property
    def n_terms(self) -> int:
        return int(self.exponents.shape[0])

    @property
    def n_variables(self) -> int:
        return int(self.exponents.shape[1])

    def derivative_coefficients(self, coefficients: np.ndarray, variable: int) -> np.ndarray:
        """Coefficients (in this basis) of ``d/dx_variable`` of the polynomial ``coefficients``."""
        c = np.asarray(coefficients, dtype=float)
        out = np.zeros(self.n_terms)
        src = np.flatnonzero(self.lowered[variable] >= 0)
        np.add.at(out, self.lowered[variable, src], c[src] * self.exponents[src, variable])
        return out

    def matrix(self, x: np.ndarray) -> np.ndarray:
        """Monomial values ``(n_points, n_terms)`` at points ``x`` ``(n_points, k)``."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        if x.shape[1] != self.n_variables:
            raise ValueError(f"x has {x.shape[1]} columns, expected {self.n_variables}")
        phi = np.empty((x.shape[0], self.n_terms))
        for i in range(self.n_terms):
            phi[:, i] = 1.0 if self.parent[i] < 0 else phi[:, self.parent[i]] * x[:, self.factor[i]]
        return phi

    def gradient_matrices(self, phi: np.ndarray) -> np.ndarray:
        """``d phi / d x_j`` for every j: ``(k, n_points, n_terms)`` from :meth:`matrix`'s output."""
        out = np.zeros((self.n_variables,) + phi.shape)
        for j in range(self.n_variables):
            cols = np.flatnonzero(self.lowered[j] >= 0)
            out[j][:, cols] = phi[:, self.lowered[j, cols]] * self.exponents[cols, j]
        return out

    def casadi_monomials(self, x: Sequence) -> list:
        """Monomials as CasADi expressions of the ``k`` scalar expressions ``x`` (list)."""
        terms: list = []
        for i in range(self.n_terms):
            terms.append(1.0 if self.parent[i] < 0 else terms[self.parent[i]] * x[self.factor[i]])
        return terms
