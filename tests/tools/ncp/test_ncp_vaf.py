"""NMF, variance accounted for, and ``nmsm vaf``."""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case
from nmsm.tools.ncp.nmf import nmf, variance_accounted_for
from nmsm.tools.ncp.vaf import read_activation_trials, vaf_curve


def test_nmf_recovers_exact_low_rank_data() -> None:
    rng = np.random.default_rng(1)
    weights = rng.uniform(0, 1, (3, 12))
    commands = np.abs(np.sin(np.linspace(0, 6, 200)[:, None] * np.array([1.0, 1.7, 2.9])))
    data = commands @ weights
    result = nmf(data, 3)
    assert result.vaf > 0.9999
    assert variance_accounted_for(data, result.reconstruction) == pytest.approx(result.vaf)
    assert (result.weights >= 0).all() and (result.commands >= 0).all()


def test_vaf_reaches_99_percent_at_the_true_number_of_synergies(tmp_path) -> None:
    case = make_synthetic_ncp_case(tmp_path, n_synergies=3)
    right = [i for i, m in enumerate(case.muscles) if m.endswith("_r")]
    data = np.vstack([a[:, right] for a in case.true_activations])
    curve = vaf_curve(data, 5, muscles=[case.muscles[i] for i in right])
    assert curve.counts == (1, 2, 3, 4, 5)
    assert all(b >= a - 1e-9 for a, b in zip(curve.vaf, curve.vaf[1:]))
    assert curve.vaf[1] < 0.99 <= curve.vaf[2]
    assert curve.smallest_count(0.99) == 3


def test_vaf_command_line(tmp_path, capsys) -> None:
    case = make_synthetic_ncp_case(tmp_path, n_synergies=3)
    folder = tmp_path / "mtp" / "muscleActivations"
    data, names = read_activation_trials([folder])
    assert data.shape == (202, 12) and names[0] == "glmax_r"
    code = main(["vaf", str(folder), "--model", str(case.model_file), "--group", "RightLeg", "--max-synergies", "4",
                 "--output", str(tmp_path / "vaf.csv")])
    out = capsys.readouterr().out
    assert code == 0
    assert "RightLeg: 6 muscles" in out and "no activation column: iliacus_r, soleus_r" in out
    assert (tmp_path / "vaf.csv").read_text().startswith("synergies,vaf_percent\n1,")


def test_vaf_command_line_bad_group(tmp_path, capsys) -> None:
    case = make_synthetic_ncp_case(tmp_path)
    code = main(["vaf", str(tmp_path / "mtp" / "muscleActivations"), "--model", str(case.model_file), "--group", "RightLg"])
    assert code == 1
    assert "'RightLg' is not a ForceSet group" in capsys.readouterr().err
