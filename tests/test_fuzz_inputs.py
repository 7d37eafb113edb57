"""Fuzz harness (tests/fuzz_inputs.py): seeded mutations of real shared files through every
reader, and of command lines through ``nmsm``'s parser, end in the project's error naming the
file (or argparse's usage error), or are accepted; never another exception.

The default suite runs a short budget; the slow suite at least 10 000 inputs. The figures
are in docs/developing.md. A crash found here becomes a regression test where it is fixed.
"""

from __future__ import annotations

import argparse
import random
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tests.fuzz_inputs import Tally, fuzz_file, judge_argv, mutate_argv

#: (shared file, reader name)
FILES = [
    ("jmp/toy_simple_arm/ToySettingsFile.xml", "settings"),
    ("mtp/uf_subject3_tutorial/CompletedSettingsFiles/MTPSettingsV1.xml", "settings"),
    ("ncp/uf_subject3_tutorial/CompletedSettingsFiles/NCPSettingsV1.xml", "settings"),
    ("gcp/uf_subject3_tutorial/CompletedSettingsFiles/GCPSettingsV1.xml", "settings"),
    ("treatment/torque_kick_tutorial/CompletedSettingsFiles/TorqueTOSettingsV1.xml", "settings"),
    ("treatment/torque_kick_tutorial/GpopsSettings.xml", "settings"),
    ("jmp/toy_simple_arm/simple_arm.osim", "osim"),
    ("gcp/patient3_right_foot/footModel_1.osim", "osim"),
    ("gcp/uf_subject3_tutorial/CompletedSettingsFiles/GCPResultsV1/bodyModel_gcp.osimx", "osimx"),
    ("preprocessing/uf_subject3_tutorial/PreCompleted/input_data/externalLoads.xml", "external loads"),
    ("opensim_gait10dof18musc/gait10dof18musc_subject01_walk_grf.xml", "external loads"),
    ("jmp/toy_simple_arm/simple_arm.mot", "table"),
    ("gcp/patient3_right_foot/footModelTest/grf.mot", "table"),
    ("jmp/toy_simple_arm/arm1.sto", "table"),
    ("jmp/toy_simple_arm/simple_arm.trc", "trc"),
]

TOY = "jmp/toy_simple_arm"
PIPELINE = """<?xml version="1.0" encoding="UTF-8"?>
<NMSMPipelineDocument Version="1.5.3">
  <PipelineTool>
    <results_directory>results</results_directory>
    <input_model_file>simple_arm_translated_away.osim</input_model_file>
    <StageList>
      <Stage name="jmp"><settings_file>ToySettingsFile.xml</settings_file></Stage>
    </StageList>
  </PipelineTool>
</NMSMPipelineDocument>
"""


def _written_sources(shared_data: Path, root: Path) -> list[tuple[Path, str]]:
    """Inputs written for the fuzz (the shared data has no pipeline file, and its IK setup
    files name marker files it does not hold): a pipeline file beside the toy arm's files and
    the GCP tutorial's IK setup naming the toy arm's markers."""
    folder = root / "sources" / "toy"
    folder.mkdir(parents=True)
    for entry in (shared_data / TOY).iterdir():
        (folder / entry.name).symlink_to(entry)
    (folder / "pipeline.xml").write_text(PIPELINE, encoding="utf-8")
    ik = (shared_data / "gcp/uf_subject3_tutorial/IKSettingsStaticPose.xml").read_text(encoding="utf-8")
    (folder / "IKSettings.xml").write_text(ik.replace("StaticTrial02_markers.trc", "simple_arm.trc"),
                                           encoding="utf-8")
    return [(folder / "pipeline.xml", "pipeline"), (folder / "IKSettings.xml", "IK settings")]


def _readers() -> dict[str, Callable[[Path], Any]]:
    from nmsm.io.osimx import read_osimx
    from nmsm.io.settings import read_tool_settings
    from nmsm.io.storage import read_storage
    from nmsm.io.trc import read_trc
    from nmsm.model.external_loads import read_external_loads
    from nmsm.model.osim import load_model
    from nmsm.tools.jmp.ik_settings import read_ik_settings
    from nmsm.tools.pipeline.pipeline_file import read_pipeline

    return {"settings": read_tool_settings, "osim": load_model, "osimx": read_osimx,
            "external loads": read_external_loads, "IK settings": read_ik_settings, "table": read_storage,
            "trc": read_trc, "pipeline": read_pipeline}


def command_lines() -> list[list[str]]:
    """A valid command line of every ``nmsm`` sub-command, with every option given."""
    from nmsm.cli import _commands, build_parser

    out = []
    for name, sub in _commands(build_parser()).items():
        argv = ["--progress", "5", name]
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            value = "1" if action.type is not None else "x.xml"
            if action.choices:
                value = str(list(action.choices)[0])
            if not action.option_strings:
                argv += [value] * (1 if action.nargs in (None, "?") else 1)
            elif action.nargs == 0:
                argv.append(action.option_strings[0])
            else:
                argv += [action.option_strings[0], value]
        out.append(argv)
    return out


def run_fuzz(shared_data: Path, root: Path, per_file: int, command_line_inputs: int, seed: int) -> Tally:
    tally = Tally()
    readers = _readers()
    for relative, reader in FILES:
        fuzz_file(shared_data / relative, readers[reader], root / Path(relative).stem, per_file, seed, tally)
    for source, reader in _written_sources(shared_data, root):
        fuzz_file(source, readers[reader], root / source.stem, per_file, seed, tally)
    rng = random.Random(seed)
    lines = command_lines()
    for _ in range(command_line_inputs):
        judge_argv(mutate_argv(rng.choice(lines), rng), tally)
    return tally


def _report(tally: Tally) -> str:
    shown = "\n".join(f"  {label}: {text}" for label, text in tally.crashes[:20])
    return f"{tally.text()}\n{shown}"


def test_fuzz_short(shared_data: Path, tmp_path: Path) -> None:
    tally = run_fuzz(shared_data, tmp_path, per_file=12, command_line_inputs=150, seed=1)
    print(tally.text())
    assert not tally.crashes, _report(tally)
    assert tally.clean > 0 and tally.accepted > 0


@pytest.mark.slow
def test_fuzz_ten_thousand_inputs(shared_data: Path, tmp_path: Path) -> None:
    tally = run_fuzz(shared_data, tmp_path, per_file=560, command_line_inputs=500, seed=2)
    print(tally.text())
    assert tally.inputs >= 10_000
    assert not tally.crashes, _report(tally)
