"""Worst errors of nmsm's model core against OpenSim 4.6, for every model in the shared data.

Per model: marker positions, body origins (m) and body rotations at random poses within the
coordinate ranges (dependent coordinates through their couplers); inverse dynamics (N m or
N) at random (q, qdot, qddot): (a) with every non-muscle force as the ID tool (contact,
actuators at zero control), (b) with random external loads on two bodies and only gravity.

    python benchmarks/check_models_against_opensim.py [--poses 20] [--states 10]
"""

from __future__ import annotations

import argparse
import os
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--poses", type=int, default=20)
    parser.add_argument("--states", type=int, default=10)
    args = parser.parse_args()
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
