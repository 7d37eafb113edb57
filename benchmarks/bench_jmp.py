"""Benchmark: Joint Model Personalization of the tutorial (subject 3, simultaneous settings).

Times, on this machine:

1. ``run_settings(JMPSettingsSimultaneous.xml)`` end to end (settings, model, 506 frames of
   12 markers, IK before, the joint solve of 6072 coordinates + 23 parameters, writing the
   model with OpenSim's muscle rescaling through the bridge, IK after, reports), with a
   breakdown per stage. The first repetition includes starting the OpenSim worker.
2. For reference, OpenSim's IK of the same trial and markers (weight 1, the settings'
   accuracy 1e-6), timed inside the worker: the solver loop alone and the whole
   InverseKinematicsTool (model initialization, solve, writing). The original JMP runs one
   such IK per cost evaluation of its finite-difference least squares.
3. nmsm's IK of the same trial.
4. IK of the tutorial GaitTrial with IKSettingsGait.xml (32 markers) at OpenSim's default
   accuracy 1e-5 and at 1e-8: OpenSim's solver loop vs nmsm's, and their differences.

    python benchmarks/bench_jmp.py [--reps 3]

Prints measured numbers only (``time.perf_counter``), with the load average before and after
(the machine is shared: numbers are meaningful when it is quiet).
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
import warnings
from pathlib import Path

SHARED = Path(os.environ.get("NMSM_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
FOLDER = SHARED / "jmp" / "uf_subject3_tutorial"
SETTINGS = FOLDER / "CompletedSettingsFiles" / "JMPSettingsSimultaneous.xml"


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reps", type=int, default=3, help="repetitions of each measurement (3)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    print(f"load average before: {_load()}  (cores: {os.cpu_count()})")

    from nmsm.opensim_bridge import get_bridge
    from nmsm.tools.jmp.ik import inverse_kinematics
    from nmsm.tools.jmp.run import run_settings

    runs = []
    for rep in range(args.reps):
        with tempfile.TemporaryDirectory(prefix="nmsm-bench-jmp-") as out:
            start = time.perf_counter()
            run = run_settings(SETTINGS, results_directory=out, quiet=True)
            total = time.perf_counter() - start
        task = run.tasks[0]
        runs.append(total)
        print(f"run {rep + 1}: total {total:6.2f} s | IK before {task.before.wall_time:5.2f} s "
              f"({task.trial.n_frames} frames) | joint solve {task.solution.wall_time:5.2f} s "
              f"({task.solution.iterations} iterations, {task.solution.evaluations} evaluations, "
              f"{task.solution.status}) | IK after {task.after.wall_time:5.2f} s | marker RMS "
              f"{1000 * task.before.marker_rms():.3f} -> {1000 * task.after.marker_rms():.3f} mm")
    print(f"nmsm JMP simultaneous: median {statistics.median(runs):.2f} s, min {min(runs):.2f} s "
          f"over {len(runs)} runs (first includes the OpenSim worker start)")

    trial = run.tasks[0].trial
    weights = {m: 1.0 for m in trial.names}
    model_file = run.settings.input_model_file
    marker_file = run.tasks[0].task.marker_file_name
    time_range = run.tasks[0].task.time_range
    bridge = get_bridge()
    solver, tool = [], []
    for _ in range(args.reps):
        reply = bridge.call("opensim_inverse_kinematics", model=str(model_file), marker_file=str(marker_file),
                            marker_weights=weights, time_range=time_range, accuracy=1e-6)
        solver.append(reply["solve_seconds"])
        with tempfile.TemporaryDirectory(prefix="nmsm-bench-ik-") as out:
            reply_tool = bridge.call("opensim_inverse_kinematics_tool", model=str(model_file),
                                     marker_file=str(marker_file), output_motion=str(Path(out) / "ik.mot"),
                                     marker_weights=weights, time_range=time_range, accuracy=1e-6)
        tool.append(reply_tool["seconds"])
    n = reply["q"].shape[0]
    print(f"OpenSim IK, same trial ({n} frames, {len(weights)} markers, accuracy 1e-6): solver loop median "
          f"{statistics.median(solver):.2f} s ({1000 * statistics.median(solver) / n:.1f} ms/frame); "
          f"InverseKinematicsTool median {statistics.median(tool):.2f} s")
    ours = []
    for _ in range(args.reps):
        result = inverse_kinematics(model_file, trial, accuracy=1e-6, check_marker_units=False)
        ours.append(result.wall_time)
    print(f"nmsm IK, same trial and accuracy: median {statistics.median(ours):.2f} s "
          f"({1000 * statistics.median(ours) / n:.1f} ms/frame)")
    _gait_ik(args.reps)
    print(f"load average after: {_load()}")
    return 0


def _gait_ik(reps: int) -> None:
    import numpy as np

    from nmsm.opensim_bridge import get_bridge
    from nmsm.tools.jmp.ik import inverse_kinematics
    from nmsm.tools.jmp.ik_settings import read_ik_settings

    settings = read_ik_settings(FOLDER / "IKSettingsFiles" / "IKSettingsGait.xml")
    model_file = FOLDER / "CompletedSettingsFiles" / "UF_Subject_3_Scaled.osim"
    for accuracy in (1e-5, 1e-8):
        theirs, ours = [], []
        for _ in range(reps):
            reply = get_bridge().call("opensim_inverse_kinematics", model=str(model_file),
                                      marker_file=str(settings.marker_file), marker_weights=settings.marker_weights,
                                      time_range=settings.time_range, accuracy=accuracy)
            theirs.append(reply["solve_seconds"])
            result = inverse_kinematics(model_file, settings.marker_file, weights=settings.marker_weights,
                                        time_range=settings.time_range, accuracy=accuracy)
            ours.append(result.wall_time)
        n = result.n_frames
        free = [k for k, c in enumerate(result.coordinate_names) if c in result.free_names]
        rotational = [k for k in free if result.coordinate_names[k] in result.rotational]
        translational = [k for k in free if k not in rotational]
        diff = result.q - reply["q"]
        rms = np.sqrt(np.mean(diff**2, axis=0))
        their_rms = float(np.sqrt(np.nanmean(reply["errors"] ** 2)))
        print(f"GaitTrial IK ({n} frames, {len(settings.marker_weights)} markers), accuracy {accuracy:g}: OpenSim solver "
              f"loop median {statistics.median(theirs):.2f} s ({1000 * statistics.median(theirs) / n:.1f} ms/frame), "
              f"nmsm median {statistics.median(ours):.2f} s ({1000 * statistics.median(ours) / n:.1f} ms/frame); "
              f"coordinate RMS difference max {np.degrees(rms[rotational].max()):.5f} deg, "
              f"{1000 * rms[translational].max():.5f} mm; marker RMS {1000 * result.marker_rms():.4f} vs "
              f"{1000 * their_rms:.4f} mm")


if __name__ == "__main__":
    raise SystemExit(main())
