"""Figures of a Ground Contact Personalization results folder (``nmsm plot RESULTS_DIR``).

:func:`plot_gcp_results` reads only files of the results folder (ours or the MATLAB
original's): per foot ``<n>`` the ``*_Foot_<n>_optimizedGroundReactions.sto``,
``*_replacedExperimentalGroundReactions.sto``, ``*_optimizedFootKinematics.sto``,
``*_experimentalFootKinematics.sto``, and the ``*.osimx`` holding the springs. It saves PNG
files into ``<results>/plots`` (or ``output_directory``):

* ``Foot_<n>_forces.png``: Fx, Fy, Fz (N), modeled and experimental;
* ``Foot_<n>_moments.png``: Mx, My, Mz (N m) about the midfoot-superior point;
* ``Foot_<n>_kinematics.png``: the seven foot coordinates (deg, mm), optimized and
  experimental;
* ``Foot_<n>_stiffness.png``: the spring constants (N/m) over the sole in the hindfoot's
  x-z plane (toes springs moved into the hindfoot frame with the toes joint at 0 when the
  ``.osimx``'s associated model can be read, else drawn in the toes frame). The last
  contact surfaces of the ``.osimx`` belong to the feet, in foot order.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from nmsm.errors import InputError
from nmsm.io.osimx import OsimxContactSurface, read_osimx
from nmsm.io.storage import Table, read_storage
from nmsm.plots import style
from nmsm.plots.convergence import plot_results_convergence

_FOOT = re.compile(r"_Foot_(\d+)_optimizedGroundReactions\.sto$")


def _pyplot():
    return style.pyplot()


def _foot_files(folder: Path) -> dict[int, str]:
    """Foot index -> file prefix (text before ``_Foot_<n>_``)."""
    found: dict[int, str] = {}
    for path in sorted(folder.glob("*_Foot_*_optimizedGroundReactions.sto")):
        match = _FOOT.search(path.name)
        if match:
            found[int(match.group(1))] = path.name[: match.start()]
    return found


def plot_reactions(modeled: Table, experimental: Table, columns: tuple[str, ...], unit: str, path: Path,
                   title: str) -> Path:
    """One panel per column: modeled and experimental over time."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(columns), figsize=(4 * len(columns), 3.4))
    for ax, column in zip(np.atleast_1d(axes), columns):
        ax.plot(experimental.time, experimental.column(column), label="experimental", **style.EXPERIMENTAL)
        ax.plot(modeled.time, modeled.column(column), label="modeled", **style.SOLUTION)
        rms = float(np.sqrt(np.mean((modeled.column(column) - experimental.column(column)) ** 2)))
        ax.set_title(f"{column} (RMS error {rms:.3g} {unit})")
        ax.set_xlabel("time (s)")
        ax.set_ylabel(unit)
    fig.suptitle(title)
    style.legend_below(fig)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_kinematics(optimized: Table, experimental: Table, path: Path, title: str) -> Path:
    """The seven foot coordinates: rotations in degrees, translations in mm."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 4, figsize=(15, 6))
    for k, (ax, label) in enumerate(zip(axes.ravel(), optimized.labels)):
        factor, unit = (180.0 / np.pi, "deg") if k < 4 else (1000.0, "mm")
        ax.plot(experimental.time, factor * experimental.data[:, k], label="experimental", **style.EXPERIMENTAL)
        ax.plot(optimized.time, factor * optimized.data[:, k], label="optimized", **style.SOLUTION)
        ax.set_title(label)
        ax.set_ylabel(unit)
        ax.set_xlabel("time (s)")
    axes.ravel()[-1].axis("off")
    fig.suptitle(title)
    style.legend_below(fig)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def _toes_pose(osimx_path: Path, associated: str, surface: OsimxContactSurface) -> tuple[np.ndarray, np.ndarray] | None:
    """``(R, p)`` of the toes frame in the hindfoot frame (toes joint at 0) from the
    ``.osimx``'s associated model, or None when that model cannot be read."""
    from nmsm.errors import NmsmError
    from nmsm.model.osim import load_model

    name = Path(associated.replace("\\", "/")).name
    # the associated path as written, else a file of that name next to the .osimx or up to
    # three folders above it (a results folder inside the settings folder)
    candidates = [Path(associated)] + [folder / name for folder in list(osimx_path.resolve().parents)[:4]]
    model_path = next((p for p in candidates if p.is_file()), None)
    if model_path is None:
        return None
    try:
        model = load_model(model_path)
    except NmsmError:
        return None
    joint = next((j for j in model.joints if j.parent_body == surface.hindfoot_body and len(j.coordinates) == 1),
                 None)
    if joint is None:
        return None
    parent, child = model.frames[joint.parent_frame], model.frames[joint.child_frame]
    rotation = parent.rotation_in_base @ child.rotation_in_base.T
    return rotation, parent.origin_in_base - rotation @ child.origin_in_base


def plot_stiffness(surface: OsimxContactSurface, path: Path, title: str,
                   toes_pose: tuple[np.ndarray, np.ndarray] | None) -> Path:
    """Spring constants over the sole (x forward, z lateral, hindfoot frame)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(4.5, 7))
    hind = surface.hindfoot_body
    xs, zs, ks, on_toes = [], [], [], []
    for spring in surface.springs:
        location = np.asarray(spring.location, dtype=float)
        toes = spring.parent_body != hind
        if toes and toes_pose is not None:
            location = toes_pose[1] + toes_pose[0] @ location
        x, _, z = location
        xs.append(x)
        zs.append(z)
        ks.append(spring.spring_constant)
        on_toes.append(toes)
    on_toes_a = np.array(on_toes)
    points = ax.scatter(zs, xs, c=ks, s=90, cmap="viridis",
                        marker="o", edgecolors=np.where(on_toes_a, "r", "k"))
    fig.colorbar(points, ax=ax, label="spring constant (N/m)")
    ax.set_xlabel("z (m)")
    ax.set_ylabel("x (m)")
    ax.set_aspect("equal")
    note = "" if toes_pose is not None or not on_toes_a.any() else " (toes springs in the toes frame)"
    ax.set_title(title + note + "\nred edge: toes springs", fontsize=9)
    style.legend_below(fig)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_gcp_results(results_directory: str | os.PathLike[str],
                     output_directory: str | os.PathLike[str] | None = None) -> list[Path]:
    """Save the GCP figures of ``results_directory`` (module docstring); returns the files."""
    folder = Path(results_directory)
    feet = _foot_files(folder)
    if not feet:
        raise InputError("not a GCP results folder: no *_Foot_<n>_optimizedGroundReactions.sto", file=folder,
                         expected="a folder written by Ground Contact Personalization")
    out = Path(output_directory) if output_directory is not None else folder / "plots"
    out.mkdir(parents=True, exist_ok=True)
    osimx_files = sorted(folder.glob("*.osimx"))
    osimx = read_osimx(osimx_files[0]) if osimx_files else None
    written: list[Path] = []
    for n, prefix in feet.items():
        base = folder / f"{prefix}_Foot_{n}_"
        modeled = read_storage(f"{base}optimizedGroundReactions.sto")
        experimental = read_storage(f"{base}replacedExperimentalGroundReactions.sto")
        written.append(plot_reactions(modeled, experimental, ("Fx", "Fy", "Fz"), "N", out / f"Foot_{n}_forces.png",
                                      f"Foot {n}: ground reaction forces"))
        written.append(plot_reactions(modeled, experimental, ("Mx", "My", "Mz"), "N m", out / f"Foot_{n}_moments.png",
                                      f"Foot {n}: ground reaction moments"))
        optimized_kin = Path(f"{base}optimizedFootKinematics.sto")
        experimental_kin = Path(f"{base}experimentalFootKinematics.sto")
        if optimized_kin.is_file() and experimental_kin.is_file():
            written.append(plot_kinematics(read_storage(optimized_kin), read_storage(experimental_kin),
                                           out / f"Foot_{n}_kinematics.png", f"Foot {n}: foot kinematics"))
        surfaces = osimx.contact_surfaces[-len(feet):] if osimx is not None else ()
        position = sorted(feet).index(n)
        if position < len(surfaces):
            surface = surfaces[position]
            pose = _toes_pose(osimx_files[0], osimx.associated_osim_model, surface)
            written.append(plot_stiffness(surface, out / f"Foot_{n}_stiffness.png", f"Foot {n}: spring constants",
                                          pose))
    convergence = plot_results_convergence(folder, out, "GCP")
    if convergence is not None:
        written.append(convergence)
    return written
