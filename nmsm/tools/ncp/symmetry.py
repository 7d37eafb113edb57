"""Bilateral symmetry: which muscle of one synergy group mirrors which of the other.

With ``enforce_bilateral_symmetry`` the two synergy groups share their synergy vectors
(the MATLAB original drops the second group's weights from the design variables and
copies the first's). The original pairs muscles by position; here a muscle is paired with
its mirror by name (``_r``/``_l`` or ``_R``/``_L`` suffix swapped) when every muscle has
one, and by position otherwise (with a warning naming the unpaired muscles).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

_SUFFIX_SWAPS = (("_r", "_l"), ("_l", "_r"), ("_R", "_L"), ("_L", "_R"))


def mirror_name(name: str) -> str | None:
    """The other side's name (``soleus_r`` -> ``soleus_l``), or None when there is no side suffix."""
    for suffix, other in _SUFFIX_SWAPS:
        if name.endswith(suffix):
            return name[: -len(suffix)] + other
    return None


def mirror_muscle_map(source: Sequence[str], target: Sequence[str], *, what: str = "synergy groups") -> tuple[int, ...]:
    """For each muscle of ``target``, the index of its mirror in ``source``.

    Raises :class:`ValueError` when the groups have different sizes; falls back to pairing
    by position (warning) when some muscles have no mirror by name.
    """
    if len(source) != len(target):
        raise ValueError(
            f"bilateral symmetry needs {what} of equal size: {len(source)} and {len(target)} muscles"
        )
    index = {name: i for i, name in enumerate(source)}
    mapped = [index.get(mirror_name(name) or "") for name in target]
    if all(i is not None for i in mapped) and len(set(mapped)) == len(mapped):
        return tuple(int(i) for i in mapped)  # type: ignore[arg-type]
    unpaired = [name for name, i in zip(target, mapped) if i is None]
    warnings.warn(
        f"bilateral symmetry: no mirror by name for {', '.join(unpaired[:8])}"
        f"{' ...' if len(unpaired) > 8 else ''}; pairing the {what}' muscles by position",
        stacklevel=2,
    )
    return tuple(range(len(target)))
