"""Figures of a Tracking/Verification/Design Optimization results folder.

``nmsm plot RESULTS_DIR`` can call :func:`plot_treatment_results` when
:func:`is_treatment_results` is true for the folder. Figures (PNG, written to
``RESULTS_DIR/plots`` unless ``output_dir`` is given):

``<trial>_kinematics.png``   state coordinates: modeled vs tracked positions (deg for
                             rotational), speeds and accelerations (``Analysis/`` files)
``<trial>_loads.png``        inverse dynamics of the solution (``IDData``) for the controlled
                             coordinates, with torque controls when present
``<trial>_controls.png``     torque controls and/or synergy commands
``<trial>_activations.png``  combined muscle activations (synergy control)

``compare``: other results folders (e.g. the original pipeline's) drawn dashed on the same
axes, matched by column label.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from nmsm.io.storage import Table, read_storage


def _trial(folder: Path) -> str | None:
    states = sorted(folder.glob("*_states.sto"))
    return states[0].name[: -len("_states.sto")] if states else None


def is_treatment_results(folder: str | os.PathLike[str]) -> bool:
    """True for a folder written by TO/VO/DO (a ``<trial>_states.sto`` next to ``IKData``)."""
    folder = Path(folder)
    return _trial(folder) is not None and (folder / "IKData").is_dir()


def _read(path: Path) -> Table | None:
    return read_storage(path) if path.is_file() else None


def _grid(n: int) -> tuple[int, int]:
    cols = min(n, 3)
    return (n + cols - 1) // cols, cols


def _plot_columns(ax_list, tables: Sequence[tuple[Table | None, str, dict]], labels: Sequence[str],
                  scale: dict[str, float] | None = None) -> None:
    for ax, label in zip(ax_list, labels):
        for table, name, style in tables:
            if table is None or not table.has(label):
                continue
            factor = (scale or {}).get(label, 1.0)
            ax.plot(table.time, table.column(label) * factor, label=name, **style)
        ax.set_title(label, fontsize=9)
        ax.tick_params(labelsize=7)
    for ax in ax_list[len(labels):]:
        ax.axis("off")


def _figure(n: int):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, cols = _grid(max(n, 1))
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 2.6 * rows), squeeze=False)
    return plt, fig, list(axes.ravel())


def _save(plt, fig, path: Path, title: str) -> Path:
    fig.suptitle(title, fontsize=10)
    handles, labels = [], []
    for ax in fig.axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    if handles:
        fig.legend(handles, labels, loc="lower right", fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_treatment_results(results_dir: str | os.PathLike[str], output_dir: str | os.PathLike[str] | None = None,
                           compare: Sequence[str | os.PathLike[str]] = ()) -> list[Path]:
    """Write the figures listed in the module docstring; returns their paths."""
    folder = Path(results_dir)
    trial = _trial(folder)
    if trial is None:
        raise FileNotFoundError(f"{folder} holds no <trial>_states.sto: not a treatment optimization results folder")
    out_dir = Path(output_dir) if output_dir is not None else folder / "plots"
    # a failed solve's last iterate (``last_iterate/`` with its diagnosis) must not look converged
    note = " - LAST ITERATE, NOT CONVERGED (diagnosis.txt)" if (folder / "diagnosis.txt").is_file() else ""

    def save(plt, fig, path: Path, title: str) -> Path:
        return _save(plt, fig, path, title + note)

    others = [Path(c) for c in compare]
    written: list[Path] = []
    states = read_storage(folder / f"{trial}_states.sto")
    coords = [label for label in states.labels if not label.endswith("_u")]
    degrees = {c: 180.0 / np.pi for c in coords}
    # kinematics: modeled vs tracked
    kinds = ("Positions", "Velocities", "Accelerations")
    plt, fig, axes = _figure(3 * len(coords))
    for row, kind in enumerate(kinds):
        modeled = _read(folder / "Analysis" / f"{trial}_modeled{kind}.sto")
        tracked = _read(folder / "Analysis" / f"{trial}_tracked{kind}.sto")
        series = [(modeled, "modeled", {"color": "C0"}), (tracked, "tracked", {"color": "k", "ls": ":"})]
        series += [(_read(o / "Analysis" / f"{trial}_modeled{kind}.sto"), o.name, {"ls": "--"}) for o in others]
        _plot_columns(axes[row * len(coords):(row + 1) * len(coords)], series, coords, degrees)
        for ax in axes[row * len(coords):(row + 1) * len(coords)]:
            ax.set_ylabel({"Positions": "deg", "Velocities": "deg/s", "Accelerations": "deg/s²"}[kind], fontsize=8)
    written.append(save(plt, fig, out_dir / f"{trial}_kinematics.png", f"{trial}: state kinematics"))
    # loads
    ids = _read(folder / "IDData" / f"{trial}.sto")
    torque = _read(folder / f"{trial}_torqueControls.sto")
    if ids is not None:
        loads = [label for label in ids.labels if any(label.startswith(c + "_") for c in coords)]
        plt, fig, axes = _figure(len(loads))
        series = [(ids, "inverse dynamics", {"color": "C0"})]
        series += [(_read(o / "IDData" / f"{trial}.sto"), o.name, {"ls": "--"}) for o in others]
        _plot_columns(axes, series, loads)
        if torque is not None:
            for ax, label in zip(axes, loads):
                coord = label.rsplit("_", 1)[0]
                if torque.has(coord):
                    ax.plot(torque.time, torque.column(coord), color="C1", ls=":", label="torque control")
        written.append(save(plt, fig, out_dir / f"{trial}_loads.png", f"{trial}: joint loads (N·m, N)"))
    # controls
    commands = _read(folder / f"{trial}_synergyCommands.sto")
    for table, name in ((torque, "torque controls"), (commands, "synergy commands")):
        if table is None:
            continue
        plt, fig, axes = _figure(table.n_columns)
        fname = f"{trial}_{'torqueControls' if table is torque else 'synergyCommands'}.sto"
        series = [(table, "solution", {"color": "C0"})] + [(_read(o / fname), o.name, {"ls": "--"}) for o in others]
        _plot_columns(axes, series, table.labels)
        written.append(save(plt, fig, out_dir / f"{trial}_controls{'' if table is torque else '_synergy'}.png",
                             f"{trial}: {name}"))
    activations = _read(folder / f"{trial}_combinedActivations.sto")
    if activations is not None:
        plt, fig, axes = _figure(activations.n_columns)
        fname = f"{trial}_combinedActivations.sto"
        series = [(activations, "solution", {"color": "C0"})] + [(_read(o / fname), o.name, {"ls": "--"}) for o in others]
        _plot_columns(axes, series, activations.labels)
        written.append(save(plt, fig, out_dir / f"{trial}_activations.png", f"{trial}: muscle activations"))
    return written
