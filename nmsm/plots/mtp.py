"""Figures of a Muscle-Tendon Personalization results folder (the original's or ours).

``nmsm plot RESULTS_DIR`` can call :func:`plot_mtp_results` when :func:`is_mtp_results` is
true for the folder (it holds ``Analysis/inverseDynamicsJointMoments``). Figures (PNG,
written to ``RESULTS_DIR/plots`` unless ``output_dir`` is given), one set per trial:

``mtp_<trial>_moments.png``       inverse-dynamics vs model joint moments per coordinate
                                  (with synergy extrapolation also the SynX moments), N m
``mtp_<trial>_activations.png``   muscle activations (SynX ones dashed when present)
``mtp_<trial>_fiber_lengths.png`` normalized fiber lengths with the 0.3 / 1.3 limits
``mtp_passive_moments.png``       passive trials: experimental vs modeled moments (N m)
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from nmsm.io.storage import Table, read_storage


def is_mtp_results(folder: str | os.PathLike[str]) -> bool:
    """True for an MTP results folder (``Analysis/inverseDynamicsJointMoments`` present)."""
    return (Path(folder) / "Analysis" / "inverseDynamicsJointMoments").is_dir()


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _tables(folder: Path, quantity: str) -> dict[str, Table]:
    """``trial -> table`` of ``Analysis/<quantity>/<trial>_<quantity>.sto``."""
    path = folder / "Analysis" / quantity
    if not path.is_dir():
        return {}
    suffix = f"_{quantity}"
    out = {}
    for f in sorted(path.glob("*.sto")):
        stem = f.stem
        out[stem[: -len(suffix)] if stem.endswith(suffix) else stem] = read_storage(f)
    return out


def _grid(n: int) -> tuple[int, int]:
    cols = min(3, max(1, n))
    return math.ceil(n / cols), cols


def _moments_figure(plt: Any, trial: str, measured: Table, model: Table, synx: Table | None, out: Path) -> Path:
    labels = list(measured.labels)
    rows, cols = _grid(len(labels))
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.0 * rows), squeeze=False)
    for ax, label in zip(axes.flat, labels):
        ax.plot(measured.time, measured.column(label), "k", lw=2, label="inverse dynamics")
        if model.has(label):
            ax.plot(model.time, model.column(label), "C0", label="model (EMG)")
        if synx is not None and synx.has(label):
            ax.plot(synx.time, synx.column(label), "C1--", label="model (SynX)")
        ax.set_title(label)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("moment (N m)")
    for ax in list(axes.flat)[len(labels):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=8)
    fig.suptitle(f"{trial}: joint moments")
    fig.tight_layout()
    path = out / f"mtp_{trial}_moments.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _muscle_figure(plt: Any, trial: str, table: Table, extra: Table | None, what: str, ylabel: str,
                   limits: tuple[float, ...], out: Path) -> Path:
    labels = list(table.labels)
    rows, cols = _grid(len(labels))
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 2.4 * rows), squeeze=False)
    for ax, label in zip(axes.flat, labels):
        ax.plot(table.time, table.column(label), "C0")
        if extra is not None and extra.has(label):
            ax.plot(extra.time, extra.column(label), "C1--")
        for y in limits:
            ax.axhline(y, color="0.6", lw=0.8, ls=":")
        ax.set_title(label, fontsize=9)
        ax.set_ylabel(ylabel, fontsize=8)
    for ax in list(axes.flat)[len(labels):]:
        ax.axis("off")
    fig.suptitle(f"{trial}: {what}")
    fig.tight_layout()
    path = out / f"mtp_{trial}_{what.replace(' ', '_')}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _passive_figure(plt: Any, experimental: dict[str, Table], modeled: dict[str, Table], out: Path) -> Path:
    names = sorted(experimental)
    rows, cols = _grid(len(names))
    fig, axes = plt.subplots(rows, cols, figsize=(4.0 * cols, 2.8 * rows), squeeze=False)
    for ax, name in zip(axes.flat, names):
        exp = experimental[name]
        mod = modeled.get(name)
        for j, label in enumerate(exp.labels):
            values = exp.column(label)
            if not (values != 0).any():
                continue
            ax.plot(exp.time, values, color=f"C{j}", lw=2, label=f"{label} experimental")
            if mod is not None and mod.has(label):
                ax.plot(mod.time, mod.column(label), color=f"C{j}", ls="--", label=f"{label} modeled")
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("frame")
        ax.set_ylabel("moment (N m)")
        ax.legend(fontsize=6)
    for ax in list(axes.flat)[len(names):]:
        ax.axis("off")
    fig.suptitle("passive joint moments")
    fig.tight_layout()
    path = out / "mtp_passive_moments.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_mtp_results(results_dir: str | os.PathLike[str], output_dir: str | os.PathLike[str] | None = None) -> list[Path]:
    """Write the MTP figures of ``results_dir``; returns the PNG paths."""
    folder = Path(results_dir)
    out = Path(output_dir) if output_dir is not None else folder / "plots"
    out.mkdir(parents=True, exist_ok=True)
    plt = _pyplot()
    written = []
    measured = _tables(folder, "inverseDynamicsJointMoments")
    model = _tables(folder, "modelJointMoments")
    synx = _tables(folder, "modelJointMomentsSynx")
    activations = _tables(folder, "muscleActivations")
    synx_activations = _tables(folder, "muscleActivationsSynx")
    lengths = _tables(folder, "normalizedFiberLengths")
    for trial, table in measured.items():
        if trial in model:
            written.append(_moments_figure(plt, trial, table, model[trial], synx.get(trial), out))
        if trial in activations:
            written.append(_muscle_figure(plt, trial, activations[trial], synx_activations.get(trial),
                                          "activations", "activation", (0.0, 1.0), out))
        if trial in lengths:
            written.append(_muscle_figure(plt, trial, lengths[trial], None, "fiber lengths",
                                          "normalized length", (0.3, 1.3), out))
    experimental = _tables(folder, "passiveJointMomentsExperimental")
    if experimental:
        written.append(_passive_figure(plt, experimental, _tables(folder, "passiveJointMomentsModeled"), out))
    return written
