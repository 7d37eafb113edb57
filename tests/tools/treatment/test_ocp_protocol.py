"""The treatment tool's context implements every quantity the public protocol
(:class:`nmsm.core.ocp.OcpContext`) promises to a term, on each of its grids."""

from __future__ import annotations

from nmsm.core import ocp
from nmsm.testing.pendulum_problem import build_pendulum_problem


def _promised(protocol: type) -> set[str]:
    return {name for klass in protocol.__mro__ if klass.__module__ == ocp.__name__
            for name in vars(klass) if not name.startswith("_")}


def test_treatment_context_provides_every_promised_quantity() -> None:
    ctx = build_pendulum_problem([]).context
    assert not sorted(n for n in _promised(ocp.OcpContext) if not hasattr(ctx, n))
    for view in (ctx.initial, ctx.final):
        assert not sorted(n for n in _promised(ocp.OcpGrid) if not hasattr(view, n))
    assert ctx.coordinate("q0").shape == (ctx.n, 1) and ctx.final.coordinate("q0").shape == (1, 1)
