"""Synergy Extrapolation with NMF (the original's NMF path is broken) on tutorial V1.

``MTPSettingsV1.xml`` with ``<matrix_factorization_method>NMF``: non-negative synergy
commands, non-negative extrapolation weights, so the extrapolated (iliacus) activation
is a non-negative combination of synergy excitations; it must do the job SynX exists for:
the hip moment, which the measured muscles alone cannot produce, is tracked.
Measured 2026-11-25 (load ~1.2 on 2 cores): 3.8 s wall.
"""

from __future__ import annotations

import warnings

import numpy as np

from nmsm.tools.mtp.report import moment_rms
from nmsm.tools.mtp.run import run_settings


def test_v1_with_nmf(shared_data, tmp_path):
    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    text = (tutorial / "CompletedSettingsFiles" / "MTPSettingsV1.xml").read_text()
    assert "<matrix_factorization_method>PCA" in text
    text = (text.replace("<matrix_factorization_method>PCA", "<matrix_factorization_method>NMF")
            .replace("<input_model_file>", f"<input_model_file>{tutorial}/")
            .replace("<data_directory>", f"<data_directory>{tutorial}/")
            .replace("<passive_data_input_directory>", f"<passive_data_input_directory>{tutorial}/"))
    settings = tmp_path / "MTPSettingsNMF.xml"
    settings.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome = run_settings(settings, results_directory=tmp_path / "results")
    sx = outcome.setup.data.synx
    assert sx.method == "NMF" and sx.per_vector == sx.n_synergies  # no bias
    assert all(np.all(c >= 0) for c in sx.extrapolation_commands)
    assert outcome.tasks[-1].status == "Solve_Succeeded"
    weights = outcome.state.synergy_weights[: sx.n_extrapolation_weights]
    assert np.all(weights >= -1e-8)
    missing = list(outcome.setup.data.missing)
    extrapolated = outcome.synx.activations[..., missing]
    assert extrapolated.min() >= 0.0 and extrapolated.max() <= 1.0 and extrapolated.max() > 0.05
    with_synx = moment_rms(tmp_path / "results", synx=True)["gait_1"]
    without = moment_rms(tmp_path / "results", synx=False)["gait_1"]
    assert with_synx["hip_flexion_r"] <= 0.5 * without["hip_flexion_r"]
