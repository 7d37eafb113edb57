"""Comparison table of NCP results (ours vs the MATLAB original), like the seed paper's Table 3.

Both solutions are scored by the same code on the same inputs: the settings file's cost
terms (:func:`nmsm.tools.ncp.problem.score`, the proximal regularization excluded) and the
fit metrics (:func:`nmsm.tools.ncp.metrics.fit_metrics`) of the synergy activations read
from each results folder (``synergyWeights.sto`` and ``<trial>_synergyCommands.sto``).

    rows = [compare_results("NCPSettingsV1.xml", "ours/V1", "NCPResultsV1", label="V1"), ...]
    print(format_table(rows))
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.tools.ncp.loading import NcpSetup, load_ncp
from nmsm.tools.ncp.metrics import FitMetrics, fit_metrics
from nmsm.tools.ncp.outputs import read_solution
from nmsm.tools.ncp.problem import score


@attrs.frozen
class ScoredResult:
    """One results folder scored: cost per term (``total`` included) and fit metrics."""

    folder: Path
    costs: dict[str, float]
    metrics: FitMetrics


@attrs.frozen
class ComparisonRow:
    """One settings file: its synergies and terms, our result and the original's."""

    label: str
    synergies: str
    terms: str
    ours: ScoredResult
    original: ScoredResult | None

    @property
    def moment_rms_ratio(self) -> float:
        return self.ours.metrics.mean_moment_rms / self.original.metrics.mean_moment_rms if self.original else float("nan")

    @property
    def activation_rms_ratio(self) -> float:
        if not self.original:
            return float("nan")
        return self.ours.metrics.activation_rms_pooled / self.original.metrics.activation_rms_pooled


def score_folder(setup: NcpSetup, folder: str | os.PathLike[str]) -> ScoredResult:
    """Score the synergies written in ``folder`` with ``setup``'s inputs and terms."""
    trials = [t.name for t in setup.inputs.trials]
    solution = read_solution(folder, setup.inputs.layout, trials)
    return ScoredResult(Path(folder), score(setup.inputs, setup.terms, solution), fit_metrics(setup.inputs, solution))


def compare_results(
    settings_file: str | os.PathLike[str],
    ours: str | os.PathLike[str],
    original: str | os.PathLike[str] | None = None,
    *,
    label: str | None = None,
    enforce_bilateral_symmetry: bool | None = None,
) -> ComparisonRow:
    """Score our results folder and (optionally) the original's for one settings file."""
    from nmsm.tools.ncp.run import read_settings

    setup = load_ncp(read_settings(settings_file), enforce_bilateral_symmetry=enforce_bilateral_symmetry)
    layout = setup.inputs.layout
    synergies = " + ".join(str(g.n_synergies) for g in layout.groups)
    terms = ", ".join(t.label for t in setup.terms if t.kind == "cost")
    return ComparisonRow(
        label=label or Path(settings_file).stem,
        synergies=synergies,
        terms=terms,
        ours=score_folder(setup, ours),
        original=score_folder(setup, original) if original is not None else None,
    )


def _pair(ours: float, original: float | None, fmt: str) -> str:
    if original is None or not np.isfinite(original):
        return format(ours, fmt)
    return f"{format(ours, fmt)} / {format(original, fmt)}"


def format_table(rows: Sequence[ComparisonRow], *, per_coordinate: bool = False) -> str:
    """Markdown table: cost, mean moment RMS (N·m), activation RMS and VAF, ours / original.

    With ``per_coordinate`` a second table lists the moment RMS of every coordinate.
    """
    lines = [
        "| settings | synergies | cost terms | cost (nmsm / original) | moment RMS N·m (nmsm / original) "
        "| activation RMS (nmsm / original) | activation VAF % (nmsm / original) |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        o = row.original
        lines.append(
            f"| {row.label} | {row.synergies} | {row.terms} "
            f"| {_pair(row.ours.costs['total'], o.costs['total'] if o else None, '.5g')} "
            f"| {_pair(row.ours.metrics.mean_moment_rms, o.metrics.mean_moment_rms if o else None, '.3f')} "
            f"| {_pair(row.ours.metrics.activation_rms_pooled, o.metrics.activation_rms_pooled if o else None, '.4f')} "
            f"| {_pair(100 * row.ours.metrics.activation_vaf, 100 * o.metrics.activation_vaf if o else None, '.2f')} |"
        )
    if per_coordinate:
        for row in rows:
            o = row.original
            lines += ["", f"{row.label}: moment RMS per coordinate (N·m, nmsm / original)", "", "| coordinate | RMS |", "|---|---|"]
            for j, c in enumerate(row.ours.metrics.coordinates):
                lines.append(f"| {c} | {_pair(row.ours.metrics.moment_rms[j], o.metrics.moment_rms[j] if o else None, '.3f')} |")
    return "\n".join(lines)
