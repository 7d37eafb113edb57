"""Writing a task's optimized values into a new ``.osim`` (the original text edited in place).

Order, as the original applies them: joint offset frames, then body scale factors, then
marker locations.

Body scaling reproduces ``Model.scale(state, scales, preserveMassDist=true, mass=-1)`` as
the original calls it: geometry on the body (offset frames, path points, wrap objects,
contact geometry, display-mesh scale factors, CustomJoint translation functions) and the
centre of mass scale, the mass stays and the inertia scales by ``s**2``
(:meth:`~nmsm.model.osim_writer.OsimWriter.scale_body`); the markers of the body are put
back where they were unless the task has ``anatomical_markers``. Muscle optimal fibre and
tendon slack lengths change by the ratio of path lengths in the default pose after/before
scaling, which needs wrapping geometry: they are taken from OpenSim's own ``Model.scale``
through the bridge. Without OpenSim they are left unchanged, with a warning.
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import numpy as np

from nmsm.model.components import Model
from nmsm.model.osim_writer import OsimWriter
from nmsm.tools.jmp.design import TaskDesign

#: relative change below which a muscle length is left as written
_MUSCLE_TOLERANCE = 1e-12


def _grouped(model: Model, design: TaskDesign, values: np.ndarray) -> tuple[dict, dict, dict, dict]:
    translations: dict[str, np.ndarray] = {}
    orientations: dict[str, np.ndarray] = {}
    scales: dict[str, float] = {}
    markers: dict[str, np.ndarray] = {}
    for variable, value in zip(design.variables, values):
        if variable.kind == "translation":
            translations.setdefault(variable.target, model.frames[variable.target].translation.copy())[
                variable.component] = value
        elif variable.kind == "orientation":
            orientations.setdefault(variable.target, model.frames[variable.target].orientation.copy())[
                variable.component] = value
        elif variable.kind == "scale":
            scales[variable.target] = float(value)
        else:
            markers.setdefault(variable.target, model.marker(variable.target).location.copy())[
                variable.component] = value
    return translations, orientations, scales, markers


def opensim_scaled_muscle_lengths(model_file: Path, scales: dict[str, float]) -> dict[str, tuple[float, float]] | None:
    """(optimal fibre length, tendon slack length) of every muscle after OpenSim's
    ``Model.scale`` of ``model_file`` by ``scales`` (None when OpenSim is not installed)."""
    from nmsm.opensim_bridge import get_bridge, opensim_available

    if not opensim_available():
        return None
    with tempfile.TemporaryDirectory(prefix="nmsm-jmp-scale-") as folder:
        reply = get_bridge().call("opensim_scale_bodies", model=str(Path(model_file).resolve()),
                                  output=str(Path(folder) / "scaled.osim"), factors=scales,
                                  preserve_mass_distribution=True)
    return {name: (float(a), float(b)) for name, (a, b) in reply["muscles"].items()}


def write_task_model(model: Model, source: Path, design: TaskDesign, values: np.ndarray, target: Path, *,
                     anatomical_markers: bool) -> list[str]:
    """Write ``source`` with the task's ``values`` applied to ``target``; returns notes for the
    report (what changed besides the design variables)."""
    values = np.asarray(values, dtype=float)
    translations, orientations, scales, moved = _grouped(model, design, values)
    writer = OsimWriter(source)
    for path, vector in translations.items():
        writer.set_frame_translation(path, vector)
    for path, vector in orientations.items():
        writer.set_frame_orientation(path, vector)
    notes: list[str] = []
    scales = {body: s for body, s in scales.items() if s != 1.0}
    if scales:
        with tempfile.TemporaryDirectory(prefix="nmsm-jmp-") as folder:
            before_scaling = writer.write(Path(folder) / "before_scaling.osim")
            muscles = opensim_scaled_muscle_lengths(before_scaling, scales) if model.muscles else {}
        for body, factor in scales.items():
            writer.scale_body(body, factor, scale_mass=False)
            if not anatomical_markers:
                for marker in model.markers:
                    if marker.body == body:
                        writer.set_marker_location(marker.name, marker.location)
        if muscles is None:
            warnings.warn("OpenSim is not installed: muscle optimal fiber and tendon slack lengths were not rescaled "
                          "for the scaled bodies (OpenSim's Model.scale would change them by the path-length ratio)",
                          stacklevel=2)
            notes.append("muscle optimal fiber / tendon slack lengths NOT rescaled (OpenSim not available)")
        else:
            changed = 0
            for muscle in model.muscles:
                new = muscles.get(muscle.name)
                if new is None:
                    continue
                for prop, old, value in (("optimal_fiber_length", muscle.optimal_fiber_length, new[0]),
                                         ("tendon_slack_length", muscle.tendon_slack_length, new[1])):
                    if abs(value - old) > _MUSCLE_TOLERANCE * max(abs(old), 1e-12):
                        writer.set_muscle_property(muscle.name, prop, value)
                        changed += 1
            notes.append(f"{changed} muscle fiber/tendon lengths rescaled by OpenSim's Model.scale path-length ratios")
        notes.append("scaled " + ", ".join(f"{b} x{s:.6f}" for b, s in scales.items())
                     + ("" if anatomical_markers else " (markers of the scaled bodies kept in place)"))
    for name, location in moved.items():
        body = model.marker(name).body
        factor = scales.get(body, 1.0) if anatomical_markers else 1.0
        writer.set_marker_location(name, location * factor)
    target.parent.mkdir(parents=True, exist_ok=True)
    writer.write(target)
    return notes
