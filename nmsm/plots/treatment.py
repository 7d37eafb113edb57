"""Figures of a Tracking/Verification/Design Optimization results folder.

``nmsm plot RESULTS_DIR`` calls :func:`plot_treatment_results` when
:func:`is_treatment_results` is true for the folder; ``nmsm plot --compare A B C`` draws A's
figures with B and C overlaid. Figures (PNG, written to ``RESULTS_DIR/plots`` unless
``output_dir`` is given):

``<trial>_kinematics.png``        state coordinates (deg or m) and speeds (deg/s or m/s) of the
                                  solution through the collocation polynomial
                                  (``Analysis/<trial>_statesInterpolated.sto``, the nodes as dots;
                                  the nodes alone when that file is missing), the tracked data
                                  dashed (``_trackedInterpolated.sto``)
``<trial>_loads.png``             inverse dynamics of the solution (``IDData``, N·m or N) on the
                                  controlled coordinates, with the torque controls
``<trial>_controls.png``          torque controls (N·m or N); ``_controls_synergy.png`` synergy commands
``<trial>_activations.png``       combined muscle activations
``<trial>_ground_reactions.png``  modeled ground reactions (``GRFData``, N), with the tracked
                                  ones dashed when the tracked-quantities folder named in the
                                  results' settings copy is found
``<trial>_convergence.png``       objective and constraint violation per IPOPT iteration
                                  (``<trial>_ipopt.log``)

The x axis is percent of the gait cycle for trials with ground contact (a ``GRFData``
folder: the trial is a gait cycle), time (s) otherwise. ``compare``: other results folders
(e.g. the original pipeline's, or VO and DO against TO) drawn on the same axes, matched by
column label and named by folder.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.core.convergence import ConvergenceHistory
from nmsm.io.storage import Table, read_storage, strip_load_suffix
from nmsm.plots import style
from nmsm.plots.convergence import plot_histories


def _trial(folder: Path) -> str | None:
    states = sorted(folder.glob("*_states.sto"))
    return states[0].name[: -len("_states.sto")] if states else None


def is_treatment_results(folder: str | os.PathLike[str]) -> bool:
    """True for a folder written by TO/VO/DO (a ``<trial>_states.sto`` next to ``IKData``)."""
    folder = Path(folder)
    return _trial(folder) is not None and (folder / "IKData").is_dir()


def _read(path: Path) -> Table | None:
    return read_storage(path, allow_nan=lambda label: True) if path.is_file() else None


@attrs.frozen
class Run:
    """A results folder drawn on the figures: its name in legends and its line style."""

    folder: Path
    name: str
    style: dict[str, Any]

    def table(self, relative: str) -> Table | None:
        return _read(self.folder / relative)


@attrs.frozen
class Axis:
    """The x axis of a trial's figures: percent of ``[start, end]`` s or time."""

    gait_cycle: bool
    start: float
    end: float

    def x(self, time: np.ndarray) -> np.ndarray:
        return style.cycle_axis(time, self.gait_cycle, self.start, self.end)[0]

    @property
    def label(self) -> str:
        return style.PERCENT_CYCLE if self.gait_cycle else style.TIME


def _rotational(label: str) -> bool:
    """Model-free guess used for units: coordinates ending in ``_tx``/``_ty``/``_tz`` are translations."""
    return not strip_load_suffix(label).endswith(("_tx", "_ty", "_tz"))


def _series(ax: Any, axis: Axis, runs: Sequence[Run], relative: str, label: str, factor: float = 1.0,
            nodes: str | None = None) -> None:
    """Draw column ``label`` of ``relative`` of every run; ``nodes``: the file holding the
    solution at the nodes, drawn as dots (and as the line when ``relative`` is missing)."""
    for run in runs:
        table = run.table(relative)
        node_table = run.table(nodes) if nodes else None
        if table is not None and table.has(label):
            ax.plot(axis.x(table.time), factor * table.column(label), label=run.name, **run.style)
        elif node_table is not None and node_table.has(label):
            ax.plot(axis.x(node_table.time), factor * node_table.column(label), label=run.name, **run.style)
        if node_table is not None and node_table.has(label) and table is not None:
            ax.plot(axis.x(node_table.time), factor * node_table.column(label), ls="none", marker=".", ms=2.5,
                    color=run.style.get("color"), label="_nodes")


def _reference(ax: Any, axis: Axis, table: Table | None, label: str, factor: float = 1.0,
               name: str = "tracked") -> None:
    if table is not None and table.has(label):
        ax.plot(axis.x(table.time), factor * table.column(label), label=name, **style.EXPERIMENTAL)


def _speeds_by_coordinate(states: Table) -> Table:
    """The speed columns (``<coordinate>_u``) of a states table, labelled by coordinate."""
    speeds = [label for label in states.labels if label.endswith("_u")]
    return Table(time=states.time, labels=tuple(s.removesuffix("_u") for s in speeds),
                 data=states.columns(speeds), in_degrees=states.in_degrees)


def _kinematics(plt_fig: tuple, axis: Axis, runs: Sequence[Run], trial: str, coords: Sequence[str]) -> None:
    _, _, axes = plt_fig
    dense = runs[0].table(f"Analysis/{trial}_trackedInterpolated.sto")
    tracked = dense or runs[0].table(f"Analysis/{trial}_trackedPositions.sto")
    tracked_speeds = _speeds_by_coordinate(dense) if dense is not None else \
        runs[0].table(f"Analysis/{trial}_trackedVelocities.sto")
    for j, c in enumerate(coords):
        rot = _rotational(c)
        factor = float(np.degrees(1.0)) if rot else 1.0
        top, bottom = axes[j], axes[len(coords) + j]
        _series(top, axis, runs, f"Analysis/{trial}_statesInterpolated.sto", c, factor, f"{trial}_states.sto")
        _reference(top, axis, tracked, c, factor)
        top.set_title(c)
        top.set_ylabel("deg" if rot else "m")
        speed = f"{c}_u"
        _series(bottom, axis, runs, f"Analysis/{trial}_statesInterpolated.sto", speed, factor, f"{trial}_states.sto")
        _reference(bottom, axis, tracked_speeds, c, factor)
        bottom.set_title(f"{c} speed")
        bottom.set_ylabel("deg/s" if rot else "m/s")
        bottom.set_xlabel(axis.label)


def _load_unit(label: str) -> str:
    return "N" if label.endswith("_force") or not _rotational(label) else "N·m"


def _columns_figure(path: Path, title: str, axis: Axis, runs: Sequence[Run], relative: str, labels: Sequence[str],
                    unit: Any, extra: Any = None) -> Path:
    plt, fig, axes = style.panels(len(labels))
    for ax, label in zip(axes, labels):
        _series(ax, axis, runs, relative, label)
        if extra is not None:
            extra(ax, label)
        ax.set_title(label)
        ax.set_ylabel(unit(label) if callable(unit) else unit)
        ax.set_xlabel(axis.label)
    return style.save(plt, fig, path, title)


def ipopt_iterations(path: Path) -> np.ndarray:
    """(n, 3) iteration, objective, constraint violation (``inf_pr``) of an IPOPT log's table."""
    rows = []
    pattern = re.compile(r"^\s*(\d+)r?\s+(\S+)\s+(\S+)\s+\S+\s")
    for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
        match = pattern.match(line)
        if match:
            try:
                rows.append((float(match.group(1)), float(match.group(2)), float(match.group(3))))
            except ValueError:
                continue
    return np.array(rows).reshape(-1, 3)


def plot_convergence(log: Path, path: Path, title: str) -> Path | None:
    """Objective and constraint violation per IPOPT iteration of ``log``; None without iterations."""
    table = ipopt_iterations(log)
    if table.shape[0] == 0:
        return None
    history = ConvergenceHistory(cost=table[:, 1], violation=table[:, 2])
    return plot_histories({"IPOPT": history}, path, title, iteration_label="IPOPT iteration")


def _tracked_folder(folder: Path) -> Path | None:
    """The tracked-quantities folder named in the settings copy of a results folder, when it exists."""
    from lxml import etree

    from nmsm.io.xml_input import xml_parser

    for settings in sorted(folder.glob("*.xml")):
        try:
            root = etree.parse(str(settings), xml_parser()).getroot()
        except (etree.XMLSyntaxError, OSError):
            continue
        for element in root.iter("tracked_quantities_directory"):
            text = (element.text or "").strip()
            for base in (folder, folder.parent):
                candidate = (base / text).resolve()
                if text and candidate.is_dir():
                    return candidate
    return None


def _ground_reactions(path: Path, title: str, axis: Axis, runs: Sequence[Run], trial: str) -> Path | None:
    modeled = runs[0].table(f"GRFData/{trial}.sto")
    if modeled is None:
        return None
    forces = [label for label in modeled.labels if re.search(r"(force_v[xyz]|_F[xyz]|_v[xyz])$", label)]
    forces = forces or list(modeled.labels[:3])
    tracked_folder = _tracked_folder(runs[0].folder)
    tracked = _read(tracked_folder / "GRFData" / f"{trial}.sto") if tracked_folder is not None else None
    if tracked is not None:
        tracked = attrs.evolve(tracked, time=tracked.time - tracked.time[0] + modeled.time[0])

    def experimental(ax: Any, label: str) -> None:
        _reference(ax, axis, tracked, label, name="experimental")

    return _columns_figure(path, title, axis, runs, f"GRFData/{trial}.sto", forces, "N", experimental)


def plot_treatment_results(results_dir: str | os.PathLike[str], output_dir: str | os.PathLike[str] | None = None,
                           compare: Sequence[str | os.PathLike[str]] = (), *, prefix: str = "") -> list[Path]:
    """Write the figures listed in the module docstring (file names preceded by ``prefix``);
    returns their paths."""
    folder = Path(results_dir)
    trial = _trial(folder)
    if trial is None:
        raise FileNotFoundError(f"{folder} holds no <trial>_states.sto: not a treatment optimization results folder")
    out_dir = Path(output_dir) if output_dir is not None else folder / "plots"
    # a failed solve's last iterate (``last_iterate/`` with its diagnosis) must not look converged
    note = " - LAST ITERATE, NOT CONVERGED (diagnosis.txt)" if (folder / "diagnosis.txt").is_file() else ""
    names = [folder.resolve().name] + [Path(c).resolve().name for c in compare]
    if len(set(names)) < len(names):  # folders of the same name: the path relative to the common parent
        common = Path(os.path.commonpath([str(folder.resolve())] + [str(Path(c).resolve()) for c in compare]))
        names = [str(Path(f).resolve().relative_to(common)) or Path(f).name for f in [folder, *compare]]
    runs = [Run(folder, names[0], style.SOLUTION)]
    runs += [Run(Path(c), name, {"color": style.COMPARED_COLORS[k % len(style.COMPARED_COLORS)]})
             for k, (c, name) in enumerate(zip(compare, names[1:]))]
    states = read_storage(folder / f"{trial}_states.sto")
    axis = Axis((folder / "GRFData").is_dir(), float(states.time[0]), float(states.time[-1]))
    what = " vs ".join(names) if compare else names[0]

    def target(name: str) -> Path:
        return out_dir / f"{prefix}{trial}_{name}.png"

    written: list[Path] = []
    coords = [label for label in states.labels if not label.endswith("_u")]
    fig = style.panels(2 * len(coords))
    _kinematics(fig, axis, runs, trial, coords)
    written.append(style.save(fig[0], fig[1], target("kinematics"), f"{trial}: state kinematics ({what}){note}"))
    ids = runs[0].table(f"IDData/{trial}.sto")
    torque = runs[0].table(f"{trial}_torqueControls.sto")
    if ids is not None:
        loads = [label for label in ids.labels if strip_load_suffix(label) in coords]

        def torque_control(ax: Any, label: str) -> None:
            coordinate = strip_load_suffix(label)
            if torque is not None and torque.has(coordinate):
                ax.plot(axis.x(torque.time), torque.column(coordinate), color="C1", ls=":", label="torque control")

        written.append(_columns_figure(target("loads"), f"{trial}: joint loads ({what}){note}", axis, runs,
                                       f"IDData/{trial}.sto", loads, _load_unit, torque_control))
    for file, name, title, unit in ((f"{trial}_torqueControls.sto", "controls", "torque controls", _load_unit),
                                    (f"{trial}_synergyCommands.sto", "controls_synergy", "synergy commands", "-")):
        table = runs[0].table(file)
        if table is not None:
            written.append(_columns_figure(target(name), f"{trial}: {title} ({what}){note}", axis, runs, file,
                                           table.labels, unit))
    activations = runs[0].table(f"{trial}_combinedActivations.sto")
    if activations is not None:
        written.append(_columns_figure(target("activations"), f"{trial}: muscle activations ({what}){note}", axis,
                                       runs, f"{trial}_combinedActivations.sto", activations.labels, "activation (-)"))
    reactions = _ground_reactions(target("ground_reactions"), f"{trial}: ground reactions ({what}){note}", axis, runs,
                                  trial)
    if reactions is not None:
        written.append(reactions)
    log = folder / f"{trial}_ipopt.log"
    if log.is_file():
        figure = plot_convergence(log, target("convergence"), f"{trial}: IPOPT convergence ({names[0]}){note}")
        if figure is not None:
            written.append(figure)
    return written
