"""Surrogate Model Creation: coordinate and muscle names are checked against the model before
any data file is looked for; named muscles are the only ones fitted; the muscle analysis
finds a model given by a relative path when OpenSim computes wrapping muscles."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.tools.surrogate.sampling import opensim_samples
from nmsm.model.surrogate_fitting import fit_from_data_directory

KICK = Path("treatment") / "surrogate_kick_tutorial"


def test_misspelled_coordinate_is_named_with_the_model(shared_data: Path) -> None:
    with pytest.raises(InputError, match=r"coordinates not in the model RightLegAndPelvis \(.*RightLegAndPelvis"
                                         r"\.osim\): 'knee_angel_r' \(did you mean knee_angle_r"):
        fit_from_data_directory(shared_data / KICK / "RightLegAndPelvis.osim", shared_data / KICK / "surrogateData",
                                ["knee_angel_r"])


def test_only_named_muscles_are_fitted_and_unknown_ones_refused(shared_data: Path) -> None:
    model, data = shared_data / KICK / "RightLegAndPelvis.osim", shared_data / KICK / "surrogateData"
    with pytest.raises(InputError, match=r"muscles not in the model RightLegAndPelvis .*'bogus_r'"):
        fit_from_data_directory(model, data, ["knee_angle_r"], muscles=["soleus_r", "bogus_r"])
    fitted = fit_from_data_directory(model, data, ["knee_angle_r"], muscles=["vasmed_r", "soleus_r"])
    assert fitted.muscle_names == ("vasmed_r",) and fitted.excluded_muscles == ("soleus_r",)


def test_opensim_sampling_checks_names_first(shared_data: Path, bridge) -> None:
    model = shared_data / KICK / "RightLegAndPelvis.osim"
    poses = np.zeros((2, 1))
    with pytest.raises(InputError, match=r"'knee_angel_r' \(did you mean knee_angle_r"):
        opensim_samples(model, ["knee_angle_r"], poses, ["knee_angel_r"], bridge=bridge)
    with pytest.raises(InputError, match=r"muscles not in the model .*'soleus_R' \(did you mean soleus_r"):
        opensim_samples(model, ["knee_angle_r"], poses, ["knee_angle_r"], muscles=["soleus_R"], bridge=bridge)


def test_muscle_analysis_with_a_relative_model_path(shared_data: Path, bridge, tmp_path: Path, monkeypatch) -> None:
    from nmsm.model.muscle_analysis import analyze_motion

    shutil.copy(shared_data / KICK / "RightLegAndPelvis.osim", tmp_path / "model.osim")
    motion = shared_data / KICK / "preprocessed" / "IKData" / "drive_kick1.sto"
    monkeypatch.chdir(tmp_path)
    result = analyze_motion("model.osim", motion, muscles=["gasmed_r", "soleus_r"], coordinates=["knee_angle_r"],
                            bridge=bridge)
    assert result.sources == {"gasmed_r": "opensim", "soleus_r": "path"}
    assert np.all(result.lengths > 0.1)


def test_command_line_passes_the_named_muscles(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.cli import main

    model, data = shared_data / KICK / "RightLegAndPelvis.osim", shared_data / KICK / "surrogateData"
    out = tmp_path / "s.json"
    common = ["surrogate", "--model", str(model), "--data-dir", str(data), "--coordinates", "knee_angle_r",
              "-o", str(out)]
    assert main(common + ["--muscles", "soleus_r", "bogus_r"]) == 1 and not out.exists()
    assert main(common + ["--muscles", "vasmed_r"]) == 0
    from nmsm.model.surrogate import SurrogateModel

    assert SurrogateModel.load(out).muscle_names == ("vasmed_r",)


def test_muscle_analysis_refuses_a_trial_name_with_a_path_before_computing(shared_data: Path, tmp_path: Path,
                                                                          monkeypatch) -> None:
    import nmsm.model.muscle_analysis as analysis
    from nmsm.cli import main

    monkeypatch.setattr(analysis, "analyze_motion", lambda *a, **k: pytest.fail("computed before refusing"))
    motion = shared_data / KICK / "preprocessed" / "IKData" / "drive_kick1.sto"
    code = main(["muscle-analysis", str(shared_data / KICK / "RightLegAndPelvis.osim"), str(motion),
                 "--trial", "../../escape", "-o", str(tmp_path / "MA")])
    assert code == 1 and not (tmp_path / "escape").exists()
