"""The synergy kicking tutorial's ``NCPSettings.xml`` (9 muscles, 4 synergies, no MTP results):
NCP driven by the ID moments alone, run as ``nmsm run`` does."""

from __future__ import annotations

import re
import warnings

import numpy as np

from nmsm.io.storage import read_storage
from nmsm.tools.dispatch import run_settings_file


def test_without_mtp_activations(shared_data, tmp_path) -> None:
    settings = shared_data / "treatment" / "synergy_kick_tutorial" / "NCPSettings.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_settings_file(settings, results_directory=tmp_path, print_level=0)
    assert run.solver.success, run.solver.status
    assert not run.setup.inputs.mtp_muscles
    assert max(run.metrics.moment_rms) < 1.0  # N m (measured 0.52, hip_flexion_r)
    log = (tmp_path / "commandWindowOutput.txt").read_text()
    # no activation fit to report: said so, not "nan"
    assert "activation RMS vs MTP: none (no muscle has MTP activations)" in log
    assert not re.search(r"\bnan\b", log, re.IGNORECASE), log
    activations = read_storage(tmp_path / "drive_kick1_combinedActivations.sto")
    assert activations.data.shape == (63, 9) and np.isfinite(activations.data).all()
