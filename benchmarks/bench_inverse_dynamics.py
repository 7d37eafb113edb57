"""Benchmark: inverse dynamics of the full-body RCNL2024 model (41 coordinates), 101 frames.

Measures (wall time, ``time.perf_counter``, best of ``--repeats``):

* nmsm: CasADi inverse dynamics (with two ground-reaction loads) mapped over 101 frames
  (``map(101, "thread", 2)``), and ID plus its full Jacobian w.r.t. (q, qdot, qddot);
* OpenSim 4.6: ``InverseDynamicsSolver.solve`` per frame, timed inside the bridge worker
  (no IPC, no model loading; muscles disabled as the ID tool does), and the cost a
  forward-difference Jacobian would need: per-frame time x (1 + 3 n) x 101 frames.

Motion: the tutorial gait trial (101 frames; qdot, qddot from a quintic spline) with
random ground reactions. ``--codegen`` also times the functions compiled to C (cached).

    python benchmarks/bench_inverse_dynamics.py [--repeats 5] [--codegen]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from nmsm.io.storage import read_storage
from nmsm.model import CasadiModel, load_model
from nmsm.model.id_tool import motion_coordinates
from nmsm.model.signal import quintic_spline
from nmsm.opensim_bridge import get_bridge

SHARED = Path(os.environ.get("NMSM_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
MODEL = SHARED / "models" / "RCNL2024.osim"
MOTION = SHARED / "mtp" / "uf_subject3_tutorial" / "preprocessed" / "IKData" / "gait_1.sto"
FRAMES = 101


def best_time(call, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--codegen", action="store_true", help="also time C-compiled functions")
    args = parser.parse_args()

    start = time.perf_counter()
    model = load_model(MODEL)
    cm = CasadiModel(model)
    n = cm.n
    motion = read_storage(MOTION)
    values, _ = motion_coordinates(model, motion)
    if motion.in_degrees:
        rot = [i for i, c in enumerate(model.coordinates) if c.motion_type == "rotational"]
        values[:, rot] = np.deg2rad(values[:, rot])
    q, qd, qdd = quintic_spline(motion.time, values, motion.time)
    q, qd, qdd = q[:FRAMES], qd[:FRAMES], qdd[:FRAMES]
    rng = np.random.default_rng(0)
    loads = np.zeros((9, 2 * FRAMES))
    loads[0:3] = rng.normal(0, 100, (3, 2 * FRAMES)) + np.array([[0], [700], [0]])
    loads[3:6] = rng.normal(0, 0.2, (3, 2 * FRAMES))
    loads[6:9] = rng.normal(0, 5, (3, 2 * FRAMES))

    id_frame = cm.inverse_dynamics_function(["calcn_r", "calcn_l"])
    setup = time.perf_counter() - start
    start = time.perf_counter()
    jac_frame = cm.inverse_dynamics_jacobian_function(["calcn_r", "calcn_l"])  # tau and its 3 Jacobian blocks
    jac_build = time.perf_counter() - start
    id_map = id_frame.map(FRAMES, "thread", 2)
    jac_map = jac_frame.map(FRAMES, "thread", 2)
    inputs = (q.T, qd.T, qdd.T, loads)
    id_map(*inputs)
    jac_map(*inputs)
    t_id = best_time(lambda: id_map(*inputs), args.repeats)
    t_jac = best_time(lambda: jac_map(*inputs), args.repeats)

    print(f"model: {MODEL.name}, {n} coordinates, {len(model.bodies)} bodies; motion {MOTION.name}, {FRAMES} frames")
    print(f"nmsm setup (parse + build ID function): {setup:.3f} s; Jacobian function build: {jac_build:.3f} s")
    print(f"ID SX function: {id_frame.n_instructions()} instructions; ID+Jacobian: {jac_frame.n_instructions()}")
    print(f"nmsm ID, {FRAMES} frames (map, thread x2):              {t_id * 1e3:9.3f} ms "
          f"({t_id / FRAMES * 1e6:.1f} us/frame)")
    print(f"nmsm ID + Jacobian wrt (q, qdot, qddot) [{n}x{3 * n}] x {FRAMES}: {t_jac * 1e3:9.3f} ms "
          f"({t_jac / FRAMES * 1e6:.1f} us/frame)")

    compiled_times = None
    if args.codegen:
        from nmsm.model.codegen import compiled

        start = time.perf_counter()
        id_c = compiled(id_frame).map(FRAMES, "thread", 2)
        jac_c = compiled(jac_frame).map(FRAMES, "thread", 2)
        build_c = time.perf_counter() - start
        id_c(*inputs)
        jac_c(*inputs)
        compiled_times = (best_time(lambda: id_c(*inputs), args.repeats), best_time(lambda: jac_c(*inputs), args.repeats))
        print(f"C code (generate + compile, or load from cache): {build_c:.1f} s")
        print(f"nmsm ID compiled:            {compiled_times[0] * 1e3:9.3f} ms; ID + Jacobian compiled: "
              f"{compiled_times[1] * 1e3:9.3f} ms")

    bridge = get_bridge()
    load_list = [{"body": b, "force": loads[0:3, k::2].T, "point": loads[3:6, k::2].T, "torque": loads[6:9, k::2].T}
                 for k, b in enumerate(["calcn_r", "calcn_l"])]
    reference = bridge.call("oracle_inverse_dynamics", path=str(MODEL), q=q, u=qd, udot=qdd, loads=load_list)
    ours = np.array(id_map(*inputs)).T
    timing = bridge.call("oracle_time_inverse_dynamics", path=str(MODEL), q=q, u=qd, udot=qdd, repeats=args.repeats)
    per_frame = timing["seconds_per_frame"]
    t_osim = per_frame * FRAMES
    t_fd = per_frame * (1 + 3 * n) * FRAMES
    print(f"check: max |nmsm - OpenSim| over {FRAMES} frames = {np.abs(ours - reference).max():.2e} N m or N")
    print(f"OpenSim InverseDynamicsSolver (in worker): {per_frame * 1e6:.1f} us/frame, {t_osim * 1e3:.2f} ms for {FRAMES} frames"
          " (no external loads in the timed call)")
    print(f"OpenSim + forward-difference Jacobian: {per_frame * 1e6:.1f} us x (1 + 3*{n}) x {FRAMES} = {t_fd * 1e3:.1f} ms")
    print(f"speed-up, ID alone: {t_osim / t_id:.1f}x; ID + Jacobian vs OpenSim + finite differences: {t_fd / t_jac:.1f}x"
          f" (target >= 100x)")
    if compiled_times:
        print(f"speed-up compiled: ID {t_osim / compiled_times[0]:.1f}x; ID + Jacobian {t_fd / compiled_times[1]:.1f}x")


if __name__ == "__main__":
    main()
