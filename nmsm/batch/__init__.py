"""Many runs at once: ``nmsm batch BATCH.xml`` and :func:`run` on Dask distributed.

A batch file lists runs (tool settings files, pipeline files) and sweeps that vary named
settings elements, each variant warm-started from its parent's results; runs wait for the
runs they depend on, the others run in parallel on a local cluster of worker processes or an
existing Dask cluster. docs/batch.md describes the file, the ways to run and the summary.

Modules, one job each: :mod:`~nmsm.batch.batch_file` (reading the file),
:mod:`~nmsm.batch.sweep` (runs and their settings), :mod:`~nmsm.batch.graph` (dependencies),
:mod:`~nmsm.batch.task` (one run on a worker), :mod:`~nmsm.batch.execute` (the cluster and
the schedule), :mod:`~nmsm.batch.summary` (``batch_summary.csv`` and figures),
:mod:`~nmsm.batch.template` (``nmsm print-xml batch``), :mod:`~nmsm.batch.cli` (the command).
"""

from __future__ import annotations

import os
from typing import Any


def run(batch_file: str | os.PathLike[str], **options: Any) -> Any:
    """Run a batch file (as ``nmsm batch``) and return its :class:`~nmsm.batch.execute.BatchRun`
    (outcomes, ``summary_file``, ``text()``). Options: ``results_directory``, ``workers``,
    ``scheduler``, ``timeout`` (s), ``log``, ``on_event`` (:func:`nmsm.batch.execute.run_batch`)."""
    from nmsm.batch.execute import run_batch

    if not isinstance(batch_file, (str, os.PathLike)):
        raise TypeError(f"nmsm.batch.run(batch_file): expected the path of a file (str or os.PathLike), got "
                        f"{type(batch_file).__name__} {batch_file!r}")
    return run_batch(batch_file, **options)
