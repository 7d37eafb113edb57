"""Every relative link of README.md, benchmarks/README.md and docs/*.md names a file of the
repository and, with ``#anchor``, a heading of that file (GitHub's anchor rule)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _anchors(path: Path) -> set[str]:
    found, fence = set(), False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            fence = not fence
        match = re.match(r"^#+ (.*)", line)
        if match and not fence:
            found.add(re.sub(r"[^\w\- ]", "", match.group(1).strip().lower()).replace(" ", "-"))
    return found


def broken_links(files: list[Path]) -> list[str]:
    """``file: target: reason`` of each relative link that does not resolve."""
    bad = []
    for file in files:
        text = re.sub(r"```.*?```", "", file.read_text(encoding="utf-8"), flags=re.S)
        for match in re.finditer(r"\]\(([^)\s]+)\)", text):
            target = match.group(1)
            if re.match(r"^[a-z]+:", target):
                continue
            path, _, anchor = target.partition("#")
            destination = (file.parent / path).resolve() if path else file
            if not destination.exists():
                bad.append(f"{file.name}: {target}: no such file")
            elif anchor and destination.suffix == ".md" and anchor not in _anchors(destination):
                bad.append(f"{file.name}: {target}: no such heading")
    return bad


def test_every_relative_link_resolves() -> None:
    files = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), *sorted((ROOT / "benchmarks").glob("*.md"))]
    assert broken_links(files) == []


def test_a_broken_link_or_anchor_is_found(tmp_path: Path) -> None:
    (tmp_path / "a.md").write_text("# Title here\n[x](b.md) [y](a.md#title-here) [z](#nowhere) [w](https://x.org/q)\n",
                                   encoding="utf-8")
    assert broken_links([tmp_path / "a.md"]) == ["a.md: b.md: no such file", "a.md: #nowhere: no such heading"]
