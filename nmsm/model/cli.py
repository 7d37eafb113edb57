"""Model sub-commands of ``nmsm``: ``id`` (inverse dynamics as OpenSim's ID tool) and
``markers`` (forward kinematics of markers)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from nmsm.cli_types import finite_float, positive_float


def _inverse_dynamics(args: argparse.Namespace) -> int:
    """``nmsm id``: outputs checked, then computed, then written atomically."""
    from nmsm.io.output_file import check_outputs, existing_inputs, write_output
    from nmsm.io.storage import format_storage, read_storage
    from nmsm.model import load_model
    from nmsm.model.external_loads import read_external_loads
    from nmsm.model.id_tool import inverse_dynamics_of_motion

    loads = read_external_loads(args.external_loads) if args.external_loads else None
    inputs = existing_inputs({args.model: "the input model (MODEL)", args.motion: "the input motion (MOTION)",
                              args.external_loads: "the --external-loads file",
                              loads.data_file if loads else None: "the data file the --external-loads file names"})
    output = check_outputs({"-o": args.output}, inputs, example_names={"-o": "id.sto"})["-o"]
    model = load_model(args.model)
    motion = read_storage(args.motion)
    time_range = None
    if args.start is not None or args.end is not None:
        time_range = (args.start if args.start is not None else -np.inf, args.end if args.end is not None else np.inf)
    table = inverse_dynamics_of_motion(model, motion, external_loads=loads, lowpass_hz=args.lowpass,
                                       time_range=time_range)
    write_output(output, format_storage(table, name="Inverse Dynamics Generalized Forces"))
    print(f"wrote {output} ({table.n_rows} frames, {table.n_columns} generalized forces)")
    return 0


def _markers(args: argparse.Namespace) -> int:
    """``nmsm markers``: the output checked, then computed, then written atomically."""
    from nmsm.io.output_file import check_outputs, existing_inputs, write_output
    from nmsm.io.storage import read_storage
    from nmsm.io.trc import MarkerTable, format_trc
    from nmsm.model import CasadiModel, load_model
    from nmsm.model.id_tool import motion_coordinates
    from nmsm.model.muscle_analysis import analysis_poses
    from nmsm.core.threads import SOLVER_THREADS

    inputs = existing_inputs({args.model: "the input model (MODEL)", args.motion: "the input motion (MOTION)"})
    output = check_outputs({"-o": args.output}, inputs, example_names={"-o": "markers.trc"})["-o"]
    model = load_model(args.model)
    motion = read_storage(args.motion)
    values, missing = motion_coordinates(model, motion)
    if motion.in_degrees:
        rotational = [i for i, c in enumerate(model.coordinates) if c.motion_type == "rotational"]
        values[:, rotational] = np.deg2rad(values[:, rotational])
    cm = CasadiModel(model)
    # poses as OpenSim sets them: locked coordinates at their default, clamped ones within range,
    # dependent ones from their couplers (the markers IK and JMP can reach with this model)
    values = analysis_poses(model, values, source=args.motion)
    n = motion.n_rows
    positions = np.array(cm.marker_function().map(n, "thread", SOLVER_THREADS)(values.T))  # 3 x (n_markers * n)
    positions = positions.reshape(3, len(model.markers), n, order="F").transpose(2, 1, 0)
    rate = (n - 1) / (motion.time[-1] - motion.time[0]) if n > 1 else None
    table = MarkerTable(motion.time, tuple(model.marker_names), positions, units=args.units, data_rate=rate)
    write_output(output, format_trc(table, units=args.units, file_label=output.name))
    print(f"wrote {output} ({n} frames, {len(model.markers)} markers)")
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "id", help="inverse dynamics of a motion, as OpenSim's Inverse Dynamics tool (muscles excluded)")
    p.add_argument("model", type=Path, help="OpenSim model (.osim)")
    p.add_argument("motion", type=Path, help="coordinates over time (IK .mot/.sto; degrees if inDegrees=yes)")
    p.add_argument("--external-loads", type=Path, help="OpenSim ExternalLoads XML (its datafile: GRF .mot)")
    p.add_argument("--lowpass", type=positive_float,
                   help="low-pass cut-off (Hz, > 0) for the coordinates; none by default")
    p.add_argument("--start", type=finite_float, help="first time (s) to report")
    p.add_argument("--end", type=finite_float, help="last time (s) to report")
    p.add_argument("-o", "--output", type=Path, required=True, help="generalized forces (.sto)")
    p.set_defaults(func=_inverse_dynamics)

    p = subparsers.add_parser("markers", help="marker trajectories of a motion (forward kinematics) as .trc")
    p.add_argument("model", type=Path, help="OpenSim model (.osim)")
    p.add_argument("motion", type=Path, help="coordinates over time (IK .mot/.sto)")
    p.add_argument("--units", choices=["m", "mm"], default="m", help="units written to the .trc (default m)")
    p.add_argument("-o", "--output", type=Path, required=True, help="marker file (.trc)")
    p.set_defaults(func=_markers)

    try:  # the muscle-analysis command lives with the muscle code, when present
        from nmsm.model import muscle_analysis
    except ImportError:
        return
    hook = getattr(muscle_analysis, "register_cli", None)
    if hook is not None:
        hook(subparsers)
