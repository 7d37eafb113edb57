"""How many threads nmsm's parallel CasADi evaluations use, a map that keeps to them, and the
threads of the BLAS under IPOPT's linear solves."""

from __future__ import annotations

import ctypes
import functools
import os
from collections.abc import Collection
from pathlib import Path

import casadi as cs

#: environment variable that sets :data:`SOLVER_THREADS` (a whole number >= 1): ``nmsm batch``
#: starts its worker processes with 1, so that runs in parallel do not share cores
THREADS_VARIABLE = "NMSM_THREADS"


def _threads() -> int:
    text = os.environ.get(THREADS_VARIABLE, "").strip()
    if text.isdigit() and int(text) >= 1:
        return int(text)
    return min(2, os.cpu_count() or 1)


#: threads of parallel CasADi evaluations (``map`` with ``thread`` parallelization): two
#: where the machine has two or more cores, unless :data:`THREADS_VARIABLE` says otherwise.
#: MUMPS's BLAS threads share the same cores, so more are not used (the measurements behind
#: two are in docs/developing.md).
SOLVER_THREADS = _threads()


def thread_map(function: cs.Function, n: int, *, shared: Collection[int] = (), threads: int = SOLVER_THREADS,
               name: str | None = None) -> cs.Function:
    """``function`` evaluated for ``n`` columns on at most ``threads`` threads.

    The result takes each input ``i`` with ``n`` times the columns of ``function``'s
    (column block ``k`` for evaluation ``k``), except the inputs listed in ``shared``, which
    keep ``function``'s size and are used by every evaluation; each output stacks the ``n``
    evaluations' outputs side by side. The same signature as
    ``function.map(name, "thread", n, shared, [])``, but that form starts one thread per
    evaluation at every call (its ``max_num_threads`` option is not applied; docs/developing.md,
    "GCP"), where this one starts ``threads``
    threads, each evaluating a contiguous share of the columns.
    """
    shared = set(shared)
    mapped = function.map(n, "thread", threads) if threads > 1 and n > 1 else function.map(n)
    inputs = [cs.MX.sym(function.name_in(i), function.sparsity_in(i) if i in shared
                        else cs.repmat(function.sparsity_in(i), 1, n)) for i in range(function.n_in())]
    arguments = [cs.repmat(x, 1, n) if i in shared else x for i, x in enumerate(inputs)]
    return cs.Function(name or f"{function.name()}_map", inputs, mapped.call(arguments),
                       function.name_in(), function.name_out())


#: environment variables with which a user chooses the BLAS threads themselves
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")


def limit_solver_blas_threads(threads: int = 1) -> int | None:
    """Set the threads of the BLAS that CasADi's IPOPT and MUMPS use (CasADi's bundled
    OpenBLAS, not numpy's) to ``threads``, unless one of :data:`BLAS_THREAD_VARIABLES` is set;
    returns the number of threads it now has, or None where that BLAS is not found.

    Its worker threads wait for work by spinning, on the same cores as the threads of
    :func:`thread_map`, so with more than one each factorization of MUMPS costs system time
    (the measurements: docs/developing.md, "Full-body case").
    """
    blas = _casadi_blas()
    if blas is None:
        return None
    if not any(os.environ.get(name, "").strip() for name in BLAS_THREAD_VARIABLES):
        blas.openblas_set_num_threads(int(threads))
    return int(blas.openblas_get_num_threads())


@functools.lru_cache(maxsize=1)
def _casadi_blas() -> ctypes.CDLL | None:
    """CasADi's bundled OpenBLAS (loaded once), or None where this CasADi build has none."""
    library = Path(cs.__file__).parent / "libcasadi-tp-openblas.so.0"
    return ctypes.CDLL(str(library)) if library.is_file() else None
