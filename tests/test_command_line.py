"""The ``nmsm`` command line as a whole: ``python -m nmsm`` and the global options."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from nmsm import __version__
from nmsm.cli import build_parser, main
from nmsm.core.progress import DEFAULT_INTERVAL


def test_python_dash_m_runs_the_command_line():
    done = subprocess.run([sys.executable, "-m", "nmsm", "--version"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"nmsm {__version__}"


def test_progress_interval_option():
    parser = build_parser()
    assert parser.parse_args(["plugins"]).progress == DEFAULT_INTERVAL == 5.0
    assert parser.parse_args(["--progress", "0", "plugins"]).progress == 0.0
    assert parser.parse_args(["--progress", "2.5", "plugins"]).progress == 2.5


def test_run_says_where_the_results_went(shared_data, tmp_path, capsys):
    """``nmsm run`` ends with the results folder (MTP printed nothing at all on success; every
    runner's return value has the folder: the next test)."""
    import warnings

    from nmsm.cli import main

    settings = shared_data / "mtp" / "uf_subject3_tutorial" / "CompletedSettingsFiles" / "MTPSettingsV3.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["--progress", "0", "run", str(settings), "-o", str(tmp_path / "mtp")]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == f"nmsm: results in {tmp_path / 'mtp'}"


def test_every_runner_of_nmsm_run_says_where_its_results_are():
    """What each ``nmsm run`` runner returns gives the line above: a results folder field, or
    the folder itself (the pipeline's preprocessing and surrogate stages)."""
    import importlib
    import inspect
    import typing

    import attrs

    from nmsm.tools.dispatch import TOOL_RUNNERS

    for tag, target in TOOL_RUNNERS.items():
        module, name = target.split(":")
        runner = getattr(importlib.import_module(module), name)
        returned = typing.get_type_hints(runner)["return"]
        if returned is not Path:
            assert inspect.isclass(returned) and attrs.has(returned), tag
            assert "results_directory" in attrs.fields_dict(returned), tag


def test_a_warning_is_shown_once_per_command(shared_data, tmp_path, recwarn):
    """Preprocessing reads its IK file in several steps (checks, ID, muscle analysis), each of
    which warns about the file's repeated row: the command shows that text once."""
    folder = shared_data / "opensim_gait10dof18musc"
    code = main(["preprocess", "--time-pair", "0.6 1.0", "--output", str(tmp_path / "out"), "--cutoff", "0",
                 "--model", str(folder / "gait10dof18musc_subject01.osim"),
                 "--ik", str(folder / "gait10dof18musc_subject_adjusted_Kinematics_q.sto"),
                 "--external-loads", str(folder / "gait10dof18musc_subject01_walk_grf.xml"),
                 "--compute-muscle-analysis"])
    assert code == 0
    repeated = [w for w in recwarn if "repeat the previous row" in str(w.message)]
    assert len(repeated) == 1


#: a parser with one command that finishes at once (``done``), for the Ctrl-C tests
FAST_PARSER = """
import argparse
from nmsm import cli


def fast_parser():
    parser = argparse.ArgumentParser(prog="nmsm")
    parser.add_argument("--traceback", action="store_true")
    parser.add_argument("--progress", type=float, default=0.0)
    parser.add_subparsers().add_parser("done").set_defaults(func=lambda args: 0)
    return parser
"""


def test_ctrl_c_after_the_command_finished_keeps_its_exit_status(tmp_path: Path) -> None:
    """A Ctrl-C arriving after the results were saved (nmsm exiting: the OpenSim worker
    closing, threads joining) leaves the exit status 0, not death by SIGINT."""
    import os

    script = FAST_PARSER + ("cli.build_parser = fast_parser\n"
                            "import os, signal, sys, time\n"
                            "sys.argv = ['nmsm', 'done']\n"
                            "code = cli.main()\n"
                            "os.kill(os.getpid(), signal.SIGINT)\n"
                            "time.sleep(0.5)\n"
                            "sys.exit(code)\n")
    done = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])})
    assert done.returncode == 0, done.stderr[-2000:]


def test_ctrl_c_while_leaving_a_finished_command_is_not_a_stop(monkeypatch, capsys) -> None:
    import contextlib

    from nmsm import cli

    namespace: dict = {}
    exec(FAST_PARSER, namespace)  # noqa: S102 - the parser above, in this process
    monkeypatch.setattr(cli, "build_parser", namespace["fast_parser"])

    @contextlib.contextmanager
    def interrupted_on_exit(seconds):
        yield
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "progress_every", interrupted_on_exit)
    assert cli.main(["done"]) == 0
    assert "stopped" not in capsys.readouterr().err
