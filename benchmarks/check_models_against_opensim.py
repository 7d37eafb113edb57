"""Worst errors of nmsm's model core against OpenSim 4.6, for every model in the shared data.

Per model: marker positions, body origins (m) and body rotations at random poses within the
coordinate ranges (dependent coordinates through their couplers); inverse dynamics (N m or
N) at random (q, qdot, qddot): (a) with every non-muscle force as the ID tool (contact,
actuators at zero control), (b) with random external loads on two bodies and only gravity.

With ``--muscles``: per model with muscles (identical files once), ``nmsm muscle-analysis``
against OpenSim's MuscleAnalysis over the tutorial gait trial's 0.10-0.30 s (gastrocnemius
wraps engage and let go there; coordinates the trial lacks swing within their ranges):
the worst muscle's moment-arm RMS (m, over frames, worst coordinate) and the worst length
RMS (m).

    python benchmarks/check_models_against_opensim.py [--poses 20] [--states 10]
    python benchmarks/check_models_against_opensim.py --muscles [--start 0.1 --end 0.3]
"""

from __future__ import annotations

import argparse
import hashlib
import os
import tempfile
import zlib
from pathlib import Path

import numpy as np

from nmsm.model import CasadiModel, load_model
from nmsm.opensim_bridge import get_bridge

SHARED = Path(os.environ.get("NMSM_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))


def random_poses(model, cm, count, rng):
    lo = np.array([max(c.range[0], -np.pi) for c in model.coordinates])
    hi = np.array([min(c.range[1], np.pi) for c in model.coordinates])
    return cm.coordinates.dependent_values(lo + (hi - lo) * rng.random((count, len(model.coordinates))))


GAIT = "preprocessing/uf_subject3_tutorial/PreCompleted/input_data/GaitTrial_IKResults.mot"


def distinct_muscle_models() -> list[Path]:
    """Shared models with muscles, each distinct file once (first path in sorted order)."""
    seen, out = set(), []
    for path in sorted(SHARED.rglob("*.osim")):
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        if digest in seen:
            continue
        seen.add(digest)
        if load_model(path).muscles:
            out.append(path)
    return out


def check_muscles(start: float, end: float, only: str | None = None) -> None:
    import attrs
    import warnings

    from nmsm.io.storage import read_storage
    from nmsm.model.muscle_analysis_check import compare_with_opensim, gait_motion

    gait = read_storage(SHARED / GAIT)
    keep = (gait.time >= start - 1e-9) & (gait.time <= end + 1e-9)
    gait = attrs.evolve(gait, time=gait.time[keep], data=gait.data[keep])
    bridge = get_bridge()
    models = [m for m in distinct_muscle_models() if only is None or only in str(m)]
    print(f"{len(models)} distinct models with muscles; gait frames {start:g}-{end:g} s ({keep.sum()})")
    print(f"{'arm RMS mm':>10} {'len RMS mm':>10} {'muscles':>7}  worst muscle (coordinate, source); model")
    worst_all = (0.0, "", "", "")
    with tempfile.TemporaryDirectory() as tmp:
        for i, path in enumerate(models):
            model = load_model(path)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                result = compare_with_opensim(path, gait_motion(model, gait), Path(tmp) / str(i), bridge=bridge,
                                              model=model)
            muscle, rms, coordinate = result.worst()
            relative = str(path.relative_to(SHARED))
            length = float(result.length_rms.max()) if result.muscles else 0.0
            print(f"{1e3 * rms:10.2e} {1e3 * length:10.2e} {len(result.muscles):7d}  {muscle or '-'} "
                  f"({coordinate}, {result.sources.get(muscle, '-')}); {relative}"
                  + (f"; not in OpenSim's MuscleAnalysis: {len(result.unreported)}" if result.unreported else ""),
                  flush=True)
            if rms > worst_all[0]:
                worst_all = (rms, muscle, coordinate, relative)
    print(f"WORST moment-arm RMS {1e3 * worst_all[0]:.2e} mm: {worst_all[1]} ({worst_all[2]}) in {worst_all[3]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--poses", type=int, default=20)
    parser.add_argument("--states", type=int, default=10)
    parser.add_argument("--muscles", action="store_true", help="muscle analysis against OpenSim's MuscleAnalysis")
    parser.add_argument("--start", type=float, default=0.10)
    parser.add_argument("--end", type=float, default=0.30)
    parser.add_argument("--only", help="check only models whose path contains this text")
    args = parser.parse_args()
    if args.muscles:
        check_muscles(args.start, args.end, args.only)
        return
    bridge = get_bridge()
    files = sorted(SHARED.rglob("*.osim"))
    print(f"{len(files)} models; {args.poses} poses, {args.states} dynamic states each")
    print(f"{'markers m':>10} {'origins m':>10} {'rotations':>10} {'ID N(m)':>10} {'ID+loads':>10} {'max|tau|':>9}  model")
    worst = np.zeros(5)
    for path in files:
        relative = str(path.relative_to(SHARED))
        model = load_model(path)
        cm = CasadiModel(model)
        rng = np.random.default_rng(zlib.crc32(relative.encode()))
        q = random_poses(model, cm, args.poses, rng)
        ref = bridge.call("oracle_kinematics", path=model.source_file, q=q)
        k = len(q)
        err_m = 0.0
        if model.markers:
            ours = np.array(cm.marker_function().map(k)(q.T)).reshape(3, len(model.markers), k, order="F").transpose(2, 1, 0)
            order = [model.marker_names.index(n) for n in ref["marker_names"]]
            err_m = np.abs(ours[:, order] - ref["markers"]).max()
        ours = np.array(cm.body_origins_function().map(k)(q.T)).reshape(3, len(model.bodies), k, order="F").transpose(2, 1, 0)
        order = [list(model.bodies).index(n) for n in ref["body_names"]]
        err_o = np.abs(ours[:, order] - ref["origins"]).max()
        err_r = 0.0
        for i, name in enumerate(ref["body_names"]):
            rot = np.array(cm.body_pose_function(name).map(k)(q.T)[0]).reshape(3, 3, k, order="F").transpose(2, 0, 1)
            err_r = max(err_r, np.abs(rot - ref["rotations"][:, i]).max())
        s = args.states
        q = q[:s]
        u = rng.normal(0, 1, q.shape)
        udot = rng.normal(0, 5, q.shape)
        ref = bridge.call("oracle_inverse_dynamics", path=model.source_file, q=q, u=u, udot=udot)
        ours = np.array(cm.inverse_dynamics_function(include_contact=True).map(s)(q.T, u.T, udot.T)).T
        err_id = np.abs(ours - ref).max()
        bodies = list(model.bodies)[-2:]
        loads = [{"body": b, "force": rng.normal(0, 300, (s, 3)), "point": rng.normal(0, 1, (s, 3)),
                  "torque": rng.normal(0, 20, (s, 3))} for b in bodies]
        ref = bridge.call("oracle_inverse_dynamics", path=model.source_file, q=q, u=u, udot=udot, loads=loads, forces="none")
        values = np.concatenate([np.stack([np.concatenate([L["force"][i], L["point"][i], L["torque"][i]]) for L in loads],
                                          axis=1) for i in range(s)], axis=1)
        ours = np.array(cm.inverse_dynamics_function(bodies).map(s)(q.T, u.T, udot.T, values)).T
        err_loads = np.abs(ours - ref).max()
        errors = np.array([err_m, err_o, err_r, err_id, err_loads])
        worst = np.maximum(worst, errors)
        print(f"{err_m:10.1e} {err_o:10.1e} {err_r:10.1e} {err_id:10.1e} {err_loads:10.1e} {np.abs(ref).max():9.1f}  {relative}")
    print(f"{worst[0]:10.1e} {worst[1]:10.1e} {worst[2]:10.1e} {worst[3]:10.1e} {worst[4]:10.1e} {'':9}  WORST")


if __name__ == "__main__":
    main()
