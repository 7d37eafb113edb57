"""Benchmark: surrogate muscle geometry of the full-body RCNL model (86 muscles).

Samples Latin-hypercube poses of the 17 surrogate coordinates (others at the trial's
values) around a gait trial (OpenSim computes the lengths and the
central-difference moment arms; timed separately, inside the bridge call), fits one
polynomial per muscle (timed), and measures accuracy on held-out poses sampled with
another seed. Muscles whose cylinder wrapping switches on and off over the held-out
poses are listed with their figures.

    python benchmarks/bench_surrogate.py [--frames-step 2] [--samples-per-frame 25] [--degree 5]

Prints measured numbers only (wall times with ``time.perf_counter``).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from nmsm.io.storage import read_storage
from nmsm.model.surrogate import fit_surrogate_model
from nmsm.opensim_bridge import get_bridge
from nmsm.tools.surrogate.sampling import model_geometry_info, opensim_samples, poses_around_motion

SHARED = Path(os.environ.get("NMSM_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
MODEL = SHARED / "models" / "RCNL2024.osim"
MOTION = SHARED / "preprocessing" / "uf_subject3_tutorial" / "PreCompleted" / "preprocessed" / "IKData" / "gait_1.sto"
COORDINATES = [
    f"{c}_{side}"
    for side in ("r", "l")
    for c in ("hip_flexion", "hip_adduction", "hip_rotation", "knee_angle", "ankle_angle", "subtalar_angle", "mtp_angle")
] + ["lumbar_extension", "lumbar_bending", "lumbar_rotation"]
LENGTH_LIMIT = 0.5e-3  # m, RMS over held-out poses
ARM_LIMIT = 1.0e-3  # m, RMS over held-out poses, worst coordinate


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames-step", type=int, default=2, help="use every n-th frame of the gait trial (2)")
    parser.add_argument("--samples-per-frame", type=int, default=25)
    parser.add_argument("--held-out-per-frame", type=int, default=8)
    parser.add_argument("--angular-padding", type=float, default=10.0, help="degrees")
    parser.add_argument("--degree", type=int, default=5)
    parser.add_argument("--output", help="write the fitted surrogate (.json) here")
    args = parser.parse_args(argv)

    bridge = get_bridge()
    motion = read_storage(MOTION)
    motion = motion.select(list(motion.labels))
    frames = motion.data[:: args.frames_step]
    import attrs

    reference = attrs.evolve(motion, time=motion.time[:: args.frames_step], data=frames)
    info = model_geometry_info(MODEL, bridge)
    print(f"model {MODEL.name}: {len(info['muscles'])} muscles, {len(info['coordinates'])} coordinates; "
          f"reference {MOTION.name}: {reference.n_rows} frames; surrogate coordinates: {len(COORDINATES)}")

    coords, fit_poses = poses_around_motion(MODEL, reference, angular_padding=math.radians(args.angular_padding),
                                            samples_per_frame=args.samples_per_frame, seed=0, varied=COORDINATES,
                                            bridge=bridge)
    _, test_poses = poses_around_motion(MODEL, reference, angular_padding=math.radians(args.angular_padding),
                                        samples_per_frame=args.held_out_per_frame, seed=1, varied=COORDINATES,
                                        bridge=bridge)
    bridge.call("muscle_lengths", model=str(MODEL), q=fit_poses[:1], coordinates=list(coords))  # model load
    t0 = time.perf_counter()
    samples = opensim_samples(MODEL, coords, fit_poses, COORDINATES, bridge=bridge)
    t_sample = time.perf_counter() - t0
    t0 = time.perf_counter()
    held_out = opensim_samples(MODEL, coords, test_poses, COORDINATES, bridge=bridge)
    t_test = time.perf_counter() - t0
    n_evals = len(fit_poses) * (1 + 2 * len(COORDINATES))
    print(f"sampling through OpenSim: {len(fit_poses)} poses x (1 + 2 x {len(COORDINATES)}) length evaluations "
          f"= {n_evals} in {t_sample:.1f} s ({1e3 * t_sample / n_evals:.2f} ms per evaluation of all muscles); "
          f"held-out set {len(test_poses)} poses in {t_test:.1f} s")

    t0 = time.perf_counter()
    model = fit_surrogate_model(samples, args.degree, 1e-4, validation=held_out)
    t_fit = time.perf_counter() - t0
    terms = sum(len(m.coefficients) for m in model.muscles)
    print(f"fitting {len(model.muscles)} muscles (degree {args.degree}, {terms} coefficients in all): {t_fit:.2f} s "
          f"({1e3 * t_fit / max(1, len(model.muscles)):.0f} ms per muscle); not modeled: {list(model.excluded_muscles)}")

    t0 = time.perf_counter()
    function = model.function()
    print(f"CasADi function of all muscles built in {time.perf_counter() - t0:.2f} s: {function}")

    wrapping = bridge.call("muscle_wrapping_active", model=str(MODEL), q=test_poses, coordinates=list(coords),
                           muscles=list(model.muscle_names))
    switching = {m: len(np.unique(wrapping[:, i])) > 1 for i, m in enumerate(model.muscle_names)}

    rows = []
    for m in model.muscles:
        a = m.accuracy
        rows.append((m.muscle, len(m.coordinates), a.length_rms, a.length_max, a.worst_moment_arm_rms,
                     a.worst_moment_arm_max, switching[m.muscle]))
    passing = [r for r in rows if r[2] <= LENGTH_LIMIT and r[4] <= ARM_LIMIT]
    failing = [r for r in rows if r not in passing]
    print(f"\nheld-out accuracy ({held_out.n_poses} poses): {len(passing)} of {len(rows)} muscles within "
          f"length RMS <= {LENGTH_LIMIT * 1e3} mm and moment-arm RMS <= {ARM_LIMIT * 1e3} mm")
    worst_length = max(rows, key=lambda r: r[2])
    worst_arm = max(rows, key=lambda r: r[4])
    print(f"worst length RMS: {worst_length[0]} {worst_length[2] * 1e3:.3f} mm (max {worst_length[3] * 1e3:.3f} mm)")
    print(f"worst moment-arm RMS: {worst_arm[0]} {worst_arm[4] * 1e3:.3f} mm (max {worst_arm[5] * 1e3:.3f} mm)")
    ok = [r for r in passing]
    if ok:
        print(f"worst muscle within limits: length {max(ok, key=lambda r: r[2])[0]} "
              f"{max(r[2] for r in ok) * 1e3:.3f} mm, moment arm {max(ok, key=lambda r: r[4])[0]} "
              f"{max(r[4] for r in ok) * 1e3:.3f} mm")
    print("\nmuscles outside the limits (mm; 'switching' = a wrap object engages for some held-out poses, not for others):")
    print(f"{'muscle':<14s} {'coords':>6s} {'L rms':>7s} {'L max':>7s} {'r rms':>7s} {'r max':>7s}  wrapping")
    for r in sorted(failing, key=lambda r: -max(r[2] / LENGTH_LIMIT, r[4] / ARM_LIMIT)):
        print(f"{r[0]:<14s} {r[1]:>6d} {r[2] * 1e3:7.3f} {r[3] * 1e3:7.3f} {r[4] * 1e3:7.3f} {r[5] * 1e3:7.3f}  "
              f"{'switching' if r[6] else 'constant'}")
    if args.output:
        model.save(args.output)
        print(f"written {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
