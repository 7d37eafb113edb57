"""IK, ID and MuscleAnalysis for preprocessing: nmsm's model core or OpenSim (the user's choice).

``engine``:

``"nmsm"``     nmsm's own model core: IK (:func:`nmsm.tools.jmp.ik.run_ik_files`), inverse
               dynamics (:func:`nmsm.model.id_tool.inverse_dynamics_of_motion`), muscle
               analysis (:func:`nmsm.model.muscle_analysis.analyze_motion`, path-point muscles
               exactly, wrapping muscles from OpenSim when available);
``"opensim"``  OpenSim's tools run in the bridge worker (InverseKinematicsTool,
               InverseDynamicsTool, AnalyzeTool + MuscleAnalysis).

Outputs are files, as the original's preprocessing expects them: a motion (.mot), an ID
table (.sto) and a muscle-analysis folder with ``<name>_MuscleAnalysis_Length.sto``,
``..._Velocity.sto`` (muscle-tendon velocity) and ``..._MomentArm_<coordinate>.sto``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from nmsm.errors import InputError
from nmsm.io.storage import write_storage

ENGINES = ("nmsm", "opensim")


def _check(engine: str) -> None:
    if engine not in ENGINES:
        raise InputError(f"unknown engine '{engine}'", element="--engine", expected=" or ".join(ENGINES))


def inverse_kinematics(model_file: str | os.PathLike[str], marker_file: str | os.PathLike[str],
                       output: str | os.PathLike[str], *, engine: str = "nmsm",
                       ik_settings: str | os.PathLike[str] | None = None) -> Path:
    """Coordinates over the marker trial written to ``output`` (.mot); ``ik_settings`` (an
    OpenSim IK setup file) gives marker weights, time range and accuracy to either engine."""
    _check(engine)
    out = Path(output)
    out.parent.mkdir(parents=True, exist_ok=True)
    if engine == "nmsm":
        from nmsm.tools.jmp.ik import run_ik_files

        run_ik_files(model_file, marker_file, ik_settings=ik_settings, output=out)
    else:
        from nmsm.opensim_bridge import get_bridge
        from nmsm.tools.jmp.ik_settings import read_ik_settings

        settings = read_ik_settings(ik_settings) if ik_settings is not None else None
        options = {} if settings is None else {
            "marker_weights": settings.marker_weights, "time_range": settings.time_range,
            **({"accuracy": settings.accuracy} if settings.accuracy is not None else {})}
        get_bridge().call("opensim_inverse_kinematics_tool", model=str(Path(model_file).resolve()),
                          marker_file=str(Path(marker_file).resolve()), output_motion=str(out.resolve()), **options)
    return out


def inverse_dynamics(model_file: str | os.PathLike[str], motion_file: str | os.PathLike[str],
                     output: str | os.PathLike[str], *, engine: str = "nmsm",
                     external_loads: str | os.PathLike[str] | None = None, lowpass_hz: float | None = 6.0) -> Path:
    """Generalized forces over the motion written to ``output`` (.sto), OpenSim's ID tool semantics."""
    _check(engine)
    out = Path(output)
    out.parent.mkdir(parents=True, exist_ok=True)
    if engine == "nmsm":
        from nmsm.io.storage import read_storage
        from nmsm.model import load_model
        from nmsm.model.external_loads import read_external_loads
        from nmsm.model.id_tool import inverse_dynamics_of_motion

        loads = read_external_loads(external_loads) if external_loads else None
        table = inverse_dynamics_of_motion(load_model(model_file), read_storage(motion_file), external_loads=loads,
                                           lowpass_hz=lowpass_hz)
        write_storage(out, table, name="Inverse Dynamics Generalized Forces")
    else:
        from nmsm.opensim_bridge import get_bridge

        get_bridge().call("oracle_inverse_dynamics_tool", model_path=str(Path(model_file).resolve()),
                          coordinates_file=str(Path(motion_file).resolve()), output_file=str(out.resolve()),
                          external_loads_file=str(Path(external_loads).resolve()) if external_loads else None,
                          lowpass_hz=float(lowpass_hz) if lowpass_hz else -1.0)
    return out


def muscle_analysis(model_file: str | os.PathLike[str], motion_file: str | os.PathLike[str],
                    directory: str | os.PathLike[str], *, engine: str = "nmsm",
                    muscles: Sequence[str] | None = None, coordinates: Sequence[str] | None = None,
                    name: str = "trial", velocity_cutoff: float | None = 10.0) -> Path:
    """Muscle-tendon lengths, velocities and moment arms along the motion, in ``directory``.

    With OpenSim the velocity file is made from the lengths (:mod:`.velocity`); nmsm's
    muscle analysis differentiates the path exactly (``V = sum dL/dq qdot``).
    """
    _check(engine)
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    if engine == "nmsm":
        from nmsm.model.muscle_analysis import analyze_motion

        result = analyze_motion(model_file, motion_file, muscles=muscles, coordinates=coordinates, engine="auto")
        for quantity in ["Length", "Velocity"] + [f"MomentArm_{c}" for c in result.coordinates]:
            write_storage(out / f"{name}_MuscleAnalysis_{quantity}.sto", result.table(quantity), name=quantity)
    else:
        from nmsm.opensim_bridge import get_bridge
        from nmsm.tools.preprocess.velocity import create_velocity_file

        get_bridge().call("run_muscle_analysis", model=str(Path(model_file).resolve()),
                          coordinates_file=str(Path(motion_file).resolve()), results_directory=str(out.resolve()),
                          name=name, muscles=list(muscles) if muscles else None,
                          moment_arm_coordinates=list(coordinates) if coordinates else None)
        create_velocity_file(out / f"{name}_MuscleAnalysis_Length.sto", velocity_cutoff)
    return out
