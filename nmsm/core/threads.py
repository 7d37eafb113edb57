"""How many threads nmsm's parallel CasADi evaluations use by default."""

from __future__ import annotations

import os

#: threads of parallel CasADi evaluations (``map`` with ``thread`` parallelization): two
#: where the machine has two or more cores. Measured on the 2-core CI machine
#: (docs/mtp.md, docs/treatment.md); MUMPS's BLAS threads share the same cores, so more
#: is not used without a measurement.
SOLVER_THREADS = min(2, os.cpu_count() or 1)
