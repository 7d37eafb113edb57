"""Single-threaded OpenBLAS while a trust-region least-squares solver with LSMR steps runs.

scipy's LSMR steps take many norms and dot products of vectors of ~1e4 entries. With the
bundled OpenBLAS allowed several threads, each such call wakes the BLAS threads, which on a
machine with more runnable processes than cores costs far more than the call itself
(docs/developing.md, GCP). :func:`single_threaded_blas` sets every OpenBLAS copy loaded in the
process (numpy's and scipy's) to one thread and restores the previous counts afterwards.
Nothing happens where no OpenBLAS library is found (e.g. another BLAS, non-Linux systems).
"""

from __future__ import annotations

import ctypes
import functools
from collections.abc import Iterator
from contextlib import contextmanager

#: (setter, getter) symbol names of the OpenBLAS builds numpy and scipy wheels ship
_SYMBOLS = (
    ("scipy_openblas_set_num_threads64_", "scipy_openblas_get_num_threads64_"),
    ("scipy_openblas_set_num_threads", "scipy_openblas_get_num_threads"),
    ("openblas_set_num_threads64_", "openblas_get_num_threads64_"),
    ("openblas_set_num_threads", "openblas_get_num_threads"),
)


@functools.lru_cache(maxsize=1)
def _controls() -> tuple[tuple[object, object], ...]:
    """``(set, get)`` function pairs of the OpenBLAS libraries mapped into this process."""
    import numpy  # noqa: F401  (load numpy's and scipy's BLAS before scanning)
    import scipy.sparse.linalg  # noqa: F401

    try:
        with open("/proc/self/maps", encoding="utf-8") as maps:
            paths = sorted({line.split()[-1] for line in maps if "openblas" in line.lower() and "/" in line})
    except OSError:
        return ()
    found = []
    for path in paths:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for setter, getter in _SYMBOLS:
            if hasattr(lib, setter) and hasattr(lib, getter):
                set_fn, get_fn = getattr(lib, setter), getattr(lib, getter)
                set_fn.argtypes, set_fn.restype = [ctypes.c_int], None
                get_fn.argtypes, get_fn.restype = [], ctypes.c_int
                found.append((set_fn, get_fn))
                break
    return tuple(found)


@contextmanager
def single_threaded_blas() -> Iterator[None]:
    """Run the block with one OpenBLAS thread (module docstring)."""
    controls = _controls()
    previous = [get() for _, get in controls]
    for set_fn, _ in controls:
        set_fn(1)
    try:
        yield
    finally:
        for (set_fn, _), count in zip(controls, previous):
            set_fn(count)
