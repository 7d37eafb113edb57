"""The full-body gait stress case solved from its settings files, full mesh (25 x 4), TO -> VO
-> DO (issue 24, items 1 and 4), in a child process capped at 10 minutes and 12 GB of
address space. Marked ``scale``, in neither the default nor the slow suite: run it with
``python -m pytest -m scale``.

Checks: IPOPT succeeds in every tool; every TO tracking term's RMS is within its
``max_allowable_error``; states, controls, synergy commands, combined activations, IK, ID and
both feet's ground reactions are written; the VO reproduces the TO within 0.1 deg and
0.1 N·m; the DO changes the paretic synergy's drive and names the terms that drove it.

Today the TO iterates (limited-memory Hessian, about 0.7 GB) but needs hundreds of
iterations of a few CPU seconds each, longer than the cap (docs/treatment.md, "Scale"):
running out of time or memory (an abort, a ``MemoryError``) raises :class:`TooSlowOrTooBig`,
the expected failure. A run that ends inside the cap and misses a check fails; one that
passes shows as a strict XPASS (remove the marker then).
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
from pathlib import Path

import pytest

TIME_LIMIT_S = 600
MEMORY_LIMIT_GB = 12
CHILD = r"""
import json, sys
from nmsm.examples.fullbody_checks import run_chain
print("CHAIN " + json.dumps(run_chain(json.loads(sys.argv[1]))), flush=True)
"""


class TooSlowOrTooBig(Exception):
    """The chain did not finish inside the time and memory caps."""


def _limit() -> None:
    size = MEMORY_LIMIT_GB * 1024 ** 3
    resource.setrlimit(resource.RLIMIT_AS, (size, size))


@pytest.fixture(scope="module")
def full_stress(shared_data, tmp_path_factory):
    from nmsm.examples.fullbody import write_case

    return write_case(tmp_path_factory.mktemp("fullbody_full"), "stress", "full", shared_data, quick=True)


@pytest.mark.scale
@pytest.mark.xfail(raises=TooSlowOrTooBig, strict=True,
                   reason="the full-body stress TO -> VO -> DO chain takes longer than 10 min")
def test_stress_chain_full_mesh(full_stress):
    repo = Path(__file__).resolve().parents[3]
    try:
        proc = subprocess.run([sys.executable, "-c", CHILD, json.dumps({k: str(v) for k, v in full_stress.items()})],
                              capture_output=True, text=True, timeout=TIME_LIMIT_S, preexec_fn=_limit, cwd=repo,
                              check=False)
    except subprocess.TimeoutExpired as exc:
        raise TooSlowOrTooBig(f"no result after {TIME_LIMIT_S} s") from exc
    out_of_memory = ("MemoryError", "std::bad_alloc", "cannot allocate memory",
                     "the problem needs about")  # the last: nmsm's memory estimate stopped it before building
    if proc.returncode < 0 or any(s in proc.stderr for s in out_of_memory):
        raise TooSlowOrTooBig(f"out of the {MEMORY_LIMIT_GB} GB cap (exit {proc.returncode}): {proc.stderr[-500:]}")
    lines = [line for line in proc.stdout.splitlines() if line.startswith("CHAIN ")]
    assert lines, proc.stderr[-3000:]
    chain = json.loads(lines[-1].split(" ", 1)[1])
    assert [chain[t]["success"] for t in ("to", "vo", "do")] == [True, True, True], chain
    misses = {label: v for label, v in chain["to"]["tracking"].items() if v[0] > v[1]}
    assert not misses, misses
    files = set(chain["to"]["files"])
    for name in ("gait_1_states.sto", "gait_1_torqueControls.sto", "gait_1_synergyCommands.sto",
                 "gait_1_combinedActivations.sto", "IKData/gait_1.sto", "IDData/gait_1.sto", "GRFData/gait_1.sto"):
        assert name in files, name
    versus = chain["vo"]["versus_to"]
    assert versus["max_angle_deg"] <= 0.1 and versus["max_moment_Nm"] <= 0.1, versus
    design = chain["do"]["design"]
    (scale,) = design["parameters"].values()
    assert scale[0] < 1 - 1e-3, design
    assert design["term_changes"], design
