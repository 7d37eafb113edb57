"""``nmsm ik``: inverse kinematics of a marker file, written as an OpenSim ``.mot``.

    nmsm ik MODEL.osim MARKERS.trc [--ik-settings IK.xml] -o IK.mot [--errors ERRORS.sto]

The IK settings (an OpenSim ``InverseKinematicsTool`` setup, or a bare ``IKTaskSet`` file)
give marker weights, coordinate tasks, the time range and accuracy; MARKERS.trc may be
omitted when a setup names the marker file. JMP itself runs through ``nmsm run JMPSettings.xml``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from nmsm.cli_types import finite_float, positive_float


def _ik_paths(args: argparse.Namespace) -> tuple[Any, str, dict[str, Path | None]]:
    """The IK settings (or None), the marker file and the checked outputs (``-o``, ``--errors``),
    before anything is computed: no output may be an input, nor both options one file."""
    import attrs

    from nmsm.errors import InputError
    from nmsm.io.output_file import check_outputs, existing_inputs
    from nmsm.tools.jmp.ik_settings import read_ik_settings

    settings = read_ik_settings(args.ik_settings) if args.ik_settings else None
    markers = args.markers or (str(settings.marker_file) if settings and settings.marker_file else None)
    if markers is None:
        raise InputError("no marker file given", element="MARKERS.trc",
                         expected="a .trc path, or an IK settings file with <marker_file>")
    motion_option, motion = "-o", args.output
    if motion is None and settings is not None and settings.output_motion_file is not None:
        motion_option, motion = f"<output_motion_file> of {settings.file}", settings.output_motion_file
    inputs = existing_inputs({args.model: "the input model (MODEL)", markers: "the marker file (MARKERS.trc)",
                              args.ik_settings: "the --ik-settings file",
                              settings.coordinate_file if settings else None: "the IK settings' coordinate file",
                              settings.model_file if settings else None: "the IK settings' model file"})
    outputs = check_outputs({motion_option: motion, "--errors": args.errors}, inputs,
                            example_names={motion_option: "ik.mot", "--errors": "marker_errors.sto"})
    if settings is not None:
        settings = attrs.evolve(settings, output_motion_file=None)  # written here, atomically
    return settings, markers, {"motion": outputs.get(motion_option), "errors": outputs.get("--errors")}


def _ik(args: argparse.Namespace) -> int:
    """``nmsm ik``: every output checked, then IK, then the files written atomically."""
    from nmsm.io.output_file import write_output
    from nmsm.io.storage import format_storage
    from nmsm.tools.jmp.ik import marker_error_table, motion_table, run_ik_files

    settings, markers, paths = _ik_paths(args)
    time_range = None
    if args.start is not None or args.end is not None:
        time_range = (args.start if args.start is not None else float("-inf"),
                      args.end if args.end is not None else float("inf"))
    result = run_ik_files(args.model, markers, ik_settings=settings, output=None,
                          time_range=time_range, accuracy=args.accuracy)
    if paths["motion"]:
        write_output(paths["motion"], format_storage(motion_table(result), name="Coordinates"))
    if paths["errors"]:
        write_output(paths["errors"], format_storage(marker_error_table(result), name="MarkerErrors"))
    print(f"IK: {result.n_frames} frames, {len(result.marker_names)} markers, {len(result.free_names)} free "
          f"coordinates, {result.wall_time:.2f} s; marker RMS {1000 * result.marker_rms():.2f} mm, "
          f"max {1000 * result.marker_max():.2f} mm")
    if result.insensitive_names:
        print("held at default (no marker moves them): " + ", ".join(result.insensitive_names))
    if paths["motion"]:
        print(f"wrote {paths['motion']}")
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("ik", help="inverse kinematics of a .trc marker file (writes an OpenSim .mot)")
    p.add_argument("model", help="OpenSim model (.osim)")
    p.add_argument("markers", nargs="?", help="marker file (.trc); optional when --ik-settings names one")
    p.add_argument("--ik-settings", help="OpenSim IK setup or IK task set (.xml): marker weights, coordinate tasks, "
                   "time range, accuracy")
    p.add_argument("-o", "--output", help="output motion (.mot, rotational coordinates in degrees)")
    p.add_argument("--errors", help="also write per-marker distance errors (m) to this .sto")
    p.add_argument("--start", type=finite_float, help="first time (s)")
    p.add_argument("--end", type=finite_float, help="last time (s)")
    p.add_argument("--accuracy", type=positive_float, help="OpenSim-style IK accuracy (> 0, default 1e-5)")
    p.set_defaults(func=_ik)
