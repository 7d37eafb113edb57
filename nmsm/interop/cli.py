"""Sub-command ``export``: a personalized ``.osimx`` as a plain OpenSim model; a treatment
solution's ground reactions as ExternalLoads.

::

    nmsm export OSIMX -o MODEL.osim [--model M.osim] [--no-contact]
                [--treatment RESULTS_DIR --loads LOADS.xml]   # ExternalLoads of a treatment solution
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def _export_inputs(args: argparse.Namespace) -> tuple[dict[Path, str], dict[Path, str]]:
    """Files and folders ``nmsm export`` reads (the .osimx, its model, the treatment folder)."""
    from nmsm.interop.osim_export import associated_model
    from nmsm.io.osimx import read_osimx

    osimx = Path(args.osimx)
    model = Path(args.model) if args.model else associated_model(osimx, read_osimx(osimx))
    what = "the --model file" if args.model else "the model the .osimx names in <associated_osim_model>"
    files = {osimx: "the input .osimx (OSIMX)", model: what}
    folders = {Path(args.treatment): "the --treatment results folder"} if args.treatment else {}
    return files, folders


def _check_export(args: argparse.Namespace) -> tuple[Path | None, Path | None, Any]:
    """Every argument, input and output of ``nmsm export`` before anything is written: the
    .osim, the ExternalLoads XML and its .mot (none an input, none the same file), and the
    treatment solution's ground reactions (read here). Returns (osim, loads xml, reactions)."""
    from nmsm.errors import InputError
    from nmsm.io.output_file import check_outputs

    if not args.output and not args.treatment:
        raise InputError("nothing to export", element="nmsm export", expected="-o MODEL.osim and/or --treatment DIR")
    if args.treatment and not args.loads:
        raise InputError("--treatment needs --loads", element="nmsm export", expected="--loads LOADS.xml")
    if args.loads and not args.treatment:
        raise InputError("--loads needs --treatment", element="nmsm export", expected="--treatment RESULTS_DIR")
    if args.trial and not args.treatment:
        raise InputError("--trial names a trial of --treatment's results", element="nmsm export",
                         expected="--trial with --treatment RESULTS_DIR")
    files, folders = _export_inputs(args)
    xml = Path(args.loads).with_suffix(".xml") if args.loads else None
    data = xml.with_suffix(".mot") if xml else None
    outputs = check_outputs({"-o": args.output, "--loads": xml, "--loads (its .mot)": data}, files,
                            protected_folders=folders,
                            example_names={"-o": "model.osim", "--loads": "loads.xml", "--loads (its .mot)": "loads.mot"})
    reactions = None
    if args.treatment:
        from nmsm.interop.treatment_loads import solution_reactions

        reactions = solution_reactions(Path(args.treatment), Path(args.osimx), args.trial)
    return outputs.get("-o"), outputs.get("--loads"), reactions


def _export(args: argparse.Namespace) -> int:
    """``nmsm export``: everything checked first; the .osim, the ExternalLoads XML and its
    .mot staged and moved into place together (all or nothing)."""
    import attrs

    from nmsm.interop.external_loads import write_external_loads
    from nmsm.interop.osim_export import export_osimx
    from nmsm.io.output_file import staged_outputs

    osim, xml, reactions = _check_export(args)
    with staged_outputs() as staged:
        report = None if osim is None else export_osimx(args.osimx, staged.file(osim), model_path=args.model,
                                                        include_contact=not args.no_contact)
        loads = None if xml is None else write_external_loads(staged.file(xml), reactions)
    if report is not None:
        print(attrs.evolve(report, model=osim).text())
    if loads is not None:
        print(f"wrote {staged.destination(loads[0])} and {staged.destination(loads[1])}")
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("export", help="a personalized .osimx as a plain OpenSim model; a treatment "
                                              "solution's ground reactions as ExternalLoads")
    p.add_argument("osimx", help="the personalized .osimx")
    p.add_argument("-o", "--output", help="the .osim to write")
    p.add_argument("--model", help="the .osim to start from (default: the .osimx's associated model)")
    p.add_argument("--no-contact", action="store_true", help="leave the contact springs out (for ID with ExternalLoads)")
    p.add_argument("--treatment", metavar="RESULTS_DIR", help="a TO/VO/DO results folder whose GRFData to export")
    p.add_argument("--loads", metavar="LOADS.xml", help="ExternalLoads XML to write (its .mot next to it)")
    p.add_argument("--trial", help="trial name in GRFData (default: the only one)")
    p.set_defaults(func=_export)
