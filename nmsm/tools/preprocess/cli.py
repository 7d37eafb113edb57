"""``nmsm preprocess``: raw EMG, IK, ID and muscle analysis of a recording -> personalization folders.

Example (the tutorial's step 2)::

    nmsm preprocess --model UF_Subject_3.osim --time-pair "0.5 1.6" --prefix gait \\
        --raw-emg input_data/GaitTrial48_EMG.mot --emg-low-pass 3.1818 --ik GaitTrial48_IKResults.mot \\
        --id GaitTrial48_ID.sto --grf GaitTrial48_forces.mot --muscle-analysis MuscleAnalysis \\
        --output preprocessed

``--markers`` computes IK, ``--external-loads`` computes ID and ``--compute-muscle-analysis``
the muscle analysis, with nmsm's model core (``--engine nmsm``, default) or OpenSim
(``--engine opensim``). Arguments, output folder and inputs are checked before anything is
processed, and nothing is left behind on an error (:mod:`nmsm.tools.preprocess.command`).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def _path(value: str | None) -> Path | None:
    return Path(value) if value else None


def _preprocess(args: argparse.Namespace) -> int:
    from nmsm.tools.preprocess.command import run_checked
    from nmsm.tools.preprocess.run import EmgOptions, PreprocessRequest, parse_time_pairs

    request = PreprocessRequest(
        time_pairs=parse_time_pairs(args.time_pair),
        output=Path(args.output),
        model=_path(args.model),
        prefix=args.prefix,
        rows=args.rows,
        cutoff=None if args.cutoff <= 0 else args.cutoff,
        engine=args.engine,
        raw_emg=_path(args.raw_emg),
        processed_emg=_path(args.emg),
        emg=EmgOptions(args.emg_order, args.emg_high_pass, args.emg_low_pass, args.emg_demean),
        emg_channels=tuple(args.emg_channels.split()) if args.emg_channels else (),
        emg_padding_time=args.emg_padding_time,
        markers=_path(args.markers),
        ik_settings=_path(args.ik_settings),
        ik=_path(args.ik),
        inverse_dynamics=_path(args.id),
        external_loads=_path(args.external_loads),
        grf=_path(args.grf),
        muscle_analysis=_path(args.muscle_analysis),
        compute_muscle_analysis=args.compute_muscle_analysis,
        muscles=tuple(args.muscles.split()) if args.muscles else (),
        coordinates=tuple(args.coordinates.split()) if args.coordinates else (),
    )
    names = run_checked([request])
    print(f"wrote {len(names)} trial(s) to {request.output}: {', '.join(names)}")
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("preprocess", help="EMG/IK/ID/muscle analysis -> IKData, IDData, EMGData, MAData, GRFData")
    p.add_argument("--time-pair", action="append", required=True, metavar="'START END'",
                   help="trial window in s (repeat for several trials)")
    p.add_argument("--output", default="preprocessed", help="results folder (default: preprocessed)")
    p.add_argument("--prefix", default="trial", help="trial name prefix: <prefix>_1, <prefix>_2, ...")
    p.add_argument("--rows", type=int, default=101, help="rows per trial (default 101)")
    p.add_argument("--cutoff", type=float, default=6.0,
                   help="low-pass (Hz) of IK, ID, lengths and moment arms before resampling; <= 0: none")
    p.add_argument("--model", help="the subject's .osim (IK in degrees, computed analyses)")
    p.add_argument("--engine", choices=["nmsm", "opensim"], default="nmsm",
                   help="who computes IK/ID/muscle analysis: nmsm's model core or OpenSim (bridge)")
    p.add_argument("--raw-emg", help="raw EMG table (.mot/.sto) to filter, rectify and normalize")
    p.add_argument("--emg", help="already processed EMG table")
    p.add_argument("--emg-order", type=int, default=4, help="Butterworth order of the EMG filters")
    p.add_argument("--emg-high-pass", type=float, default=40.0, help="EMG high-pass cut-off (Hz)")
    p.add_argument("--emg-low-pass", type=float, default=10.0,
                   help="EMG low-pass (envelope) cut-off (Hz); the tutorial uses 3.5/1.1 = 3.1818")
    p.add_argument("--emg-demean", choices=["frame", "channel"], default="frame",
                   help="frame: the original's mean/min across channels at each frame (default); "
                        "channel: each channel's own mean/min")
    p.add_argument("--emg-channels", help="space-separated EMG columns to keep (default all); each must exist")
    p.add_argument("--emg-padding-time", type=float, default=0.2,
                   help="EMG kept before and after each trial (s), for the electromechanical delay")
    p.add_argument("--markers", help="marker file (.trc): compute IK")
    p.add_argument("--ik-settings", help="IK settings XML (marker weights, accuracy) for --markers")
    p.add_argument("--ik", help="IK motion (.mot)")
    p.add_argument("--id", help="inverse-dynamics table (.sto)")
    p.add_argument("--external-loads", help="external loads XML: compute ID from the IK")
    p.add_argument("--grf", help="ground reaction table (.mot) to split")
    p.add_argument("--muscle-analysis", help="folder of MuscleAnalysis results (Length, Velocity, MomentArm_*)")
    p.add_argument("--compute-muscle-analysis", action="store_true", help="run the muscle analysis on the IK")
    p.add_argument("--muscles", help="space-separated muscles for --compute-muscle-analysis (default all)")
    p.add_argument("--coordinates", help="space-separated moment-arm coordinates (default all)")
    p.set_defaults(func=_preprocess)
