"""docs/guide.md: its Python examples run as written, in order, in an empty folder."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

GUIDE = Path(__file__).resolve().parents[1] / "docs" / "guide.md"


def python_blocks(text: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL)


def test_the_guide_s_python_examples_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    pytest.importorskip("pandas")
    blocks = python_blocks(GUIDE.read_text(encoding="utf-8"))
    assert len(blocks) == 3
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for k, block in enumerate(blocks, start=1):
        exec(compile(block, f"docs/guide.md python block {k}", "exec"), namespace)
    out = capsys.readouterr().out
    assert "Solve_Succeeded" in out and "TO cost terms, e.g." in out
    assert (tmp_path / "jmp_results" / "jmp_report.txt").is_file()
