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
    """Its example pairs the synergies of check_term's leg (the pendulum has none)."""
    report = check_term(SynergyAmplitudeSymmetry)
    assert report.passed == ["declaration", "settings", "bad elements refused", "shape", "built, finite",
                             "derivatives"]
    assert report.problem == "leg" and report.not_built is None and report.warnings == []


@pytest.mark.parametrize("amplitude", ["rms", "mean", "peak"])
def test_symmetry_term_builds_with_exact_derivatives_on_any_pair_of_controls(amplitude: str) -> None:
    """The term compares two controls' amplitudes: on check_term's pendulum, its two torque
    controls stand for a pair of synergies."""
    report = check_term(SynergyAmplitudeSymmetry, {"synergy_pairs": "q0_moment:q1_moment", "amplitude": amplitude})
    assert report.passed == ["declaration", "settings", "bad elements refused", "shape", "built, finite",
                             "derivatives"]
    assert report.not_built is None and report.warnings == []


def test_an_unknown_control_in_a_pair_is_refused_naming_it() -> None:
    report = check_term(SynergyAmplitudeSymmetry, {"synergy_pairs": "q0_moment:RightSynergies_9"})
    assert report.not_built is not None
    assert "RightSynergies_9" in report.not_built and "<synergy_pairs>" in report.not_built


@pytest.mark.parametrize("pairs", ["RightSynergies_1", "a:", ""])
def test_malformed_pairs_are_refused_naming_the_element(pairs: str) -> None:
    spec = TermSpec("cost", SynergyAmplitudeSymmetry.type, {"is_enabled": "true", "synergy_pairs": pairs},
                    SourceRef("stroke.xml", 7))
    with pytest.raises(InputError, match="synergy_pairs"):
        SynergyAmplitudeSymmetry.from_spec(spec)
