"""A name listed twice in a settings list is an InputError at its line (it used to count twice:
MTP/NCP tracked a coordinate twice, a treatment term weighted a load twice, or MTP stopped with
'activations_gait_1' is declared twice' as a traceback for a repeated trial prefix)."""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.core.registry import build_terms
from nmsm.errors import InputError
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.mtp import MuscleTendonPersonalizationSettings


def _mtp(shared_data: Path, tmp_path: Path, old: str, new: str) -> Path:
    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    text = (tutorial / "CompletedSettingsFiles" / "MTPSettingsV3.xml").read_text()
    assert old in text
    path = tmp_path / "CompletedSettingsFiles" / "MTPSettings.xml"
    path.parent.mkdir()
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.shared_data
@pytest.mark.parametrize("old, new, element, name", [
    ("<coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r</coordinate_list>",
     "<coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r knee_angle_r</coordinate_list>",
     "<coordinate_list>", "'knee_angle_r'"),
    ("<data_directory>preprocessed</data_directory>",
     "<data_directory>preprocessed</data_directory><trial_prefixes>gait_1 gait_1</trial_prefixes>",
     "<trial_prefixes>", "'gait_1'"),
])
def test_repeated_name_in_a_settings_list(shared_data: Path, tmp_path: Path, old: str, new: str, element: str,
                                          name: str) -> None:
    path = _mtp(shared_data, tmp_path, old, new)
    with pytest.raises(InputError) as info:
        MuscleTendonPersonalizationSettings.from_document(read_settings_document(path, check_paths=False))
    error = info.value
    assert error.element == element and f"{name} listed more than once" in str(error) and error.line is not None


def test_repeated_name_in_a_term_list(tmp_path: Path) -> None:
    path = tmp_path / "settings.xml"
    path.write_text("""<NMSMPipelineDocument Version="1.5.0"><TrackingOptimizationTool>
 <RCNLCostTermSet>
  <RCNLCostTerm>
   <type>inverse_dynamics_load_tracking</type><is_enabled>true</is_enabled>
   <load_list>hip_flexion_r_moment knee_angle_r_moment knee_angle_r_moment</load_list>
   <max_allowable_error>50</max_allowable_error>
  </RCNLCostTerm>
 </RCNLCostTermSet>
</TrackingOptimizationTool></NMSMPipelineDocument>""")
    doc = read_settings_document(path, check_paths=False)
    with pytest.raises(InputError) as info:
        build_terms(doc.term_specs(doc.tool_element), "TO")
    error = info.value
    assert error.line == 5 and error.element == "<load_list>"
    assert "'knee_angle_r_moment' listed more than once in term 'inverse_dynamics_load_tracking'" in str(error)
