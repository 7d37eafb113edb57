"""Which distribution registered a class: ``(distribution, version)``, for messages about a
plugin's code (:class:`nmsm.core.term.TermCodeError`). Filled by the registry."""

from __future__ import annotations

import weakref

#: class -> (distribution, version) of every class a registry holds
_ORIGINS: weakref.WeakKeyDictionary[type, tuple[str, str]] = weakref.WeakKeyDictionary()


def record_origin(cls: type, distribution: str, version: str) -> None:
    """Remember that ``distribution`` ``version`` registered ``cls``."""
    _ORIGINS[cls] = (distribution, version)


def origin_of(cls: type) -> tuple[str, str] | None:
    """``(distribution, version)`` that registered ``cls`` (or a class it derives from), if any."""
    for klass in cls.__mro__:
        try:
            found = _ORIGINS.get(klass)
        except TypeError:
            continue
        if found is not None:
            return found
    return None
