"""Muscle-tendon length initialization inside NCP: only muscles without MTP activations take its lengths."""

from __future__ import annotations

import numpy as np
import pytest
from lxml import etree

from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case
from nmsm.io.osimx import read_osimx
from nmsm.tools.ncp.loading import load_ncp
from nmsm.tools.ncp.run import read_settings, run_settings

MTLI_TERMS = (
    ("optimal_muscle_fiber_length", "0.3", "1"),
    ("tendon_slack_length", "1", "1"),
    ("minimum_normalized_muscle_fiber_length", "0.3", None),
    ("maximum_normalized_muscle_fiber_length", "0.03", None),
)


@pytest.fixture
def case(tmp_path):
    case = make_synthetic_ncp_case(tmp_path, n_trials=1, n_points=51)
    tree = etree.parse(str(case.settings_file))
    mtli = tree.getroot().find("NeuralControlPersonalizationTool/MuscleTendonLengthInitialization")
    mtli.find("is_enabled").text = "true"
    for tag, text in (("max_normalized_muscle_fiber_length", "1.0"), ("min_normalized_muscle_fiber_length", "0.95"),
                      ("optimize_maximum_muscle_stress", "false")):
        etree.SubElement(mtli, tag).text = text
    terms = etree.SubElement(mtli, "RCNLCostTermSet")
    for kind, error, center in MTLI_TERMS:
        term = etree.SubElement(terms, "RCNLCostTerm")
        etree.SubElement(term, "is_enabled").text = "true"
        etree.SubElement(term, "type").text = kind
        etree.SubElement(term, "max_allowable_error").text = error
        if center is not None:
            etree.SubElement(term, "error_center").text = center
    tree.write(str(case.settings_file))
    return case


def test_mtli_updates_only_muscles_without_mtp_activations(case) -> None:
    setup = load_ncp(read_settings(case.settings_file))
    untracked = {"iliacus_r", "soleus_r", "iliacus_l", "soleus_l"}
    assert set(setup.mtli_muscles) == untracked and setup.mtli_updated_force
    names = setup.inputs.muscles.names
    personal = read_osimx(case.osimx_file).muscles
    changed = {n for i, n in enumerate(names)
               if not np.isclose(setup.inputs.muscles.optimal_fiber_length[i], personal[n].optimal_fiber_length, rtol=1e-9)}
    assert changed and changed <= untracked  # the synthetic lengths exceed the 1.0 maximum: MTLI must move some


def test_mtli_lengths_are_written_to_the_osimx(case) -> None:
    run = run_settings(case.settings_file, print_level=0)
    osimx = read_osimx(run.osimx_file)
    i = run.setup.inputs.muscles.names.index("soleus_r")
    assert osimx.muscles["soleus_r"].optimal_fiber_length == pytest.approx(run.setup.inputs.muscles.optimal_fiber_length[i])
    assert osimx.muscles["soleus_r"].max_isometric_force == pytest.approx(run.setup.inputs.muscles.max_isometric_force[i])
    assert osimx.muscles["vasti_r"].max_isometric_force == read_osimx(case.osimx_file).muscles["vasti_r"].max_isometric_force
    assert "length initialization updated" in (run.results_directory / "commandWindowOutput.txt").read_text()
