"""Helpers of the batch tests: batch files written in code, the processes a batch left."""

from __future__ import annotations

import textwrap
import time
from pathlib import Path

import psutil

KNEE_BOUNDS = "JMPTaskList/JMPTask/JMPJointSet/JMPJoint[@name='knee']/parent_frame_transformation/orientation_bounds"


def write_batch(folder: Path, runs: str, results: str = "out") -> Path:
    """A batch file in ``folder`` with ``runs`` (the elements of its <RunList>)."""
    path = folder / "batch.xml"
    path.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<NMSMPipelineDocument Version="1.5.3">
  <BatchTool name="test">
    <results_directory>{results}</results_directory>
    <RunList>
{textwrap.dedent(runs)}
    </RunList>
  </BatchTool>
</NMSMPipelineDocument>
""", encoding="utf-8")
    return path


def sweep(settings: Path, values: str = "0.2 0.5", name: str = "bounds", extra: str = "") -> str:
    return f"""<Sweep name="{name}">
  <settings_file>{settings}</settings_file>{extra}
  <Parameter name="knee_bounds"><element>{KNEE_BOUNDS}</element><values>{values}</values></Parameter>
</Sweep>"""


#: helper processes Python's multiprocessing starts once per process and keeps (not a cluster's)
_PROCESS_HELPERS = ("multiprocessing.resource_tracker", "multiprocessing.forkserver")


def _cmdline(process: psutil.Process) -> str:
    try:
        return " ".join(process.cmdline())
    except psutil.Error:
        return ""


def leftover_processes(wait: float = 10.0) -> list[str]:
    """Command lines of child processes of this test process still alive after ``wait``
    seconds, multiprocessing's own helpers left out (a cluster's workers and nannies must be
    gone once a batch returns)."""
    deadline = time.monotonic() + wait
    while True:
        children = []
        for child in psutil.Process().children(recursive=True):
            try:
                alive = child.is_running() and child.status() != psutil.STATUS_ZOMBIE
            except psutil.Error:
                continue
            line = _cmdline(child)
            if alive and not any(helper in line for helper in _PROCESS_HELPERS):
                children.append(line[:160])
        if not children or time.monotonic() > deadline:
            return children
        time.sleep(0.2)
