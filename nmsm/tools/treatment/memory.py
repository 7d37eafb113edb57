"""Will a Treatment Optimization fit in memory? An estimate from the problem's size, made
before the problem is built.

Most of a solve's memory is taken when the solver is constructed: CasADi's derivative
functions of the per-point model functions (their size grows with the muscles, the contact
springs and the state coordinates, not with the points) and the evaluation of those
functions on every point (which grows with the points times the same sizes)::

    work per point   w  = STATE_WORK n_states + MUSCLE_WORK muscles + SPRING_WORK springs
    memory (GB)      m  = BASE_GB + w (FUNCTION_GB + POINT_GB points)

The coefficients are fitted to the peak resident memory of the synthetic full-body case of
``benchmarks/bench_treatment_scale.py --curves`` (docs/treatment.md, "Scale"). The dimension
named when the estimate does not fit is the one whose doubling would add most memory.
"""

from __future__ import annotations

import os
import resource
from pathlib import Path
from typing import Any

import attrs

from nmsm.errors import InputError

BASE_GB = 0.18
FUNCTION_GB = 0.0131
POINT_GB = 7.25e-5
#: work of a state coordinate, a muscle and a contact spring, relative to a muscle: their
#: shares of the per-point functions' SX instructions (a state coordinate in the inverse
#: dynamics; a spring its force and its position and velocity on its foot body)
STATE_WORK = 0.3
MUSCLE_WORK = 1.0
SPRING_WORK = 0.25


@attrs.frozen
class MemoryEstimate:
    """Estimated peak resident memory (GB) of a treatment solve and what drives it."""

    points: int
    states: int
    muscles: int
    springs: int

    @property
    def work(self) -> float:
        return STATE_WORK * self.states + MUSCLE_WORK * self.muscles + SPRING_WORK * self.springs

    @property
    def gigabytes(self) -> float:
        return BASE_GB + self.work * (FUNCTION_GB + POINT_GB * self.points)

    def shares(self) -> dict[str, float]:
        """GB each dimension adds when doubled: ``nodes``, ``muscles``, ``springs``, ``states``."""
        per_work = FUNCTION_GB + POINT_GB * self.points
        return {"nodes": self.work * POINT_GB * self.points, "muscles": MUSCLE_WORK * self.muscles * per_work,
                "springs": SPRING_WORK * self.springs * per_work, "states": STATE_WORK * self.states * per_work}

    def dominant(self) -> str:
        shares = self.shares()
        return max(shares, key=shares.__getitem__)


#: how to make each dimension smaller, for the message
REMEDIES = {
    "nodes": "fewer collocation points (setup_mesh_phase_intervals x setup_mesh_phase_colpoints_per_Interval in the "
             "solver settings)",
    "muscles": "fewer muscles driven by the synergy or muscle controller (the .osimx RCNLSynergySet groups)",
    "springs": "fewer contact springs (the .osimx RCNLContactSurface spring sets)",
    "states": "fewer coordinates in <states_coordinate_list> (the others are prescribed)",
}


def available_gigabytes() -> float:
    """Memory this process may still use (GB): the system's available memory, and no more
    than what is left under an address-space limit (``ulimit -v``)."""
    available = float("inf")
    try:
        for line in Path("/proc/meminfo").read_text(encoding="ascii").splitlines():
            if line.startswith("MemAvailable:"):
                available = float(line.split()[1]) / 1e6
    except OSError:
        pass
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        try:
            used = float(Path("/proc/self/statm").read_text(encoding="ascii").split()[0]) * os.sysconf("SC_PAGE_SIZE")
        except (OSError, ValueError):
            used = 0.0
        available = min(available, (soft - used) / 1e9)
    return available


def check_memory(estimate: MemoryEstimate, settings_file: Any, available: float | None = None) -> None:
    """Raise :class:`InputError` when ``estimate`` does not fit in ``available`` GB
    (default :func:`available_gigabytes`), naming the dominant dimension."""
    available = available_gigabytes() if available is None else available
    need = estimate.gigabytes
    if need <= available:
        return
    dominant = estimate.dominant()
    sizes = {"nodes": f"{estimate.points} collocation points", "muscles": f"{estimate.muscles} muscles",
             "springs": f"{estimate.springs} contact springs", "states": f"{estimate.states} state coordinates"}
    raise InputError(
        f"the problem needs about {need:.1f} GB ({', '.join(sizes.values())}) and {available:.1f} GB are available; "
        f"most of it grows with the {dominant} ({sizes[dominant]})", file=settings_file,
        expected=f"a smaller problem: {REMEDIES[dominant]}, or a machine with more memory")
