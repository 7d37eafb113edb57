"""`nmsm id` of a motion whose times are in milliseconds warns (it ran silently: velocities and
accelerations 1e3 and 1e6 times too small, the toy arm's moments off by its whole inertial
part)."""

from __future__ import annotations

import warnings
from pathlib import Path

import attrs
import pytest

from nmsm.io.storage import read_storage
from nmsm.model import load_model
from nmsm.model.id_tool import inverse_dynamics_of_motion


@pytest.mark.shared_data
def test_motion_in_milliseconds_warns(shared_data: Path) -> None:
    folder = shared_data / "treatment" / "toy_arm" / "tracking_optimization"
    model = load_model(folder / "simple_arm.osim")
    motion = read_storage(folder / "preprocessed" / "IKData" / "arm1.sto")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # seconds: silent
        inverse_dynamics_of_motion(model, motion)
    with pytest.warns(UserWarning, match=r"arm1.sto: frames are 16.6667 s apart: are the times in milliseconds\?"):
        inverse_dynamics_of_motion(model, attrs.evolve(motion, time=motion.time * 1000.0))
