"""Suggestions for a name that was not found (columns, markers, elements)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def close_matches(name: str, candidates: Iterable[str], n: int = 5, cutoff: float = 0.6) -> list[str]:
    """Candidates that differ from ``name`` only in case first, then similar spellings."""
    pool = list(dict.fromkeys(candidates))
    lowered: dict[str, list[str]] = {}
    for candidate in pool:
        lowered.setdefault(candidate.lower(), []).append(candidate)
    same_case_free = lowered.get(name.lower(), [])
    similar = difflib.get_close_matches(name.lower(), list(lowered), n=n, cutoff=cutoff)
    out = list(same_case_free)
    for key in similar:
        out.extend(c for c in lowered[key] if c not in out)
    return out[:n]
