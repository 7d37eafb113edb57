"""``nmsm vaf``: how many synergies account for 90-95 % of the MTP activations' variance."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from nmsm.cli_types import percent, positive_int


def _check_output(args: argparse.Namespace) -> None:
    """``--output``: checked before any factorization (never one of the activation files or the model)."""
    from nmsm.io.output_file import check_outputs, existing_inputs
    from nmsm.tools.ncp.vaf import activation_files

    inputs = existing_inputs({path: f"an activation file ({path.name})" for path in activation_files(args.activations)})
    inputs.update(existing_inputs({args.model: "the --model file"}))
    check_outputs({"--output": args.output}, inputs, example_names={"--output": "vaf.csv"})


def _vaf(args: argparse.Namespace) -> int:
    """``nmsm vaf``: the output checked, the curve computed and printed, the CSV written atomically."""
    from nmsm.io.output_file import write_output
    from nmsm.tools.ncp.vaf import read_activation_trials, vaf_curve

    _check_output(args)
    muscles = list(args.muscles) if args.muscles else None
    if args.group:
        from nmsm.tools.ncp.model_groups import group_members

        if not args.model:
            from nmsm.errors import InputError

            raise InputError("--group needs --model (the .osim file holding the ForceSet group)", element="--group")
        members = group_members(args.model, args.group)
        if muscles is None:
            from nmsm.io.storage import read_storage
            from nmsm.tools.ncp.vaf import activation_files

            available = set(read_storage(activation_files(args.activations)[0]).labels)
            muscles = [m for m in members if m in available]
            missing = [m for m in members if m not in available]
            if missing:
                print(f"note: {len(missing)} member(s) of '{args.group}' have no activation column: {', '.join(missing)}")
        else:
            muscles = [m for m in muscles if m in set(members)]
    data, names = read_activation_trials(args.activations, muscles)
    curve = vaf_curve(data, args.max_synergies, muscles=names, name=args.group or "activations", seed=args.seed)
    thresholds = [t / 100.0 for t in args.threshold]
    print(curve.table(thresholds))
    if args.output:
        rows = "".join(f"{count},{100 * value:.6f}\n" for count, value in zip(curve.counts, curve.vaf))
        write_output(Path(args.output), "synergies,vaf_percent\n" + rows)
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "vaf",
        help="variance accounted for by NMF of muscle activations with 1..N synergies (choose NCP's num_synergies)",
        description=(
            "Runs non-negative matrix factorization of muscle activations (MTP's "
            "muscleActivations/*.sto) with 1..N synergies and prints the variance accounted for. "
            "Pick the smallest number of synergies reaching 90-95 %."
        ),
    )
    p.add_argument("activations", nargs="+", help="activation .sto files or folders of them (trials are stacked)")
    p.add_argument("--muscles", nargs="+", help="only these columns (default: all columns of the first file)")
    p.add_argument("--model", help=".osim model holding the ForceSet group named by --group")
    p.add_argument("--group", help="only the members of this ForceSet group (a synergy group)")
    p.add_argument("--max-synergies", type=positive_int, default=None,
                   help="largest number of synergies (>= 1, default min(muscles, 10))")
    p.add_argument("--threshold", type=percent, nargs="+", default=[90.0, 95.0],
                   help="VAF thresholds in percent (in (0, 100], default 90 95)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random NMF starts")
    p.add_argument("--output", help="also write the curve to this CSV file")
    p.set_defaults(func=_vaf)
