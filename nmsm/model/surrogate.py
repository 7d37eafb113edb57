"""Polynomial surrogate muscle geometry (NMSM "Surrogate Model Creation").

For each muscle, the coordinates it spans are those of the surrogate coordinate list whose
moment arm exceeds ``epsilon`` somewhere in the fitting samples. Its muscle-tendon length
is a polynomial of total degree ``<= degree`` in those coordinates,

    L(θ) = Σ_k c_k φ_k(x),   x_i = (θ_i − center_i) / scale_i,

with moment arms ``r_i = −∂L/∂θ_i`` and lengthening velocity ``V = Σ_i ∂L/∂θ_i θ̇_i``
from the same polynomial. The coefficients solve one linear least-squares problem per
muscle, ``[Φ; −∂Φ/∂θ_1; …; −∂Φ/∂θ_n] c = [L; r_1; …; r_n]`` (lengths and moment arms
jointly, unweighted, as the original). ``center``/``scale`` (mid-point and half-range of
the fitting samples) only condition the fit; they are part of the model.

Units: lengths m, moment arms m (rotational coordinates) or m/m (translational),
velocities m/s; coordinates rad or m; coordinate speeds rad/s or m/s.

Accuracy is measured on held-out poses only (fitting samples prove nothing: a degree-5
polynomial in six coordinates has 462 terms) and stored with each muscle.

File format (``.json``, written by :meth:`SurrogateModel.save`)::

    {"format": "nmsm-surrogate-model", "version": 1,
     "coordinates": [...], "degree": 5, "epsilon": 1e-4,
     "excluded_muscles": [...], "metadata": {...},
     "muscles": [{"muscle": "...", "coordinates": [...],
                  "center": [...], "scale": [...],          # per muscle coordinate
                  "sample_min": [...], "sample_max": [...],  # fitting range
                  "exponents": [[...], ...],                 # (n_terms, n_coordinates)
                  "coefficients": [...],                     # (n_terms,)
                  "accuracy": null | {"n_poses": ..., "length_rms": ..., "length_max": ...,
                                      "moment_arm_rms": {coord: ...}, "moment_arm_max": {coord: ...}}}]}

Floats are written with ``repr`` (exact round trip); one line per muscle. The original's ``surrogateMuscles.mat``
holds MATLAB function handles and cannot be read; refit from its sample data instead.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import attrs
import casadi as cs
import numpy as np
import scipy.linalg

from nmsm.errors import InputError
from nmsm.model.polynomial import MonomialBasis, monomial_exponents

FORMAT = "nmsm-surrogate-model"
FORMAT_VERSION = 1


# ---- data ---------------------------------------------------------------------------------
@attrs.frozen(eq=False)
class GeometrySamples:
    """Muscle geometry at poses: what a surrogate is fitted to, or checked against.

    ``q`` ``(n_poses, n_coordinates)`` (rad or m) in ``coordinates`` order; ``lengths``
    ``(n_poses, n_muscles)`` (m); ``moment_arms`` ``(n_poses, n_muscles, n_coordinates)``
    (m), ``r = −dL/dq`` (total derivative through coupler constraints).
    """

    coordinates: tuple[str, ...] = attrs.field(converter=tuple)
    muscles: tuple[str, ...] = attrs.field(converter=tuple)
    q: np.ndarray = attrs.field(converter=lambda a: np.atleast_2d(np.asarray(a, dtype=float)))
    lengths: np.ndarray = attrs.field(converter=lambda a: np.atleast_2d(np.asarray(a, dtype=float)))
    moment_arms: np.ndarray = attrs.field(converter=lambda a: np.asarray(a, dtype=float))

    def __attrs_post_init__(self) -> None:
        n, nc, nm = self.q.shape[0], len(self.coordinates), len(self.muscles)
        if self.q.shape != (n, nc):
            raise ValueError(f"q has shape {self.q.shape}, expected ({n}, {nc})")
        if self.lengths.shape != (n, nm):
            raise ValueError(f"lengths has shape {self.lengths.shape}, expected ({n}, {nm})")
        if self.moment_arms.shape != (n, nm, nc):
            raise ValueError(f"moment_arms has shape {self.moment_arms.shape}, expected ({n}, {nm}, {nc})")

    @property
    def n_poses(self) -> int:
        return int(self.q.shape[0])

    def subset(self, rows: np.ndarray) -> GeometrySamples:
        """The samples at ``rows`` (indices or boolean mask)."""
        return attrs.evolve(self, q=self.q[rows], lengths=self.lengths[rows], moment_arms=self.moment_arms[rows])

    def split_rows(self, holdout_fraction: float, seed: int | None = 0) -> tuple[np.ndarray, np.ndarray]:
        """Row indices (sorted) of a random (fitting, held-out) split; ``holdout_fraction`` in [0, 1)."""
        if not 0.0 <= holdout_fraction < 1.0:
            raise ValueError(f"holdout_fraction must be in [0, 1), got {holdout_fraction}")
        order = np.random.default_rng(seed).permutation(self.n_poses)
        n_out = int(round(holdout_fraction * self.n_poses))
        return np.sort(order[n_out:]), np.sort(order[:n_out])

    def split(self, holdout_fraction: float, seed: int | None = 0) -> tuple[GeometrySamples, GeometrySamples]:
        """Random split into (fitting, held-out) samples (see :meth:`split_rows`)."""
        fit_rows, held_rows = self.split_rows(holdout_fraction, seed)
        return self.subset(fit_rows), self.subset(held_rows)


@attrs.frozen
class SurrogateAccuracy:
    """Errors of one muscle's surrogate over held-out poses.

    ``length_rms``/``length_max`` in m; ``moment_arm_rms``/``moment_arm_max`` per
    coordinate of the surrogate coordinate list present in the data (m), including
    coordinates the muscle does not span (the surrogate's moment arm is 0 there).
    """

    n_poses: int
    length_rms: float
    length_max: float
    moment_arm_rms: Mapping[str, float]
    moment_arm_max: Mapping[str, float]

    @property
    def worst_moment_arm_rms(self) -> float:
        return max(self.moment_arm_rms.values(), default=0.0)

    @property
    def worst_moment_arm_max(self) -> float:
        return max(self.moment_arm_max.values(), default=0.0)

    def to_dict(self) -> dict[str, Any]:
        return {
            "n_poses": self.n_poses,
            "length_rms": self.length_rms,
            "length_max": self.length_max,
            "moment_arm_rms": dict(self.moment_arm_rms),
            "moment_arm_max": dict(self.moment_arm_max),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> SurrogateAccuracy:
        return cls(
            int(d["n_poses"]),
            float(d["length_rms"]),
            float(d["length_max"]),
            {k: float(v) for k, v in d["moment_arm_rms"].items()},
            {k: float(v) for k, v in d["moment_arm_max"].items()},
        )


def _vector(a: Any) -> np.ndarray:
    return np.asarray(a, dtype=float).reshape(-1)


@attrs.frozen(eq=False)
class MuscleSurrogate:
    """One muscle's length polynomial in the coordinates it spans.

    ``coordinates`` (k names); ``center``, ``scale``, ``sample_min``, ``sample_max`` (k,)
    in rad or m; ``exponents`` ``(n_terms, k)``; ``coefficients`` ``(n_terms,)`` in m.
    """

    muscle: str
    coordinates: tuple[str, ...] = attrs.field(converter=tuple)
    center: np.ndarray = attrs.field(converter=_vector)
    scale: np.ndarray = attrs.field(converter=_vector)
    exponents: np.ndarray = attrs.field(converter=lambda a: np.asarray(a, dtype=int).reshape(len(a), -1))
    coefficients: np.ndarray = attrs.field(converter=_vector)
    sample_min: np.ndarray = attrs.field(converter=_vector)
    sample_max: np.ndarray = attrs.field(converter=_vector)
    accuracy: SurrogateAccuracy | None = None
    basis: MonomialBasis = attrs.field(init=False, repr=False)
    gradient_coefficients: np.ndarray = attrs.field(init=False, repr=False)  # (k, n_terms), d/dx_j

    def __attrs_post_init__(self) -> None:
        k = len(self.coordinates)
        exps = self.exponents.reshape(self.exponents.shape[0], k)
        object.__setattr__(self, "exponents", exps)
        for name in ("center", "scale", "sample_min", "sample_max"):
            if getattr(self, name).shape != (k,):
                raise ValueError(f"muscle {self.muscle}: {name} has {getattr(self, name).size} values, expected {k}")
        if np.any(self.scale <= 0):
            raise ValueError(f"muscle {self.muscle}: scale must be > 0")
        if self.coefficients.shape != (exps.shape[0],):
            raise ValueError(f"muscle {self.muscle}: {self.coefficients.size} coefficients for {exps.shape[0]} terms")
        basis = MonomialBasis.from_exponents(exps)
        object.__setattr__(self, "basis", basis)
        grads = np.array([basis.derivative_coefficients(self.coefficients, j) for j in range(k)]).reshape(k, -1)
        object.__setattr__(self, "gradient_coefficients", grads)

    @property
    def degree(self) -> int:
        return int(self.exponents.sum(axis=1).max(initial=0))

    def _x(self, theta: np.ndarray) -> np.ndarray:
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        if theta.shape[1] != len(self.coordinates):
            raise ValueError(f"muscle {self.muscle}: theta has {theta.shape[1]} columns, expected {len(self.coordinates)}")
        return (theta - self.center) / self.scale

    def lengths(self, theta: np.ndarray) -> np.ndarray:
        """Muscle-tendon lengths (m), shape ``(n,)``, at ``theta`` ``(n, k)``."""
        return self.basis.matrix(self._x(theta)) @ self.coefficients

    def length_gradient(self, theta: np.ndarray) -> np.ndarray:
        """``dL/dθ`` ``(n, k)`` (m/rad or m/m)."""
        phi = self.basis.matrix(self._x(theta))
        return (phi @ self.gradient_coefficients.T) / self.scale

    def moment_arms(self, theta: np.ndarray) -> np.ndarray:
        """Moment arms ``−dL/dθ`` ``(n, k)`` (m)."""
        return -self.length_gradient(theta)

    def casadi_expressions(self, theta: Sequence[Any]) -> tuple[Any, list[Any]]:
        """``(L, [dL/dθ_1, …])`` as CasADi expressions of the k scalar expressions ``theta``."""
        x = [(theta[j] - float(self.center[j])) / float(self.scale[j]) for j in range(len(self.coordinates))]
        monomials = cs.vertcat(*[cs.SX(1.0) if isinstance(m, float) else m for m in self.basis.casadi_monomials(x)])
        length = cs.dot(cs.DM(self.coefficients), monomials)
        grads = [
            cs.dot(cs.DM(self.gradient_coefficients[j]), monomials) / float(self.scale[j])
            for j in range(len(self.coordinates))
        ]
        return length, grads

    def to_dict(self) -> dict[str, Any]:
        return {
            "muscle": self.muscle,
            "coordinates": list(self.coordinates),
            "center": self.center.tolist(),
            "scale": self.scale.tolist(),
            "sample_min": self.sample_min.tolist(),
            "sample_max": self.sample_max.tolist(),
            "exponents": self.exponents.tolist(),
            "coefficients": self.coefficients.tolist(),
            "accuracy": None if self.accuracy is None else self.accuracy.to_dict(),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> MuscleSurrogate:
        acc = d.get("accuracy")
        return cls(
            muscle=str(d["muscle"]),
            coordinates=tuple(d["coordinates"]),
            center=d["center"],
            scale=d["scale"],
            exponents=np.asarray(d["exponents"], dtype=int).reshape(len(d["exponents"]), len(d["coordinates"])),
            coefficients=d["coefficients"],
            sample_min=d["sample_min"],
            sample_max=d["sample_max"],
            accuracy=None if acc is None else SurrogateAccuracy.from_dict(acc),
        )


@attrs.frozen
class MuscleGeometryValues:
    """Numeric muscle geometry over frames.

    ``lengths`` ``(n_frames, n_muscles)`` m, ``velocities`` ``(n_frames, n_muscles)`` m/s,
    ``moment_arms`` ``(n_frames, n_muscles, n_coordinates)`` m.
    """

    muscles: tuple[str, ...]
    coordinates: tuple[str, ...]
    lengths: np.ndarray
    velocities: np.ndarray
    moment_arms: np.ndarray


@attrs.frozen(eq=False)
class SurrogateModel:
    """Surrogates of a set of muscles over a surrogate coordinate list.

    ``coordinates``: the surrogate coordinate list (every muscle's coordinates are a
    subset); ``excluded_muscles``: muscles of the data with no moment arm above
    ``epsilon`` on any listed coordinate (not modeled).
    """

    coordinates: tuple[str, ...] = attrs.field(converter=tuple)
    muscles: tuple[MuscleSurrogate, ...] = attrs.field(converter=tuple)
    degree: int
    epsilon: float
    excluded_muscles: tuple[str, ...] = attrs.field(default=(), converter=tuple)
    metadata: Mapping[str, Any] = attrs.field(factory=dict)

    def __attrs_post_init__(self) -> None:
        names = [m.muscle for m in self.muscles]
        if len(set(names)) != len(names):
            raise ValueError("a muscle appears twice in the surrogate model")
        for m in self.muscles:
            extra = [c for c in m.coordinates if c not in self.coordinates]
            if extra:
                raise ValueError(f"muscle {m.muscle}: coordinates {extra} are not in the surrogate coordinate list")

    @property
    def muscle_names(self) -> tuple[str, ...]:
        return tuple(m.muscle for m in self.muscles)

    def __getitem__(self, muscle: str) -> MuscleSurrogate:
        for m in self.muscles:
            if m.muscle == muscle:
                return m
        raise KeyError(f"muscle '{muscle}' is not in the surrogate model (has: {', '.join(self.muscle_names)})")

    def _select(self, muscles: Sequence[str] | None, coordinates: Sequence[str] | None) -> tuple[list[MuscleSurrogate], tuple[str, ...]]:
        chosen = list(self.muscles) if muscles is None else [self[m] for m in muscles]
        coords = self.coordinates if coordinates is None else tuple(coordinates)
        for m in chosen:
            missing = [c for c in m.coordinates if c not in coords]
            if missing:
                raise InputError(
                    f"muscle {m.muscle} needs coordinates {', '.join(missing)}",
                    element="coordinate list",
                    expected=f"a list containing {', '.join(m.coordinates)}",
                )
        return chosen, coords

    # ---- CasADi ----------------------------------------------------------------------------
    def function(
        self,
        coordinates: Sequence[str] | None = None,
        muscles: Sequence[str] | None = None,
        name: str = "surrogate_muscle_geometry",
    ) -> cs.Function:
        """Per-frame SX function ``(q, qdot) -> (lengths, velocities, moment_arms)``.

        ``q``, ``qdot`` ``(n_c, 1)`` ordered as ``coordinates`` (default: the surrogate
        list; any list containing every selected muscle's coordinates, e.g. a model's
        full coordinate list: extra entries are ignored). Outputs: ``lengths``
        ``(n_m, 1)`` m, ``velocities`` ``(n_m, 1)`` m/s, ``moment_arms`` ``(n_m, n_c)`` m
        (0 where the muscle does not span the coordinate). ``map`` it over frames.
        """
        chosen, coords = self._select(muscles, coordinates)
        q = cs.SX.sym("q", len(coords))
        qdot = cs.SX.sym("qdot", len(coords))
        lengths, velocities = [], []
        arms = cs.SX.zeros(len(chosen), len(coords))
        for i, m in enumerate(chosen):
            idx = [coords.index(c) for c in m.coordinates]
            length, grads = m.casadi_expressions([q[j] for j in idx])
            lengths.append(length)
            velocity = cs.SX(0.0)
            for j, g in zip(idx, grads):
                arms[i, j] = -g
                velocity = velocity + g * qdot[j]
            velocities.append(velocity)
        empty = cs.SX(0, 1)
        return cs.Function(
            name,
            [q, qdot],
            [cs.vertcat(*lengths) if lengths else empty, cs.vertcat(*velocities) if velocities else empty, arms],
            ["q", "qdot"],
            ["lengths", "velocities", "moment_arms"],
        )

    # ---- numpy ----------------------------------------------------------------------------
    def evaluate(
        self,
        q: np.ndarray,
        qdot: np.ndarray | None = None,
        coordinates: Sequence[str] | None = None,
        muscles: Sequence[str] | None = None,
    ) -> MuscleGeometryValues:
        """Numeric geometry at frames ``q`` ``(n, n_c)`` (and ``qdot``, default zeros)."""
        chosen, coords = self._select(muscles, coordinates)
        q = np.atleast_2d(np.asarray(q, dtype=float))
        if q.shape[1] != len(coords):
            raise ValueError(f"q has {q.shape[1]} columns, expected {len(coords)}")
        qdot = np.zeros_like(q) if qdot is None else np.atleast_2d(np.asarray(qdot, dtype=float))
        n = q.shape[0]
        lengths = np.zeros((n, len(chosen)))
        velocities = np.zeros((n, len(chosen)))
        arms = np.zeros((n, len(chosen), len(coords)))
        for i, m in enumerate(chosen):
            idx = [coords.index(c) for c in m.coordinates]
            lengths[:, i] = m.lengths(q[:, idx])
            grad = m.length_gradient(q[:, idx])
            arms[:, i, idx] = -grad
            velocities[:, i] = np.sum(grad * qdot[:, idx], axis=1)
        return MuscleGeometryValues(tuple(m.muscle for m in chosen), coords, lengths, velocities, arms)

    def accuracy(self, samples: GeometrySamples) -> dict[str, SurrogateAccuracy]:
        """Errors per muscle against ``samples`` (which should be held-out poses)."""
        return {m.muscle: muscle_accuracy(m, samples) for m in self.muscles if m.muscle in samples.muscles}

    # ---- files ------------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "coordinates": list(self.coordinates),
            "degree": self.degree,
            "epsilon": self.epsilon,
            "excluded_muscles": list(self.excluded_muscles),
            "metadata": dict(self.metadata),
            "muscles": [m.to_dict() for m in self.muscles],
        }

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the model as JSON (see the module docstring); returns the path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        doc = self.to_dict()
        muscles = doc.pop("muscles")
        head = json.dumps(doc, indent=1)[:-2]  # without the closing brace
        body = ",\n".join("  " + json.dumps(m) for m in muscles)
        path.write_text(f'{head},\n "muscles": [\n{body}\n ]\n}}\n', encoding="utf-8")
        return path

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> SurrogateModel:
        """Read a model written by :meth:`save`; bad files raise :class:`InputError`."""
        path = Path(path)
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise InputError(f"cannot read surrogate model: {exc.strerror or exc}", file=path) from exc
        except json.JSONDecodeError as exc:
            raise InputError(f"not JSON: {exc}", file=path, line=exc.lineno, expected="an nmsm surrogate model (.json)") from exc
        if not isinstance(doc, dict) or doc.get("format") != FORMAT:
            raise InputError(
                "not an nmsm surrogate model",
                file=path,
                element="format",
                expected=f"'format': '{FORMAT}' (MATLAB surrogateMuscles.mat files cannot be read; refit from the sample data)",
            )
        if doc.get("version") != FORMAT_VERSION:
            raise InputError(f"unsupported version {doc.get('version')!r}", file=path, element="version", expected=str(FORMAT_VERSION))
        try:
            return cls(
                coordinates=tuple(doc["coordinates"]),
                muscles=tuple(MuscleSurrogate.from_dict(m) for m in doc["muscles"]),
                degree=int(doc["degree"]),
                epsilon=float(doc["epsilon"]),
                excluded_muscles=tuple(doc.get("excluded_muscles", ())),
                metadata=dict(doc.get("metadata", {})),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed surrogate model: {exc}", file=path, expected="a file written by nmsm") from exc


# ---- fitting ---------------------------------------------------------------------------------
def fit_muscle_surrogate(
    muscle: str,
    coordinates: Sequence[str],
    theta: np.ndarray,
    lengths: np.ndarray,
    moment_arms: np.ndarray,
    degree: int,
) -> MuscleSurrogate:
    """Least-squares fit of one muscle's polynomial to lengths and moment arms jointly.

    ``theta`` ``(n, k)`` (rad or m) for the k ``coordinates``; ``lengths`` ``(n,)`` m;
    ``moment_arms`` ``(n, k)`` m (``−dL/dθ``).
    """
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    n, k = theta.shape
    lengths = np.asarray(lengths, dtype=float).reshape(n)
    moment_arms = np.asarray(moment_arms, dtype=float).reshape(n, k)
    lo, hi = theta.min(axis=0), theta.max(axis=0)
    center = 0.5 * (lo + hi)
    half = 0.5 * (hi - lo)
    scale = np.where(half > 0, half, 1.0)
    exponents = monomial_exponents(k, degree)
    basis = MonomialBasis.from_exponents(exponents)
    if n * (k + 1) < basis.n_terms:
        raise InputError(
            f"muscle {muscle}: {n} poses give {n * (k + 1)} equations for {basis.n_terms} polynomial terms",
            element=muscle,
            expected=f"at least {-(-basis.n_terms // (k + 1))} sample poses, or a lower polynomial degree",
        )
    phi = basis.matrix((theta - center) / scale)
    grads = basis.gradient_matrices(phi)  # (k, n, T), d/dx
    a = np.vstack([phi] + [-grads[j] / scale[j] for j in range(k)])
    b = np.concatenate([lengths] + [moment_arms[:, j] for j in range(k)])
    coefficients = _least_squares(a, b)
    return MuscleSurrogate(muscle, tuple(coordinates), center, scale, exponents, coefficients, lo, hi)


def _least_squares(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``argmin |a x - b|``: normal equations (Cholesky) plus one refinement step.

    The scaled monomial basis keeps ``cond(a)`` small (about 30 for degree 5 in six
    coordinates), so this matches an SVD solution to rounding at a fraction of its cost;
    a singular system (e.g. a coordinate constant over the samples) falls back to SVD.
    """
    normal = a.T @ a
    try:
        factor = scipy.linalg.cho_factor(normal, check_finite=False)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(a, b, rcond=None)[0]
    x = scipy.linalg.cho_solve(factor, a.T @ b, check_finite=False)
    x = x + scipy.linalg.cho_solve(factor, a.T @ (b - a @ x), check_finite=False)
    if not np.all(np.isfinite(x)) or np.linalg.cond(normal) > 1e12:
        return np.linalg.lstsq(a, b, rcond=None)[0]
    return x


def spanned_coordinates(moment_arms: np.ndarray, coordinates: Sequence[str], epsilon: float) -> tuple[str, ...]:
    """Coordinates whose ``max |moment arm|`` exceeds ``epsilon``; ``moment_arms`` ``(n, n_c)``."""
    peak = np.max(np.abs(np.asarray(moment_arms, dtype=float)), axis=0) if len(moment_arms) else np.zeros(len(coordinates))
    return tuple(c for c, v in zip(coordinates, peak) if v > epsilon)


def muscle_accuracy(surrogate: MuscleSurrogate, samples: GeometrySamples) -> SurrogateAccuracy:
    """Errors of ``surrogate`` against ``samples`` (length and every coordinate of the samples)."""
    i = samples.muscles.index(surrogate.muscle)
    idx = [samples.coordinates.index(c) for c in surrogate.coordinates]
    theta = samples.q[:, idx]
    length_error = surrogate.lengths(theta) - samples.lengths[:, i]
    model_arms = np.zeros((samples.n_poses, len(samples.coordinates)))
    model_arms[:, idx] = surrogate.moment_arms(theta)
    arm_error = model_arms - samples.moment_arms[:, i, :]
    rms = np.sqrt(np.mean(arm_error**2, axis=0)) if samples.n_poses else np.zeros(len(samples.coordinates))
    peak = np.max(np.abs(arm_error), axis=0) if samples.n_poses else np.zeros(len(samples.coordinates))
    return SurrogateAccuracy(
        n_poses=samples.n_poses,
        length_rms=float(np.sqrt(np.mean(length_error**2))) if samples.n_poses else 0.0,
        length_max=float(np.max(np.abs(length_error))) if samples.n_poses else 0.0,
        moment_arm_rms={c: float(v) for c, v in zip(samples.coordinates, rms)},
        moment_arm_max={c: float(v) for c, v in zip(samples.coordinates, peak)},
    )


def fit_surrogate_model(
    samples: GeometrySamples,
    degree: int = 5,
    epsilon: float = 1e-4,
    *,
    validation: GeometrySamples | None = None,
    holdout_fraction: float = 0.2,
    seed: int | None = 0,
    metadata: Mapping[str, Any] | None = None,
) -> SurrogateModel:
    """Fit every muscle of ``samples`` over ``samples.coordinates``.

    Accuracy is measured on ``validation`` when given (all of ``samples`` is then used
    for fitting); otherwise ``holdout_fraction`` of the poses (random, ``seed``) are held
    out and the model is fitted on the rest. With neither, accuracy is ``None``.
    Spanned coordinates are chosen on the fitting samples (``max|r| > epsilon``).
    """
    if degree < 0:
        raise InputError(f"polynomial degree {degree} is negative", element="surrogate_model_polynomial_degree", expected="an integer >= 0")
    if validation is None and holdout_fraction > 0:
        fitting, held_out = samples.split(holdout_fraction, seed)
    else:
        fitting, held_out = samples, validation
    if held_out is not None:
        missing = [m for m in samples.muscles if m not in held_out.muscles] + [
            c for c in samples.coordinates if c not in held_out.coordinates
        ]
        if missing:
            raise InputError(f"validation samples lack {', '.join(missing)}", element="validation data")
    muscles: list[MuscleSurrogate] = []
    excluded: list[str] = []
    for i, name in enumerate(samples.muscles):
        coords = spanned_coordinates(fitting.moment_arms[:, i, :], samples.coordinates, epsilon)
        if not coords:
            excluded.append(name)
            continue
        idx = [samples.coordinates.index(c) for c in coords]
        surrogate = fit_muscle_surrogate(
            name, coords, fitting.q[:, idx], fitting.lengths[:, i], fitting.moment_arms[:, i, idx], degree
        )
        if held_out is not None and held_out.n_poses:
            surrogate = attrs.evolve(surrogate, accuracy=muscle_accuracy(surrogate, held_out))
        muscles.append(surrogate)
    meta = dict(metadata or {})
    meta.setdefault("n_fitting_poses", fitting.n_poses)
    meta.setdefault("n_held_out_poses", 0 if held_out is None else held_out.n_poses)
    return SurrogateModel(samples.coordinates, tuple(muscles), degree, epsilon, tuple(excluded), meta)
