"""Figures of a Muscle-Tendon Personalization results folder (the original's or ours).

``nmsm plot RESULTS_DIR`` can call :func:`plot_mtp_results` when :func:`is_mtp_results` is
true for the folder (it holds ``Analysis/inverseDynamicsJointMoments``). Figures (PNG,
written to ``RESULTS_DIR/plots`` unless ``output_dir`` is given), one set per trial:

``mtp_<trial>_moments.png``       inverse-dynamics vs model joint moments per coordinate
                                  (with synergy extrapolation also the SynX moments), N m
``mtp_<trial>_activations.png``   muscle activations with the processed EMG they come from
                                  (``muscleExcitations``: EMG delayed and scaled) dashed, and
                                  the SynX activations when present
``mtp_<trial>_fiber_lengths.png`` normalized fiber lengths with the 0.3 / 1.3 limits
``mtp_passive_moments.png``       passive trials: experimental vs modeled moments (N m)
``mtp_parameters.png``            the personalized parameters of each muscle (the ``.osimx``)
                                  within their bounds; values at a bound in red

Style, axes and legends: :mod:`nmsm.plots.style`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from nmsm.io.storage import Table, read_storage
from nmsm.plots import style
from nmsm.plots.convergence import plot_results_convergence

#: parameter charts: osimx attribute, title, factor from the .osimx's unit (0.1 s, 0.01 s,
#: -) to the shown one, bounds in the shown unit (MTP's design bounds,
#: :data:`nmsm.tools.mtp.problem.BLOCKS`)
PARAMETERS = (
    ("electromechanical_delay", "electromechanical delay (ms)", 100.0, (0.0, 125.0)),
    ("activation_time_constant", "activation time constant (ms)", 10.0, (7.5, 35.0)),
    ("activation_nonlinearity_constant", "activation nonlinearity (-)", 1.0, (0.0, 0.35)),
    ("emg_scale_factor", "EMG scale (-)", 1.0, (0.05, 1.0)),
)


def is_mtp_results(folder: str | os.PathLike[str]) -> bool:
    """True for an MTP results folder (``Analysis/inverseDynamicsJointMoments`` present)."""
    return (Path(folder) / "Analysis" / "inverseDynamicsJointMoments").is_dir()


def _pyplot() -> Any:
    return style.pyplot()


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
    return style.grid(n)


def _moments_figure(plt: Any, trial: str, measured: Table, model: Table, synx: Table | None, out: Path) -> Path:
    labels = list(measured.labels)
    rows, cols = _grid(len(labels))
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.0 * rows), squeeze=False)
    for ax, label in zip(axes.flat, labels):
        ax.plot(measured.time, measured.column(label), label="inverse dynamics", **style.EXPERIMENTAL)
        if model.has(label):
            ax.plot(model.time, model.column(label), label="model (EMG)", **style.SOLUTION)
        if synx is not None and synx.has(label):
            ax.plot(synx.time, synx.column(label), "C1--", label="model (SynX)")
        ax.set_title(label)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("moment (N m)")
    for ax in list(axes.flat)[len(labels):]:
        ax.axis("off")
    return style.save(plt, fig, out / f"mtp_{trial}_moments.png", f"{trial}: joint moments")


def _muscle_figure(plt: Any, trial: str, table: Table, extra: Table | None, what: str, ylabel: str,
                   limits: tuple[float, ...], out: Path, emg: Table | None = None) -> Path:
    labels = list(table.labels)
    rows, cols = _grid(len(labels))
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 2.4 * rows), squeeze=False)
    for ax, label in zip(axes.flat, labels):
        if emg is not None and emg.has(label):
            ax.plot(emg.time, emg.column(label), label="processed EMG (delayed, scaled)", **style.EXPERIMENTAL)
        ax.plot(table.time, table.column(label), label=what.rstrip("s") if what == "activations" else what,
                **style.SOLUTION)
        if extra is not None and extra.has(label):
            ax.plot(extra.time, extra.column(label), color="C1", label="SynX activation")
        for y in limits:
            ax.axhline(y, color="0.6", lw=0.8, ls=":")
        ax.set_title(label)
        ax.set_ylabel(ylabel)
        ax.set_xlabel(style.TIME)
    for ax in list(axes.flat)[len(labels):]:
        ax.axis("off")
    return style.save(plt, fig, out / f"mtp_{trial}_{what.replace(' ', '_')}.png", f"{trial}: {what}")


def _parameters_figure(plt: Any, osimx_file: Path, out: Path) -> Path | None:
    """Each personalized parameter per muscle as a dot within its bounds (grey band); dots
    within 0.1 % of the range from a bound in red."""
    from nmsm.io.osimx import read_osimx

    muscles = read_osimx(osimx_file).muscles
    names = list(muscles)
    shown = [(attr, title, factor, bounds) for attr, title, factor, bounds in PARAMETERS
             if any(getattr(muscles[m], attr, None) is not None for m in names)]
    if not names or not shown:
        return None
    fig, axes = plt.subplots(1, len(shown), figsize=(3.2 * len(shown), 0.28 * len(names) + 1.4), squeeze=False,
                             sharey=True)
    y = np.arange(len(names))
    for ax, (attr, title, factor, (low, high)) in zip(axes.flat, shown):
        values = np.array([np.nan if getattr(muscles[m], attr, None) is None else factor * getattr(muscles[m], attr)
                           for m in names])
        at_bound = np.minimum(np.abs(values - low), np.abs(values - high)) <= 1e-3 * (high - low)
        ax.axvspan(low, high, color="0.92", zorder=0)
        for edge in (low, high):
            ax.axvline(edge, color="0.5", lw=0.8, ls=":")
        ax.plot(values[~at_bound], y[~at_bound], "o", ms=4, label="within the bounds", **{"color": "C0"})
        ax.plot(values[at_bound], y[at_bound], "o", ms=5, color="C3", label="at a bound")
        ax.set_title(title)
        ax.set_xlim(low - 0.08 * (high - low), high + 0.08 * (high - low))
    axes.flat[0].set_yticks(y, names)
    axes.flat[0].invert_yaxis()
    return style.save(plt, fig, out / "mtp_parameters.png", f"personalized muscle parameters ({osimx_file.name}; "
                      "grey: MTP's bounds)")


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
        ax.set_title(name)
        ax.set_xlabel("frame")
        ax.set_ylabel("moment (N m)")
    for ax in list(axes.flat)[len(names):]:
        ax.axis("off")
    return style.save(plt, fig, out / "mtp_passive_moments.png", "passive joint moments")


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
    excitations = _tables(folder, "muscleExcitations")
    lengths = _tables(folder, "normalizedFiberLengths")
    for trial, table in measured.items():
        if trial in model:
            written.append(_moments_figure(plt, trial, table, model[trial], synx.get(trial), out))
        if trial in activations:
            written.append(_muscle_figure(plt, trial, activations[trial], synx_activations.get(trial),
                                          "activations", "activation (-)", (0.0, 1.0), out, excitations.get(trial)))
        if trial in lengths:
            written.append(_muscle_figure(plt, trial, lengths[trial], None, "fiber lengths",
                                          "normalized fiber length (-)", (0.3, 1.3), out))
    experimental = _tables(folder, "passiveJointMomentsExperimental")
    if experimental:
        written.append(_passive_figure(plt, experimental, _tables(folder, "passiveJointMomentsModeled"), out))
    osimx_files = sorted(folder.glob("*.osimx"))
    if osimx_files:
        chart = _parameters_figure(plt, osimx_files[0], out)
        if chart is not None:
            written.append(chart)
    convergence = plot_results_convergence(folder, out, "MTP")
    if convergence is not None:
        written.append(convergence)
    return written
