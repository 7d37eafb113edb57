"""``nmsm ik``: inverse kinematics of a marker file, written as an OpenSim ``.mot``.

    nmsm ik MODEL.osim MARKERS.trc [--ik-settings IK.xml] -o IK.mot [--errors ERRORS.sto]

The IK settings (an OpenSim ``InverseKinematicsTool`` file) give marker weights, coordinate
tasks, the time range and accuracy; MARKERS.trc may be omitted when they name the marker
file. JMP itself runs through ``nmsm run JMPSettings.xml``.
"""

from __future__ import annotations

import argparse
from typing import Any


def _ik(args: argparse.Namespace) -> int:
    from nmsm.tools.jmp.ik import marker_error_table, run_ik_files
    from nmsm.io.storage import write_storage

    time_range = None
    if args.start is not None or args.end is not None:
        time_range = (args.start if args.start is not None else float("-inf"),
                      args.end if args.end is not None else float("inf"))
    result = run_ik_files(args.model, args.markers, ik_settings=args.ik_settings, output=args.output,
                          time_range=time_range, accuracy=args.accuracy)
    if args.errors:
        write_storage(args.errors, marker_error_table(result), name="MarkerErrors")
    print(f"IK: {result.n_frames} frames, {len(result.marker_names)} markers, {len(result.free_names)} free "
          f"coordinates, {result.wall_time:.2f} s; marker RMS {1000 * result.marker_rms():.2f} mm, "
          f"max {1000 * result.marker_max():.2f} mm")
    if result.insensitive_names:
        print("held at default (no marker moves them): " + ", ".join(result.insensitive_names))
    if args.output:
        print(f"wrote {args.output}")
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("ik", help="inverse kinematics of a .trc marker file (writes an OpenSim .mot)")
    p.add_argument("model", help="OpenSim model (.osim)")
    p.add_argument("markers", nargs="?", help="marker file (.trc); optional when --ik-settings names one")
    p.add_argument("--ik-settings", help="OpenSim IK settings (.xml): marker weights, time range, accuracy")
    p.add_argument("-o", "--output", help="output motion (.mot, rotational coordinates in degrees)")
    p.add_argument("--errors", help="also write per-marker distance errors (m) to this .sto")
    p.add_argument("--start", type=float, help="first time (s)")
    p.add_argument("--end", type=float, help="last time (s)")
    p.add_argument("--accuracy", type=float, help="OpenSim-style IK accuracy (default 1e-5)")
    p.set_defaults(func=_ik)
