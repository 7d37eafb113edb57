"""Tool reductions: how a term's normalized values become residuals.

A reduction turns normalized values ``z = (x - c)/e`` (any shape) into a residual
vector ``r`` with ``sum(r**2)`` equal to the term's objective contribution:

``mean_square``   ``sum(z**2)/n``          (MTP's D(x), NCP, GCP, MTLI, JMP: ``z/sqrt(n)``)
``plain``         ``sum(z**2)``            (discrete values already in final form)
``quadrature``    ``sum(w_k z_k**2)``      (time integrals; TO/VO/DO continuous terms)

The functions accept numpy arrays or CasADi expressions.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def _numel(z: Any) -> int:
    if hasattr(z, "numel"):
        return int(z.numel())
    return int(np.size(z))


def _flatten(z: Any) -> Any:
    if hasattr(z, "numel"):  # CasADi
        import casadi as cs

        return cs.vec(z)
    return np.ravel(np.asarray(z, dtype=float), order="F")


def mean_square(z: Any) -> Any:
    """Residuals ``z/sqrt(n)``: their squared sum is the mean of ``z**2``."""
    n = _numel(z)
    if n == 0:
        return _flatten(z)
    return _flatten(z) / np.sqrt(n)


def plain(z: Any) -> Any:
    """Residuals ``z`` unchanged (flattened)."""
    return _flatten(z)


def quadrature(z: Any, weights: np.ndarray) -> Any:
    """Residuals ``sqrt(w) * z`` for a column ``z`` sampled where the quadrature ``weights`` apply."""
    w = np.sqrt(np.asarray(weights, dtype=float).ravel())
    flat = _flatten(z)
    if _numel(z) != w.size:
        raise ValueError(f"quadrature: {_numel(z)} values but {w.size} weights")
    return flat * w
