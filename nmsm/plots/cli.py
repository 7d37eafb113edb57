"""``nmsm plot RESULTS_DIR``: the figures of every results folder found in a tree.

The folder itself and every folder below it (``plots`` and hidden folders skipped) is tested
against each tool's results layout; each match is drawn by the tool's plot module
(:mod:`nmsm.plots.jmp`, ``mtp``, ``ncp``, ``gcp``, ``treatment``) into ``<folder>/plots``, or
into ``--output/<folder relative to RESULTS_DIR>``. ``nmsm plot --compare A B C`` draws the
treatment figures of A with B and C overlaid (``compare_<trial>_*.png`` in ``A/plots`` or
``-o``). A pipeline results tree (``nmsm pipeline``) gets every stage's figures this way. Each
folder's figures are drawn into a hidden staging folder and moved into place together when all
are drawn (:func:`nmsm.io.output_file.staged_outputs`): a folder whose figures fail gets none
of them (its earlier figures stay, folders created for it are removed), is reported, and the
others are still drawn (exit code 1); Ctrl-C keeps the folders finished before it.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import attrs


@attrs.frozen
class Plotter:
    """A tool's plot module: ``detect(folder) -> bool`` and ``plot(folder, output) -> [paths]``."""

    tool: str
    module: str
    plot: str
    detect: str | None = None  #: the module's own detector, else ``pattern``
    pattern: str = ""  #: a glob that only the tool's results folders match

    def matches(self, folder: Path) -> bool:
        module = self._module()
        if module is None:
            return False
        if self.detect and hasattr(module, self.detect):
            return bool(getattr(module, self.detect)(folder))
        return bool(self.pattern) and any(folder.glob(self.pattern))

    def draw(self, folder: Path, output: Path | None) -> list[Path]:
        function: Callable[..., list[Path]] = getattr(self._module(), self.plot)
        return list(function(folder, output))

    def _module(self) -> Any:
        try:
            return importlib.import_module(self.module)
        except ModuleNotFoundError as exc:
            if exc.name == self.module:
                return None
            raise


PLOTTERS = (
    Plotter("jmp", "nmsm.plots.jmp", "plot_jmp_results", "is_jmp_results"),
    Plotter("mtp", "nmsm.plots.mtp", "plot_mtp_results", "is_mtp_results"),
    Plotter("ncp", "nmsm.plots.ncp", "plot_ncp_results", "is_ncp_results"),
    Plotter("gcp", "nmsm.plots.gcp", "plot_gcp_results", "is_gcp_results", "*_Foot_*_optimizedGroundReactions.sto"),
    Plotter("treatment", "nmsm.plots.treatment", "plot_treatment_results", "is_treatment_results"),
)


def results_folders(root: str | os.PathLike[str]) -> list[tuple[str, Path]]:
    """``(tool, folder)`` of every results folder in the tree below ``root`` (``root`` included)."""
    root = Path(root)
    found = []
    for folder, dirs, _ in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and d != "plots")
        path = Path(folder)
        for plotter in PLOTTERS:
            if plotter.matches(path):
                found.append((plotter.tool, path))
    return found


def plot_tree(root: str | os.PathLike[str], output: str | os.PathLike[str] | None = None,
              log: Callable[[str], None] = print) -> tuple[dict[Path, list[Path]], dict[Path, str]]:
    """Draw every results folder below ``root``, each folder's figures all or nothing (module
    docstring); returns (figures per folder, errors per folder)."""
    from nmsm.errors import NmsmError
    from nmsm.io.output_file import staged_outputs

    root = Path(root)
    figures: dict[Path, list[Path]] = {}
    errors: dict[Path, str] = {}
    by_tool = {p.tool: p for p in PLOTTERS}
    for tool, folder in results_folders(root):
        target = folder / "plots" if output is None else Path(output) / folder.relative_to(root)
        try:
            with staged_outputs() as staged:
                drawn = by_tool[tool].draw(folder, staged.folder(target))
            figures[folder] = [staged.destination(p) for p in drawn]
            log(f"{tool:<10s} {folder}: {len(figures[folder])} figure(s)")
        except (NmsmError, OSError, ValueError, KeyError) as exc:
            errors[folder] = f"{type(exc).__name__}: {exc}"
            log(f"{tool:<10s} {folder}: no figures ({errors[folder]})")
    return figures, errors


def _compare(args: argparse.Namespace) -> int:
    """``nmsm plot --compare A B C``: A's treatment figures with B and C overlaid, named
    ``compare_<trial>_*.png``, into ``-o`` (default ``A/plots``), all or none."""
    from nmsm.errors import InputError
    from nmsm.io.output_file import check_default_folder_writable, check_output_folder, staged_outputs
    from nmsm.plots.treatment import is_treatment_results, plot_treatment_results

    folders = [Path(f) for f in ([args.results] if args.results else []) + list(args.compare)]
    if len(folders) < 2:
        raise InputError("--compare needs at least two results folders", element="--compare",
                         expected="nmsm plot --compare TO_RESULTS VO_RESULTS [DO_RESULTS ...]")
    for folder in folders:
        if not is_treatment_results(folder):
            raise InputError("not a Tracking, Verification or Design Optimization results folder", file=folder,
                             expected="a folder with <trial>_states.sto and IKData/ (written by TO, VO or DO)")
    if args.output:
        target = check_output_folder(args.output, what="a folder for the figures (default: <first folder>/plots)")
    else:
        target = folders[0] / "plots"
        check_default_folder_writable(target if target.is_dir() else folders[0], "the figures (<folder>/plots)")
    with staged_outputs() as staged:
        drawn = plot_treatment_results(folders[0], staged.folder(target), compare=folders[1:], prefix="compare_")
    print(f"treatment  {' vs '.join(str(f) for f in folders)}: {len(drawn)} figure(s) in {target}")
    return 0


def _plot(args: argparse.Namespace) -> int:
    """``nmsm plot``: ``-o`` checked first (a folder, or a new one in an existing folder); the
    folders it created for a results folder that failed are removed again (:func:`plot_tree`)."""
    from nmsm.errors import InputError
    from nmsm.io.output_file import check_default_folder_writable, check_output_folder

    if args.compare:
        return _compare(args)
    if args.results is None:
        raise InputError("no results folder given", expected="nmsm plot RESULTS_DIR (or nmsm plot --compare A B ...)")
    root = Path(args.results)
    if not root.is_dir():
        raise InputError("not a folder", file=root, expected="a results folder")
    output = None
    if args.output:
        output = check_output_folder(args.output, what="a folder for the figures (default: <each folder>/plots)")
    else:
        for _, folder in results_folders(root):
            plots = folder / "plots"
            check_default_folder_writable(plots if plots.is_dir() else folder, "the figures (<folder>/plots)")
    figures, errors = plot_tree(root, output)
    if not figures and not errors:
        print(f"nmsm: no results folder of JMP, MTP, NCP, GCP or treatment optimization in {root}", file=sys.stderr)
        return 1
    return 1 if errors else 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("plot", help="figures of every results folder in a tree (PNG)")
    p.add_argument("results", nargs="?", help="a results folder or a pipeline results tree")
    p.add_argument("--compare", nargs="+", metavar="FOLDER", default=[],
                   help="TO/VO/DO results folders drawn on the figures of the first (RESULTS, or the first of these): "
                        "nmsm plot --compare to vo do")
    p.add_argument("-o", "--output", help="write the figures here (default: <each folder>/plots)")
    p.set_defaults(func=_plot)
