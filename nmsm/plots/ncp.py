"""Figures of a Neural Control Personalization results folder (``nmsm plot RESULTS_DIR``).

:func:`plot_ncp_results` reads only files of the results folder (``synergyWeights.sto``,
``<trial>_synergyCommands.sto``, ``<trial>_combinedActivations.sto``, ``modelMoments/``)
and, through ``ncpRunInfo.json`` written by the run, the inverse-dynamics and MTP
activation files the run used. It saves PNG files:

* ``synergyVectors.png``: one bar chart per synergy (weights of its group's muscles);
* ``<trial>_synergyCommands.png``: commands of every synergy over the cycle (%);
* ``<trial>_momentMatching.png``: per coordinate, ID moments, NCP-only and MTP/NCP
  combined muscle moments (N·m);
* ``<trial>_activationMatching.png``: per muscle, NCP activations and MTP activations
  where MTP has them.

Results folders written without ``ncpRunInfo.json`` (e.g. by the MATLAB original) get the
first two figures only, unless ``inverse_dynamics_directory``/``mtp_activations_directory``
are given.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage
from nmsm.io.trials import find_trial_file
from nmsm.plots import style
from nmsm.plots.convergence import plot_results_convergence

_WEIGHTS = "synergyWeights.sto"
_COMMANDS = "_synergyCommands.sto"
_MOMENTS = "modelMoments"


def _pyplot():
    return style.pyplot()


def _percent(table: Table) -> np.ndarray:
    t = table.time
    return 100.0 * (t - t[0]) / (t[-1] - t[0]) if t.size > 1 else np.zeros_like(t)


def _grid(n: int) -> tuple[int, int]:
    cols = int(np.ceil(np.sqrt(n)))
    return int(np.ceil(n / cols)), cols


def _groups_from_commands(labels: Sequence[str]) -> list[tuple[str, list[int]]]:
    """``<group>_<k>`` command labels -> [(group, synergy row indices)] in order."""
    groups: list[tuple[str, list[int]]] = []
    for i, label in enumerate(labels):
        group = label.rsplit("_", 1)[0]
        if not groups or groups[-1][0] != group:
            groups.append((group, []))
        groups[-1][1].append(i)
    return groups


def plot_synergy_vectors(weights: Table, command_labels: Sequence[str], path: Path) -> Path:
    """Bar chart of every synergy vector (rows of ``synergyWeights.sto``), by group."""
    plt = _pyplot()
    groups = _groups_from_commands(command_labels) if command_labels else [("synergy", list(range(weights.n_rows)))]
    n_rows = max(len(rows) for _, rows in groups)
    fig, axes = plt.subplots(n_rows, len(groups), figsize=(6 * len(groups), 2.2 * n_rows), squeeze=False)
    for g, (group, rows) in enumerate(groups):
        block = weights.data[rows]
        used = np.flatnonzero(np.any(block != 0, axis=0))
        names = [weights.labels[i] for i in used]
        for k, row in enumerate(rows):
            ax = axes[k, g]
            ax.bar(np.arange(used.size), weights.data[row, used], color="tab:blue")
            ax.set_title(command_labels[row] if command_labels else f"synergy {row + 1}", fontsize=9)
            ax.set_ylim(0, 1.05 * max(1.0, float(np.max(weights.data[row, used], initial=0))))
            ax.set_xticks(np.arange(used.size))
            ax.set_xticklabels(names if k == len(rows) - 1 else [], rotation=90, fontsize=6)
        for k in range(len(rows), n_rows):
            axes[k, g].axis("off")
    fig.suptitle("Synergy vectors (largest weight 1)")
    style.legend_below(fig)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_commands(commands: Table, path: Path, trial: str) -> Path:
    """Synergy commands of one trial over the cycle."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    x = _percent(commands)
    for j, label in enumerate(commands.labels):
        ax.plot(x, commands.data[:, j], label=label)
    ax.set_xlabel(style.PERCENT_CYCLE)
    ax.set_ylabel("synergy command (-)")
    ax.set_title(f"{trial}: synergy commands")
    style.legend_below(fig)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_moment_matching(ncp: Table, combined: Table | None, inverse_dynamics: Table | None, path: Path, trial: str) -> Path:
    """Per coordinate: ID moments, NCP muscle moments and MTP/NCP combined muscle moments."""
    plt = _pyplot()
    rows, cols = _grid(ncp.n_columns)
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols, 2.6 * rows), squeeze=False)
    x = _percent(ncp)
    for j, label in enumerate(ncp.labels):
        ax = axes.flat[j]
        if inverse_dynamics is not None and inverse_dynamics.has(label):
            ax.plot(_percent(inverse_dynamics), inverse_dynamics.column(label), label="inverse dynamics",
                    **style.EXPERIMENTAL)
        ax.plot(x, ncp.data[:, j], label="NCP", **style.SOLUTION)
        if combined is not None and combined.has(label):
            ax.plot(_percent(combined), combined.column(label), "tab:orange", ls="--", label="MTP + NCP")
        if inverse_dynamics is not None and inverse_dynamics.has(label):
            rms = float(np.sqrt(np.mean((ncp.data[:, j] - inverse_dynamics.column(label)) ** 2)))
            ax.set_title(f"{label} (RMS {rms:.2f} N·m)")
        else:
            ax.set_title(label)
        ax.set_xlabel(style.PERCENT_CYCLE)
        ax.set_ylabel("N·m")
    for k in range(ncp.n_columns, rows * cols):
        axes.flat[k].axis("off")
    fig.suptitle(f"{trial}: joint moments (N·m)")
    style.legend_below(fig)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_activation_matching(ncp_activations: np.ndarray, muscles: Sequence[str], time: np.ndarray,
                             mtp: Table | None, path: Path, trial: str) -> Path:
    """Per muscle: NCP activations, with MTP activations where available."""
    plt = _pyplot()
    rows, cols = _grid(len(muscles))
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols, 2.0 * rows), squeeze=False)
    x = 100.0 * (time - time[0]) / (time[-1] - time[0]) if time.size > 1 else time
    for i, muscle in enumerate(muscles):
        ax = axes.flat[i]
        if mtp is not None and mtp.has(muscle):
            ax.plot(_percent(mtp), mtp.column(muscle), label="MTP", **style.EXPERIMENTAL)
        ax.plot(x, ncp_activations[:, i], label="NCP", **style.SOLUTION)
        ax.set_title(muscle, fontsize=7)
        ax.set_xlabel(style.PERCENT_CYCLE, fontsize=6)
        ax.set_ylim(bottom=min(0.0, float(ncp_activations[:, i].min())))
        ax.tick_params(labelsize=6)
    for k in range(len(muscles), rows * cols):
        axes.flat[k].axis("off")
    fig.suptitle(f"{trial}: muscle activations")
    style.legend_below(fig)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def is_ncp_results(folder: str | os.PathLike[str]) -> bool:
    """True when ``folder`` looks like an NCP results folder (it holds ``synergyWeights.sto``)."""
    return (Path(folder) / _WEIGHTS).is_file()


def _trials(folder: Path) -> list[str]:
    return sorted(p.name[: -len(_COMMANDS)] for p in folder.glob(f"*{_COMMANDS}"))


def plot_ncp_results(
    results_directory: str | os.PathLike[str],
    output_directory: str | os.PathLike[str] | None = None,
    *,
    inverse_dynamics_directory: str | os.PathLike[str] | None = None,
    mtp_activations_directory: str | os.PathLike[str] | None = None,
) -> list[Path]:
    """Save the NCP figures of ``results_directory`` (see module docstring); returns the files.

    ``output_directory`` defaults to ``<results_directory>/plots``.
    """
    folder = Path(results_directory)
    weights_path = folder / _WEIGHTS
    if not weights_path.is_file():
        raise InputError("not an NCP results folder: synergyWeights.sto missing", file=folder,
                         expected="a folder written by Neural Control Personalization")
    out = Path(output_directory) if output_directory is not None else folder / "plots"
    out.mkdir(parents=True, exist_ok=True)
    info_path = folder / "ncpRunInfo.json"
    info = json.loads(info_path.read_text(encoding="utf-8")) if info_path.is_file() else {}
    trial_info = {t["name"]: t for t in info.get("trials", [])}
    weights = read_storage(weights_path)
    trials = _trials(folder)
    written: list[Path] = []
    first_commands = read_storage(folder / f"{trials[0]}{_COMMANDS}") if trials else None
    written.append(plot_synergy_vectors(weights, first_commands.labels if first_commands else (), out / "synergyVectors.png"))
    for trial in trials:
        commands = read_storage(folder / f"{trial}{_COMMANDS}")
        written.append(plot_commands(commands, out / f"{trial}_synergyCommands.png", trial))
        ncp_activations = commands.data @ weights.data
        id_table = mtp_table = None
        entry = trial_info.get(trial, {})
        if entry.get("inverse_dynamics"):
            id_table = read_storage(entry["inverse_dynamics"])
        elif inverse_dynamics_directory is not None:
            id_table = read_storage(find_trial_file(inverse_dynamics_directory, trial))
        if entry.get("mtp_activations"):
            mtp_table = read_storage(entry["mtp_activations"])
        elif mtp_activations_directory is not None:
            mtp_table = read_storage(find_trial_file(mtp_activations_directory, trial))
        ncp_moments = folder / _MOMENTS / f"{trial}_modeledMomentsNcp.sto"
        combined_moments = folder / _MOMENTS / f"{trial}_modeledMomentsMtpNcpCombined.sto"
        if ncp_moments.is_file():
            written.append(plot_moment_matching(
                read_storage(ncp_moments),
                read_storage(combined_moments) if combined_moments.is_file() else None,
                id_table, out / f"{trial}_momentMatching.png", trial,
            ))
        written.append(plot_activation_matching(
            ncp_activations, weights.labels, commands.time, mtp_table, out / f"{trial}_activationMatching.png", trial
        ))
    convergence = plot_results_convergence(folder, out, "NCP")
    if convergence is not None:
        written.append(convergence)
    return written
