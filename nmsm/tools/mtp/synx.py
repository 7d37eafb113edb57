"""Synergy Extrapolation (SynX, Ao et al. 2020) inside MTP.

Excitations of muscles without EMG are built from synergy excitations ("commands")
extracted from the measured channels, and every measured channel gets a small residual
excitation from the same kind of commands (docs/mtp.md):

* measured EMG is normalized per channel by its maximum over all trials; per category of
  trials (``trial``: each trial; ``task``: trials whose name contains a task name;
  ``subject``: all trials) the stacked (frames * trials, channels) matrix is factorized;
* **PCA** (as the original runs it): the commands are the first K principal-component
  scores (MATLAB ``pca`` convention: centred data, the largest coefficient of each
  component positive); each extrapolated excitation is ``u = C w + b``;
* **NMF** (the original's path is broken; done here as intended): non-negative commands
  ``C`` (frames * trials, K) from multiplicative-update NMF with several replicates,
  scaled by the row sums of the synergy vectors; ``u = C w`` (no bias) with extrapolation
  weights ``w >= 0``, so extrapolated excitations are non-negative combinations of
  non-negative synergy excitations. With either method the extrapolated excitations are
  constrained to [0, 1] (the original's linear inequalities).

Design-variable layout (the original's order):

* extrapolation weights: for each missing channel, for each extrapolation category:
  K weights (+ 1 bias with PCA);
* residual weights: for each residual category, for each measured channel: K weights
  (+ 1 bias with PCA). (The original sizes this block by the *measured* channels but
  reshapes it by the number of *missing* channels, which only works when both are equal;
  here the measured-channel layout is used throughout.)

Muscle excitations before the delay: ``e = s_emg * x + rho`` where ``x`` is the measured
EMG (measured muscles) or ``u`` (muscles of a missing group) and ``rho`` the residual of the
muscle's channel (0 for missing muscles).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.errors import InputError

CATEGORIZATIONS = ("trial", "task", "subject")
#: negatives of processed EMG down to this fraction of the peak are filtering round-off (NMF clips them)
NEGATIVE_ROUNDOFF = 1e-9
METHODS = ("PCA", "NMF")


def categorize_trials(
    method: str, trial_names: Sequence[str], task_names: Sequence[str] = ()
) -> list[list[int]]:
    """Trial indices per category for ``method`` in {trial, task, subject}.

    ``task``: one category per task name, holding the trials whose name contains it; with no
    task names every trial belongs to one task. A trial in no task is an error.
    """
    method = method.strip().lower()
    n = len(trial_names)
    if method == "trial":
        return [[i] for i in range(n)]
    if method == "subject":
        return [list(range(n))]
    if method == "task":
        if not task_names:
            return [list(range(n))]
        groups = [[i for i, name in enumerate(trial_names) if task in name] for task in dict.fromkeys(task_names)]
        covered = {i for g in groups for i in g}
        missing = [trial_names[i] for i in range(n) if i not in covered]
        if missing:
            raise InputError(
                f"trial(s) {', '.join(missing)} contain none of the task names {', '.join(task_names)}",
                element="<task_prefixes>",
                expected="every trial name containing one task name",
            )
        return [g for g in groups if g]
    raise InputError(
        f"unknown categorization '{method}'",
        element="<synergy_extrapolation_categorization>/<residual_categorization>",
        expected="trial, task or subject",
    )


def normalize_emg(emg: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Each trial's EMG (frames, channels) divided by the channel maximum over all trials."""
    peak = np.max([np.max(x, axis=0) for x in emg], axis=0)
    if np.any(peak <= 0):
        raise InputError(
            "an EMG channel is zero in every trial: it cannot drive synergy extrapolation",
            element="EMGData",
            expected="a positive maximum in every collected channel",
        )
    return [np.asarray(x, dtype=float) / peak for x in emg]


def pca_scores(data: np.ndarray, n_components: int) -> np.ndarray:
    """First ``n_components`` principal-component scores, MATLAB ``pca`` conventions.

    ``data`` (samples, variables); centred by column means; each coefficient vector's
    largest-magnitude entry made positive.
    """
    centred = data - data.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    coeff = vt.T
    rows = np.abs(coeff).argmax(axis=0)
    coeff = coeff * np.sign(coeff[rows, np.arange(coeff.shape[1])])
    if n_components > coeff.shape[1]:
        raise InputError(
            f"{n_components} synergies requested but only {coeff.shape[1]} components exist",
            element="<number_of_synergies>",
            expected=f"at most {coeff.shape[1]} (the number of measured channels)",
        )
    return centred @ coeff[:, :n_components]


def nmf(data: np.ndarray, rank: int, *, replicates: int = 20, max_iterations: int = 2000,
        tolerance: float = 1e-10, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Non-negative factorization ``data ~ C @ W`` (multiplicative updates, Lee & Seung).

    ``data`` (samples, channels) >= 0; returns ``C`` (samples, rank) and ``W`` (rank,
    channels) of the best of ``replicates`` random starts (lowest Frobenius residual);
    seeded, so results are reproducible.
    """
    x = np.asarray(data, dtype=float)
    # low-pass filtering leaves round-off negatives (~1e-19) in processed EMG: clipped;
    # anything larger is not rectified EMG
    roundoff = NEGATIVE_ROUNDOFF * max(float(np.abs(x).max(initial=0.0)), 1.0)
    if np.any(x < -roundoff):
        raise InputError(f"NMF needs non-negative EMG; smallest value {x.min():.3g}", element="EMGData",
                         expected="processed (rectified, low-pass filtered) EMG >= 0")
    x = np.maximum(x, 0.0)
    rng = np.random.default_rng(seed)
    best: tuple[float, np.ndarray, np.ndarray] | None = None
    eps = 1e-12
    scale = np.sqrt(max(x.mean(), eps) / rank)
    for _ in range(replicates):
        c = rng.random((x.shape[0], rank)) * scale
        w = rng.random((rank, x.shape[1])) * scale
        previous = np.inf
        for _ in range(max_iterations):
            w *= (c.T @ x) / (c.T @ c @ w + eps)
            c *= (x @ w.T) / (c @ (w @ w.T) + eps)
            residual = float(np.linalg.norm(x - c @ w))
            if abs(previous - residual) <= tolerance * max(1.0, residual):
                break
            previous = residual
        if best is None or residual < best[0]:
            best = (residual, c.copy(), w.copy())
    assert best is not None
    return best[1], best[2]


def synergy_commands(
    normalized_emg: Sequence[np.ndarray], categories: Sequence[Sequence[int]], n_synergies: int, method: str
) -> list[np.ndarray]:
    """Commands per category: ``(frames * n_trials_in_category, n_synergies)``, trials stacked in order."""
    out = []
    for category in categories:
        stacked = np.concatenate([normalized_emg[i] for i in category], axis=0)
        if method.upper() == "PCA":
            out.append(pca_scores(stacked, n_synergies))
        elif method.upper() == "NMF":
            c, w = nmf(stacked, n_synergies)
            out.append(c * w.sum(axis=1))
        else:
            raise InputError(f"unknown matrix factorization '{method}'", element="<matrix_factorization_method>",
                             expected="PCA or NMF")
    return out


@attrs.frozen(eq=False)
class SynergyExtrapolation:
    """Everything SynX needs, fixed before the optimization.

    ``missing_muscles[j]`` muscle indices of missing channel j; ``channel_muscles[g]``
    muscle indices of measured channel g; commands per category as from
    :func:`synergy_commands`; ``n_frames`` EMG frames per trial.
    """

    method: str
    n_synergies: int
    n_frames: int
    n_trials: int
    missing_muscles: tuple[tuple[int, ...], ...]
    channel_muscles: tuple[tuple[int, ...], ...]
    extrapolation_categories: tuple[tuple[int, ...], ...]
    residual_categories: tuple[tuple[int, ...], ...]
    extrapolation_commands: tuple[np.ndarray, ...]
    residual_commands: tuple[np.ndarray, ...]

    @property
    def per_vector(self) -> int:
        """Variables per (channel, category): K weights (+ bias with PCA)."""
        return self.n_synergies + (1 if self.method.upper() == "PCA" else 0)

    @property
    def n_extrapolation_weights(self) -> int:
        return self.per_vector * len(self.extrapolation_categories) * len(self.missing_muscles)

    @property
    def n_residual_weights(self) -> int:
        return self.per_vector * len(self.residual_categories) * len(self.channel_muscles)

    @property
    def n_weights(self) -> int:
        return self.n_extrapolation_weights + self.n_residual_weights

    def _apply(self, commands: np.ndarray, w: Any) -> Any:
        """``C w[:K] (+ w[K])`` for one channel and category."""
        k = self.n_synergies
        out = cs.mtimes(cs.DM(commands), w[:k])
        if self.per_vector > k:
            out = out + w[k]
        return out

    def extrapolated(self, weights: Any) -> list[list[Any]]:
        """``u[trial][j]``: extrapolated (unscaled) excitation (n_frames,) of missing channel j."""
        w = weights
        p = self.per_vector
        n_cat = len(self.extrapolation_categories)
        out: list[list[Any]] = [[None] * len(self.missing_muscles) for _ in range(self.n_trials)]
        for j in range(len(self.missing_muscles)):
            for i, category in enumerate(self.extrapolation_categories):
                start = (j * n_cat + i) * p
                u = self._apply(self.extrapolation_commands[i], w[start : start + p])
                for pos, trial in enumerate(category):
                    out[trial][j] = u[pos * self.n_frames : (pos + 1) * self.n_frames]
        return out

    def residuals(self, weights: Any) -> list[list[Any]]:
        """``rho[trial][g]``: residual excitation (n_frames,) of measured channel g."""
        w = weights[self.n_extrapolation_weights :]
        p = self.per_vector
        n_chan = len(self.channel_muscles)
        out: list[list[Any]] = [[None] * n_chan for _ in range(self.n_trials)]
        for i, category in enumerate(self.residual_categories):
            for g in range(n_chan):
                start = (i * n_chan + g) * p
                r = self._apply(self.residual_commands[i], w[start : start + p])
                for pos, trial in enumerate(category):
                    out[trial][g] = r[pos * self.n_frames : (pos + 1) * self.n_frames]
        return out

    def excitation_samples(self, emg_expanded: Sequence[np.ndarray], emg_scale: Any, weights: Any) -> list[cs.MX]:
        """Undelayed excitations ``(n_frames, n_muscles)`` per trial: ``s_emg * x + rho``.

        ``emg_expanded[trial]`` (n_frames, n_muscles): measured EMG per muscle (columns of
        missing muscles ignored); ``emg_scale`` (1, n_muscles) or (n_muscles,).
        """
        n_muscles = emg_expanded[0].shape[1]
        scale = cs.reshape(cs.MX(emg_scale) if not isinstance(emg_scale, np.ndarray) else cs.MX(cs.DM(emg_scale)), 1, n_muscles)
        u = self.extrapolated(weights)
        rho = self.residuals(weights)
        out = []
        for t in range(self.n_trials):
            cols = [cs.MX(cs.DM(emg_expanded[t][:, m])) for m in range(n_muscles)]
            extra: list[Any] = [cs.MX.zeros(self.n_frames, 1) for _ in range(n_muscles)]
            for j, muscles in enumerate(self.missing_muscles):
                for m in muscles:
                    cols[m] = u[t][j]
            for g, muscles in enumerate(self.channel_muscles):
                for m in muscles:
                    extra[m] = rho[t][g]
            x = cs.horzcat(*cols)
            out.append(x * cs.repmat(scale, self.n_frames, 1) + cs.horzcat(*extra))
        return out

    def weight_bounds(self, low: float = -100.0, high: float = 100.0) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of the weight vector: ``[low, high]``; with NMF the extrapolation weights are >= 0.

        NMF commands are non-negative, so non-negative weights keep every extrapolated
        excitation a non-negative combination of synergy excitations (the point of NMF);
        residual weights stay signed (a residual corrects measured EMG up or down).
        """
        lower = np.full(self.n_weights, float(low))
        upper = np.full(self.n_weights, float(high))
        if self.method.upper() == "NMF":
            lower[: self.n_extrapolation_weights] = 0.0
        return lower, upper

    def extrapolated_bounds_expression(self, weights: Any) -> cs.MX:
        """All extrapolated (unscaled) excitations stacked: the original bounds them to [0, 1]."""
        u = self.extrapolated(weights)
        return cs.vertcat(*[u[t][j] for t in range(self.n_trials) for j in range(len(self.missing_muscles))])


def build_synergy_extrapolation(
    emg: Sequence[np.ndarray],
    trial_names: Sequence[str],
    *,
    method: str,
    n_synergies: int,
    extrapolation_categorization: str,
    residual_categorization: str,
    missing_muscles: Sequence[Sequence[int]],
    channel_muscles: Sequence[Sequence[int]],
    task_names: Sequence[str] = (),
) -> SynergyExtrapolation:
    """Commands and layout from the measured EMG ``emg[trial]`` (frames, channels)."""
    if method.upper() not in METHODS:
        raise InputError(f"unknown matrix factorization '{method}'", element="<matrix_factorization_method>",
                         expected="PCA or NMF")
    if n_synergies < 1:
        raise InputError(f"number_of_synergies = {n_synergies}", element="<number_of_synergies>", expected=">= 1")
    normalized = normalize_emg(emg)
    ext_cat = categorize_trials(extrapolation_categorization, trial_names, task_names)
    res_cat = categorize_trials(residual_categorization, trial_names, task_names)
    return SynergyExtrapolation(
        method=method.upper(),
        n_synergies=int(n_synergies),
        n_frames=int(emg[0].shape[0]),
        n_trials=len(emg),
        missing_muscles=tuple(tuple(g) for g in missing_muscles),
        channel_muscles=tuple(tuple(g) for g in channel_muscles),
        extrapolation_categories=tuple(tuple(c) for c in ext_cat),
        residual_categories=tuple(tuple(c) for c in res_cat),
        extrapolation_commands=tuple(synergy_commands(normalized, ext_cat, n_synergies, method)),
        residual_commands=tuple(synergy_commands(normalized, res_cat, n_synergies, method)),
    )
