"""``synergy_amplitude_symmetry``: paired synergy activation amplitudes should match.

After a stroke, a patient's paretic side may recruit a synergy with a lower amplitude than
the non-paretic side. This discrete cost compares, for each pair ``a:b`` of synergy
controls, an amplitude of ``a``'s activation with that of ``b``'s over the movement:

``rms``   sqrt(integral of u^2 over normalized time)
``mean``  integral of u over normalized time
``peak``  smooth maximum (log-sum-exp with sharpness 50 / max of the initial guess)

value = amplitude(a) - amplitude(b); the objective adds ((value - c)/e)^2 per pair.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs
import numpy as np

from nmsm.core.ocp import DiscreteCost

AMPLITUDES = ("rms", "mean", "peak")


def _pairs(text: Any) -> tuple[tuple[str, str], ...]:
    items = text.split() if isinstance(text, str) else list(text)
    out = []
    for item in items:
        left, sep, right = item.partition(":")
        if not sep or not left or not right:
            raise ValueError(f"synergy pair '{item}' is not 'a:b'")
        out.append((left, right))
    return tuple(out)


@attrs.frozen(kw_only=True)
class SynergyAmplitudeSymmetry(DiscreteCost):
    """Difference of activation amplitudes between paired synergies (activation units)."""

    type: ClassVar[str] = "synergy_amplitude_symmetry"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    check_example: ClassVar[dict[str, str]] = {"synergy_pairs": "group_1:group_2"}  # check_term's leg
    synergy_pairs: str
    amplitude: str = "rms"
    #: set by from_spec: one term per pair
    pair: tuple[str, str] | None = None

    @classmethod
    def from_spec(cls, spec: Any) -> list[Any]:
        terms = super().from_spec(spec)
        out = []
        for term in terms:
            try:
                pairs = _pairs(term.synergy_pairs)
            except ValueError as exc:
                raise term.error(str(exc), element="<synergy_pairs>", expected="pairs 'a:b' separated by spaces") from None
            if not pairs:
                raise term.error("no synergy pairs", element="<synergy_pairs>", expected="pairs 'a:b'")
            out.extend(attrs.evolve(term, pair=p) for p in pairs)
        return out

    @property
    def label(self) -> str:
        return f"{self.type}:{self.pair[0]}:{self.pair[1]}" if self.pair else self.type

    def bind(self, ctx: Any) -> None:
        if self.amplitude not in AMPLITUDES:
            raise self.error(f"<amplitude> '{self.amplitude}' is not valid", element="<amplitude>",
                             expected=", ".join(AMPLITUDES))
        for name in self.pair:
            ctx.require_control(self, name, element="<synergy_pairs>")

    def _amplitude(self, ctx: Any, name: str) -> Any:
        u = ctx.control(name)
        if self.amplitude == "rms":
            return cs.sqrt(ctx.integrate(u**2) + 1e-12)
        if self.amplitude == "mean":
            return ctx.integrate(u)
        scale = float(np.max(np.abs(np.asarray(ctx.initial_control(name)))) or 1.0)
        k = 50.0 / scale
        return cs.logsumexp(k * u) / k

    def quantity(self, ctx: Any) -> Any:
        return self._amplitude(ctx, self.pair[0]) - self._amplitude(ctx, self.pair[1])
