"""``nmsm run SETTINGS --start-from DIR``: a treatment run started from another run's results
(e.g. the same settings on a coarser mesh), its references unchanged; other tools refuse it."""

from __future__ import annotations

import re
from pathlib import Path

from nmsm.cli import main

TOY_TO = Path("treatment") / "toy_arm" / "tracking_optimization" / "TorqueDrivenTOSettings.xml"
JMP = Path("jmp") / "uf_subject3_tutorial" / "CompletedSettingsFiles" / "JMPSettingsSequential.xml"


def _iterations(out: str) -> int:
    return int(re.search(r"IPOPT Solve_Succeeded after (\d+) iterations", out).group(1))


def test_a_run_started_from_its_own_solution_needs_fewer_iterations(shared_data: Path, tmp_path: Path,
                                                                     capsys) -> None:
    settings = shared_data / TOY_TO
    assert main(["--progress", "0", "run", str(settings), "-o", str(tmp_path / "first")]) == 0
    first = _iterations(capsys.readouterr().out)
    assert main(["--progress", "0", "run", str(settings), "-o", str(tmp_path / "again"),
                 "--start-from", str(tmp_path / "first")]) == 0
    again = _iterations(capsys.readouterr().out)
    assert first >= 3 and again < first, (first, again)


def test_other_tools_refuse_it(shared_data: Path, tmp_path: Path, capsys) -> None:
    assert main(["run", str(shared_data / JMP), "-o", str(tmp_path / "jmp"), "--start-from", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "--start-from is for treatment optimization settings, not <JointModelPersonalizationTool>" in err, err
    assert not (tmp_path / "jmp").exists()
