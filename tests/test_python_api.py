"""The Python API (``nmsm.run``, ``nmsm.run_pipeline``): wrong argument types name the argument."""

from __future__ import annotations

import pytest

import nmsm


@pytest.mark.parametrize("value", [None, 123, ["TO.xml"]])
def test_run_names_a_settings_file_that_is_not_a_path(value) -> None:
    with pytest.raises(TypeError, match=r"nmsm.run\(settings_file\): expected the path of a file .*, got "):
        nmsm.run(value)


def test_run_names_a_results_directory_that_is_not_a_path(tmp_path) -> None:
    with pytest.raises(TypeError, match=r"nmsm.run\(results_directory=...\): expected the path .*got int 5"):
        nmsm.run(tmp_path / "settings.xml", results_directory=5)


def test_run_pipeline_names_a_pipeline_file_that_is_not_a_path() -> None:
    with pytest.raises(TypeError, match=r"nmsm.run_pipeline\(pipeline_file\): .*got int 123"):
        nmsm.run_pipeline(123)
