"""Source comments and docstrings point where a reader of the installed package can follow.

The specification of the original MATLAB tools that nmsm was written from is not shipped with
nmsm, so a comment citing it (``tools.md §6.3``, ``catalog §1.4``, ``spec pitfall``) leads
nowhere. References go to our own docs (``docs/<tool>.md``, ``docs/terms.md``) or to the
original's public code and paper (docs/architecture.md). Dates, history and measurements
belong in docs/developing.md, not in code comments (docs/developing.md, "Audit trail").
"""

from __future__ import annotations

import ast
import io
import pathlib
import re
import tokenize

ROOT = pathlib.Path(__file__).resolve().parents[1]
SOURCES = sorted((ROOT / "nmsm").rglob("*.py"))

#: references into the unshipped specification (its files, its section signs, its pitfall list)
UNSHIPPED_SPEC = re.compile(
    r"§|\btools\.md\b|\bsettings-xml\.md\b|\bcost-constraint-terms\.md\b|\bpitfalls\.md\b|\bosimx\.md\b"
    r"|shared/spec\b|\bspec pitfall|\bspec tools\b|\bcatalog §"
)
#: a calendar date (2026-11-25) in a comment or docstring: history, which goes to docs/developing.md
DATE = re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b")
#: a measurement told in a comment or docstring ("Measured on ...", "3.1 s instead of 4.2 s",
#: "Patient 3: 482 iterations", a load average): measurements go to docs/developing.md
MEASUREMENT = re.compile(r"\bMeasured\b|\bmeasured (on|with) (the|a|CasADi)\b|\binstead of \d|\bload average|\bPatient 3:")


def _relative(path: pathlib.Path) -> str:
    return str(path.relative_to(ROOT))


def _comments_and_docstrings(text: str) -> list[tuple[int, str]]:
    """(line, text) of every ``#`` comment and every module, class and function docstring."""
    out = [(tok.start[0], tok.string) for tok in tokenize.generate_tokens(io.StringIO(text).readline)
           if tok.type == tokenize.COMMENT]
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                    and isinstance(body[0].value.value, str):
                out.append((body[0].lineno, body[0].value.value))
    return out


def test_the_scan_sees_the_package():
    assert len(SOURCES) > 100
    assert UNSHIPPED_SPEC.search("GCP's contact model (spec tools.md §6.3)")
    assert UNSHIPPED_SPEC.search("(catalog §1.4)") and UNSHIPPED_SPEC.search("a change of velocity; spec pitfall")
    assert not UNSHIPPED_SPEC.search("(docs/gcp.md, 'Outputs')") and not UNSHIPPED_SPEC.search("spec.element")
    assert MEASUREMENT.search("Measured on the 2-core machine") and MEASUREMENT.search("0.7 s instead of 3.2 s")
    assert not MEASUREMENT.search("Accuracy is measured on held-out poses")
    assert DATE.search("# measured 2026-11-25") and not DATE.search("# 0.2026 s")
    assert _comments_and_docstrings('"""Doc."""\nx = 1  # note\n') == [(2, "# note"), (1, "Doc.")]


def test_no_reference_to_the_unshipped_spec():
    """Comments, docstrings and messages cite our docs or the original's public sources."""
    hits = [f"{_relative(path)}:{number}: {line.strip()}" for path in SOURCES for number, line in
            enumerate(path.read_text(encoding="utf-8").splitlines(), start=1) if UNSHIPPED_SPEC.search(line)]
    assert not hits, "references into the specification, which nmsm does not ship:\n" + "\n".join(hits)


def test_no_dates_in_comments():
    hits = [f"{_relative(path)}:{line}: {DATE.search(text).group()}" for path in SOURCES
            for line, text in _comments_and_docstrings(path.read_text(encoding="utf-8")) if DATE.search(text)]
    assert not hits, "dated comments (history goes to docs/developing.md):\n" + "\n".join(hits)


def test_no_measurements_in_comments():
    hits = [f"{_relative(path)}:{line}: {MEASUREMENT.search(text).group()}" for path in SOURCES
            for line, text in _comments_and_docstrings(path.read_text(encoding="utf-8")) if MEASUREMENT.search(text)]
    assert not hits, "measurements in comments (they go to docs/developing.md):\n" + "\n".join(hits)
