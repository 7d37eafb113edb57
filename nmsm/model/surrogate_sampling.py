"""Latin-hypercube poses around reference kinematics, for fitting muscle surrogates.

As the original's ``sampleSurrogateKinematics``: for every reference frame, a Latin
hypercube of ``samples_per_frame`` points spans ``[q_ref + lower_padding, q_ref +
upper_padding]`` per coordinate, clipped to the coordinate's range when the coordinate is
clamped. Padding defaults: ``angular_padding`` (rad) for rotational coordinates,
``linear_padding`` (m) for the others; per-coordinate ``(lower, upper)`` overrides.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from scipy.stats import qmc

from nmsm.errors import InputError


def coordinate_padding(
    coordinates: Sequence[str],
    rotational: Sequence[bool],
    angular_padding: float,
    linear_padding: float,
    overrides: Mapping[str, tuple[float, float]] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper padding ``(n_c,)`` each (rad or m; lower <= 0 <= upper normally)."""
    overrides = dict(overrides or {})
    unknown = [c for c in overrides if c not in coordinates]
    if unknown:
        raise InputError(f"padding given for coordinates not sampled: {', '.join(unknown)}", element="padding",
                         expected=f"names among {', '.join(coordinates)}")
    lower = np.empty(len(coordinates))
    upper = np.empty(len(coordinates))
    for j, (name, rot) in enumerate(zip(coordinates, rotational)):
        if name in overrides:
            lo, hi = overrides[name]
            lower[j], upper[j] = min(lo, hi), max(lo, hi)
        else:
            pad = angular_padding if rot else linear_padding
            lower[j], upper[j] = -abs(pad), abs(pad)
    return lower, upper


def latin_hypercube_poses(
    reference: np.ndarray,
    lower_padding: np.ndarray,
    upper_padding: np.ndarray,
    range_min: np.ndarray | None = None,
    range_max: np.ndarray | None = None,
    samples_per_frame: int = 25,
    seed: int | np.random.Generator | None = None,
) -> np.ndarray:
    """Poses ``(n_frames * samples_per_frame, n_c)`` around ``reference`` ``(n_frames, n_c)``.

    Row ``i * samples_per_frame + k`` is sample k of frame i. ``range_min``/``range_max``
    ``(n_c,)`` clip the sampled box (use ``-inf``/``inf`` for unclamped coordinates).
    """
    ref = np.atleast_2d(np.asarray(reference, dtype=float))
    n_frames, n_c = ref.shape
    lo_pad = np.broadcast_to(np.asarray(lower_padding, dtype=float), (n_c,))
    hi_pad = np.broadcast_to(np.asarray(upper_padding, dtype=float), (n_c,))
    rmin = np.full(n_c, -np.inf) if range_min is None else np.broadcast_to(np.asarray(range_min, dtype=float), (n_c,))
    rmax = np.full(n_c, np.inf) if range_max is None else np.broadcast_to(np.asarray(range_max, dtype=float), (n_c,))
    if samples_per_frame < 1:
        raise InputError(f"samples per frame must be >= 1, got {samples_per_frame}", element="samples_per_frame")
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    sampler = qmc.LatinHypercube(d=n_c, seed=rng)
    out = np.empty((n_frames * samples_per_frame, n_c))
    for i in range(n_frames):
        lo = np.clip(ref[i] + lo_pad, rmin, rmax)
        hi = np.clip(ref[i] + hi_pad, rmin, rmax)
        out[i * samples_per_frame : (i + 1) * samples_per_frame] = lo + sampler.random(samples_per_frame) * (hi - lo)
    return out
