"""The example plugin's term passes nmsm's conformance checks (``nmsm.testing.check_term``)
and refuses malformed pairs, as a plugin's own test suite would check it."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.term_spec import SourceRef, TermSpec
from nmsm.testing import check_term


def _source_module(name: str):
    """``nmsm_stroke/<name>.py`` of this source tree (not an installed copy of the plugin)."""
    path = Path(__file__).resolve().parents[1] / "nmsm_stroke" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"nmsm_stroke_source_{name}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


SynergyAmplitudeSymmetry = _source_module("symmetry").SynergyAmplitudeSymmetry


def test_symmetry_term_conforms() -> None:
    report = check_term(SynergyAmplitudeSymmetry)
    assert {"declaration", "settings", "bad elements refused"} <= set(report.passed)
    assert report.not_built and "synerg" in report.not_built  # the pendulum has no synergy controller


@pytest.mark.parametrize("pairs", ["RightSynergies_1", "a:", ""])
def test_malformed_pairs_are_refused_naming_the_element(pairs: str) -> None:
    spec = TermSpec("cost", SynergyAmplitudeSymmetry.type, {"is_enabled": "true", "synergy_pairs": pairs},
                    SourceRef("stroke.xml", 7))
    with pytest.raises(InputError, match="synergy_pairs"):
        SynergyAmplitudeSymmetry.from_spec(spec)
