"""Non-negative matrix factorization of activations, and its variance accounted for.

``A (n_samples, n_muscles) ≈ H (n_samples, k) @ W (k, n_muscles)`` with ``H, W >= 0``
(rows of ``W`` are synergy vectors, columns of ``H`` their activations). Solved by
hierarchical alternating least squares (HALS, Cichocki & Phan 2009) from several starts
(an SVD-based start and seeded random ones); the fit with the largest VAF is kept.

VAF (variance accounted for), as used for synergy counts:
``VAF = 1 - ||A - H W||_F^2 / ||A||_F^2`` (uncentred).
"""

from __future__ import annotations

import attrs
import numpy as np

_EPS = 1e-12


@attrs.frozen
class NmfResult:
    """``commands`` (n_samples, k) >= 0, ``weights`` (k, n_muscles) >= 0, fit quality."""

    commands: np.ndarray
    weights: np.ndarray
    vaf: float
    iterations: int

    @property
    def reconstruction(self) -> np.ndarray:
        return self.commands @ self.weights


def variance_accounted_for(data: np.ndarray, reconstruction: np.ndarray) -> float:
    """``1 - ||data - reconstruction||² / ||data||²`` (uncentred VAF, fraction not percent)."""
    data = np.asarray(data, dtype=float)
    denom = float(np.sum(data**2))
    if denom == 0.0:
        return 1.0 if np.allclose(reconstruction, 0.0) else 0.0
    return 1.0 - float(np.sum((data - reconstruction) ** 2)) / denom


def _nndsvd_start(data: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """NNDSVD (Boutsidis & Gallopoulos 2008) with zeros filled by the data mean."""
    u, s, vt = np.linalg.svd(data, full_matrices=False)
    h = np.zeros((data.shape[0], k))
    w = np.zeros((k, data.shape[1]))
    h[:, 0] = np.sqrt(s[0]) * np.abs(u[:, 0])
    w[0, :] = np.sqrt(s[0]) * np.abs(vt[0, :])
    for j in range(1, min(k, s.size)):
        x, y = u[:, j], vt[j, :]
        xp, xn = np.maximum(x, 0), np.maximum(-x, 0)
        yp, yn = np.maximum(y, 0), np.maximum(-y, 0)
        pos = np.linalg.norm(xp) * np.linalg.norm(yp)
        neg = np.linalg.norm(xn) * np.linalg.norm(yn)
        if pos >= neg and pos > 0:
            uu, vv, sigma = xp / np.linalg.norm(xp), yp / np.linalg.norm(yp), pos
        elif neg > 0:
            uu, vv, sigma = xn / np.linalg.norm(xn), yn / np.linalg.norm(yn), neg
        else:
            continue
        h[:, j] = np.sqrt(s[j] * sigma) * uu
        w[j, :] = np.sqrt(s[j] * sigma) * vv
    fill = max(float(data.mean()), _EPS)
    h[h < _EPS] = fill * 1e-2
    w[w < _EPS] = fill * 1e-2
    return h, w


def _hals(data: np.ndarray, h: np.ndarray, w: np.ndarray, max_iter: int, tol: float) -> tuple[np.ndarray, np.ndarray, int]:
    k = h.shape[1]
    norm_data = float(np.sum(data**2)) or 1.0
    previous = np.inf
    it = 0
    for it in range(1, max_iter + 1):
        # update W rows
        hth = h.T @ h
        htd = h.T @ data
        for j in range(k):
            denom = max(hth[j, j], _EPS)
            w[j, :] = np.maximum(_EPS, w[j, :] + (htd[j, :] - hth[j, :] @ w) / denom)
        # update H columns
        wwt = w @ w.T
        dwt = data @ w.T
        for j in range(k):
            denom = max(wwt[j, j], _EPS)
            h[:, j] = np.maximum(_EPS, h[:, j] + (dwt[:, j] - h @ wwt[:, j]) / denom)
        error = float(np.sum((data - h @ w) ** 2)) / norm_data
        if previous - error < tol * max(error, _EPS) and it > 10:
            break
        previous = error
    return h, w, it


def nmf(
    data: np.ndarray,
    n_synergies: int,
    *,
    n_starts: int = 10,
    max_iter: int = 2000,
    tol: float = 1e-9,
    seed: int = 0,
) -> NmfResult:
    """Factorize non-negative ``data`` (n_samples, n_muscles) into ``n_synergies`` synergies.

    Negative entries are clipped to zero first (activations can dip below zero by
    round-off). Deterministic for a given ``seed``. Tiny values (<= 1e-12) are set to 0.
    """
    data = np.maximum(np.asarray(data, dtype=float), 0.0)
    if data.ndim != 2:
        raise ValueError(f"data must be 2-D (samples, muscles), got shape {data.shape}")
    k = int(n_synergies)
    if not 1 <= k <= min(data.shape):
        raise ValueError(f"n_synergies must be between 1 and {min(data.shape)}, got {k}")
    rng = np.random.default_rng(seed)
    starts = [_nndsvd_start(data, k)]
    scale = np.sqrt(max(float(data.mean()), _EPS) / k)
    for _ in range(max(0, n_starts - 1)):
        starts.append((rng.uniform(0, 2 * scale, (data.shape[0], k)), rng.uniform(0, 2 * scale, (k, data.shape[1]))))
    best: NmfResult | None = None
    for h0, w0 in starts:
        h, w, it = _hals(data, h0.copy(), w0.copy(), max_iter, tol)
        h[h <= _EPS] = 0.0
        w[w <= _EPS] = 0.0
        vaf = variance_accounted_for(data, h @ w)
        if best is None or vaf > best.vaf:
            best = NmfResult(commands=h, weights=w, vaf=vaf, iterations=it)
    assert best is not None
    return best
