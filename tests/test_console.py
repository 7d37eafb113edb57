"""One console shape for every tool: start line, progress, end summary (nmsm.core.console)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from nmsm.cli import main
from nmsm.core.console import announce, console_output, start_line, summarize

TOY = Path("treatment") / "toy_arm"


def test_start_line_and_summary_print_only_when_switched_on(capsys) -> None:
    line = start_line("TO", settings="/a/b/to.xml", model="/a/leg.osim", trials=[f"t{k}" for k in range(6)],
                      problem="5 mesh intervals")
    assert line == ("nmsm TO: settings to.xml; model leg.osim; trials t0, t1, t2, t3 and 2 more; "
                    "problem 5 mesh intervals")
    announce("TO", settings="to.xml")
    summarize("TO", ["x"])
    assert capsys.readouterr().out == ""  # library calls stay silent
    with console_output():
        announce("TO", settings="to.xml")
        summarize("TO", ["first", "second"])
    assert capsys.readouterr().out == "nmsm TO: settings to.xml\nnmsm TO summary:\n  first\n  second\n"


def test_treatment_run_prints_its_start_line_and_summary(shared_data: Path, tmp_path: Path, capsys) -> None:
    settings = shared_data / TOY / "tracking_optimization" / "TorqueDrivenTOSettings.xml"
    assert main(["--progress", "0", "run", str(settings), "-o", str(tmp_path / "to")]) == 0
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if line.startswith(("nmsm", "  "))]
    assert lines[0] == ("nmsm TO: settings TorqueDrivenTOSettings.xml; model simple_arm.osim; trials arm1; problem "
                        "5 mesh intervals, 202 variables, 150 constraint rows, 2 cost terms")
    summary = out[out.index("nmsm TO summary:"):].splitlines()
    assert re.fullmatch(r"  IPOPT Solve_Succeeded after \d+ iterations, [\d.]+ s; objective \S+ -> \S+", summary[1])
    assert summary[2] == "  tracking RMS (of each group the term furthest from its max_allowable_error):"
    assert re.fullmatch(r"    generalized_coordinate_tracking +\S+ deg +\(\S+ x max_allowable_error; "
                        r"generalized_coordinate_tracking:r_elbow_flex; "
                        r"0 of 1 term\(s\) above theirs\)", summary[3]), summary[3]
    assert re.fullmatch(r"    inverse_dynamics_load_tracking +\S+ N·m +\(\S+ x max_allowable_error; "
                        r"inverse_dynamics_load_tracking:r_elbow_flex_moment; 0 of 1 term\(s\) above theirs\)",
                        summary[4]), summary[4]
    assert re.fullmatch(r"  constraint violation: largest \S+ \(\w+\); 0 of 2 block\(s\) above 0.0001", summary[5])
    assert summary[6] == f"nmsm: results in {tmp_path / 'to'}"


def test_mtp_parameters_at_bounds() -> None:
    from nmsm.tools.mtp.model import MuscleDesign
    from nmsm.tools.mtp.problem import MtpState
    from nmsm.tools.mtp.summary import parameters_at_bounds

    design = MuscleDesign(electromechanical_delay=np.array([0.0, 0.5, 1.25]),
                          activation_time_constant=np.array([1.5, 0.75 + 1e-7, 2.0]),
                          activation_nonlinearity=np.array([0.1, 0.1, 0.1]), emg_scale=np.array([0.5, 0.5, 1.0]),
                          optimal_fiber_length_scale=np.ones(3), tendon_slack_length_scale=np.ones(3))
    assert parameters_at_bounds(MtpState(design, np.zeros(0)), ("a", "b", "c")) == {
        ("electromechanical_delay", "lower"): ["a"], ("electromechanical_delay", "upper"): ["c"],
        ("activation_time_constant", "lower"): ["b"], ("emg_scale", "upper"): ["c"]}
