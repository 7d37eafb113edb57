"""Sub-commands ``pipeline``, ``example``, ``report`` and ``export``.

::

    nmsm pipeline PIPELINE.xml [--until STAGE] [--only STAGE ...] [--force STAGE ...] [--rebuild] [--check]
    nmsm example [STAGE] [--folder DIR]            # the built-in synthetic subject, lab data to treatment
    nmsm example --batch [--workers N]             # its DO swept on Dask (nmsm.examples.batch_example)
    nmsm report RESULTS_DIR [-o report.html]       # one HTML page with every stage's tables and plots
    nmsm export OSIMX -o MODEL.osim [--model M.osim] [--no-contact]
                [--treatment RESULTS_DIR --loads LOADS.xml]   # ExternalLoads of a treatment solution
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from nmsm.cli_types import positive_int


def _pipeline(args: argparse.Namespace) -> int:
    from nmsm.tools.pipeline.runner import run_pipeline_file

    run = run_pipeline_file(args.pipeline, only=args.only or None, until=args.until, force=args.force or (),
                            rebuild=args.rebuild, check_only=args.check, accept_unconverged=args.accept_unconverged)
    print(run.summary())
    return 0


def _example(args: argparse.Namespace) -> int:
    from nmsm.examples.example_run import run_example

    if args.batch:
        from nmsm.errors import InputError
        from nmsm.examples.batch_example import run_example_batch

        if args.stage or args.strict:
            raise InputError("--batch runs the DO sweep of the whole example", element="nmsm example --batch",
                             expected="no STAGE and no --strict with --batch")
        run = run_example_batch(args.folder, workers=args.workers, rebuild=args.rebuild)
        print(run.text())
        print(f"report: {run.spec.results_directory / 'report.html'}")
        return 0 if run.ok else 1
    outcome = run_example(args.folder, until=args.stage, rebuild=args.rebuild)
    print(outcome.text)
    return 1 if args.strict and not outcome.all_within_tolerance else 0


def _report_target(args: argparse.Namespace) -> tuple[Path, Path]:
    """The results tree and the checked HTML file: never an existing non-HTML file of the tree."""
    from nmsm.errors import InputError
    from nmsm.io.output_file import check_default_folder_writable, check_outputs
    from nmsm.report.html import REPORT_FILE

    root = Path(args.results)
    if not root.is_dir():
        raise InputError("not a folder", file=root, expected="a results folder")
    if not args.output:
        check_default_folder_writable(root, f"the report ({REPORT_FILE})")
    target = Path(args.output) if args.output else root / REPORT_FILE
    html = target.suffix.lower() in (".html", ".htm")  # the report reads no HTML: an earlier report is replaced
    folders = {} if html else {root: "the results tree being reported"}
    option = "-o" if args.output else "the default report file"
    check_outputs({option: target}, {}, protected_folders=folders, example_names={option: REPORT_FILE})
    return root, target


def _report(args: argparse.Namespace) -> int:
    """``nmsm report``: the output checked, the page built and written atomically; the
    results tree is only read (figures it lacks are drawn outside it)."""
    from nmsm.report.html import write_report

    root, target = _report_target(args)
    write_report(root, target)
    print(f"wrote {target}")
    return 0


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
    p = subparsers.add_parser("pipeline", help="run a chained pipeline file (stages skipped when up to date)")
    p.add_argument("pipeline", help="pipeline XML (<PipelineTool>, docs/pipeline.md)")
    p.add_argument("--until", metavar="STAGE", help="stop after this stage")
    p.add_argument("--only", metavar="STAGE", nargs="+", help="run only these stages (others must be up to date)")
    p.add_argument("--force", metavar="STAGE", nargs="+", help="redo these stages even when up to date")
    p.add_argument("--rebuild", action="store_true",
                   help="redo every stage (also the way out of a damaged pipeline_state.json)")
    p.add_argument("--check", action="store_true",
                   help="check the file and every stage's settings, show what would run and how it is wired; "
                        "run and write nothing")
    p.add_argument("--accept-unconverged", action="store_true",
                   help="a stage whose solve did not reach its stopping criterion writes its results (each file "
                        "stamped UNCONVERGED) and the pipeline goes on (default: the stage keeps its last iterate "
                        "in its last_iterate/ folder and the pipeline stops there)")
    p.set_defaults(func=_pipeline)

    p = subparsers.add_parser("example", help="the built-in synthetic subject: lab data to treatment, with the "
                                               "known answers")
    p.add_argument("stage", nargs="?", help="run the example up to this stage (jmp, passive, analysis, preprocess, "
                                            "mtp, ncp, gcp, surrogate, to, vo, do); default all")
    p.add_argument("--folder", default="nmsm_example", help="where the subject and results go (default ./nmsm_example)")
    p.add_argument("--rebuild", action="store_true", help="regenerate the subject and redo every stage")
    p.add_argument("--strict", action="store_true", help="exit 1 when a recovered value is out of its tolerance")
    p.add_argument("--batch", action="store_true",
                   help="sweep the DO over 5 weakness levels x 2 synergy scalings from one VO with nmsm batch "
                        "(in FOLDER/batch; docs/batch.md)")
    p.add_argument("--workers", type=positive_int, metavar="N",
                   help="with --batch: worker processes (default: one per core)")
    p.set_defaults(func=_example)

    p = subparsers.add_parser("report", help="one HTML page of every stage's tables and figures in a results tree")
    p.add_argument("results", help="a pipeline results tree or one tool's results folder")
    p.add_argument("-o", "--output", help="HTML file (default: RESULTS/report.html)")
    p.set_defaults(func=_report)

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
