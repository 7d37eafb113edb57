"""A name in NCP's <coordinate_list> that is no coordinate of the model is an error (fuzz audit:
a misspelled coordinate crossed no muscle, so its muscles were silently left out of the synergy
groups and the run finished with one warning about a missing inverse-dynamics column)."""

from __future__ import annotations

import pytest
from lxml import etree

from nmsm.errors import InputError
from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case
from nmsm.tools.ncp.run import run_settings


def test_misspelled_coordinate_is_one_error_naming_close_matches(tmp_path) -> None:
    case = make_synthetic_ncp_case(tmp_path, n_trials=2, n_points=41)
    tree = etree.parse(str(case.settings_file))
    element = tree.getroot().find("NeuralControlPersonalizationTool/coordinate_list")
    names = element.text.split()
    misspelled = names[-1][:-1] + names[-1][-1].upper() + "x"
    element.text = " ".join([*names[:-1], misspelled])
    tree.write(str(case.settings_file))
    results = tmp_path / "results"
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, results_directory=results, print_level=0)
    message = str(info.value)
    assert message.startswith(f"{case.settings_file}: <coordinate_list>: '{misspelled}' is not a coordinate of model")
    assert f"close matches: {names[-1]}" in message and "(expected coordinate names of the model)" in message
    assert not results.exists()
