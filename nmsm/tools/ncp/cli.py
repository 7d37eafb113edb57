"""``nmsm vaf``: how many synergies account for 90-95 % of the MTP activations' variance."""

from __future__ import annotations

import argparse
from typing import Any


def _vaf(args: argparse.Namespace) -> int:
    from nmsm.tools.ncp.vaf import read_activation_trials, vaf_curve

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
        with open(args.output, "w", encoding="utf-8") as handle:
            handle.write("synergies,vaf_percent\n")
            for count, value in zip(curve.counts, curve.vaf):
                handle.write(f"{count},{100 * value:.6f}\n")
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
    p.add_argument("--max-synergies", type=int, default=None, help="largest number of synergies (default min(muscles, 10))")
    p.add_argument("--threshold", type=float, nargs="+", default=[90.0, 95.0], help="VAF thresholds in percent (90 95)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random NMF starts")
    p.add_argument("--output", help="also write the curve to this CSV file")
    p.set_defaults(func=_vaf)
