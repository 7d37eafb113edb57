"""What stages hand to each other: named files and folders (*artifacts*).

=====================  =======  ==============================================================
artifact               kind     what it is
=====================  =======  ==============================================================
``model``              file     the current ``.osim`` (pipeline input, then JMP's output)
``osimx``              file     the current ``.osimx`` (MTP, NCP and GCP each extend it)
``motion_data``        folder   full-length ``IKData``, ``IDData``, ``GRFData``, ``EMGData``,
                                ``MAData`` of each trial on the current model (analysis stage)
``data_directory``     folder   trials in the personalization layout (docs/guide.md, section 2):
                                ``IKData``, ``IDData``, ``EMGData``, ``GRFData``, ``MAData``
``mtp_results``        folder   MTP's results folder (``muscleActivations/`` for NCP)
``ncp_results``        folder   NCP's results (synergy weights and commands: the synergy
                                treatment's initial guess)
``gcp_results``        folder   GCP's results folder
``surrogate_data``     folder   sampled poses (``IKData``) and their muscle analyses
                                (``MAData``) for the synergy controller's surrogate
``treatment_results``  folder   the last TO/VO/DO results folder (next one's initial guess)
=====================  =======  ==============================================================
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import attrs

#: artifact -> (file or folder, description)
ARTIFACTS: dict[str, tuple[str, str]] = {
    "model": ("file", "an OpenSim model (.osim)"),
    "osimx": ("file", "a personalized-model file (.osimx)"),
    "motion_data": ("dir", "full-length IK, ID, GRF, EMG and muscle-analysis data"),
    "data_directory": ("dir", "a data folder (IKData, IDData, EMGData, GRFData, MAData)"),
    "mtp_results": ("dir", "an MTP results folder"),
    "ncp_results": ("dir", "an NCP results folder"),
    "gcp_results": ("dir", "a GCP results folder"),
    "surrogate_data": ("dir", "a surrogate data folder (IKData, MAData)"),
    "treatment_results": ("dir", "a TO, VO or DO results folder"),
}

#: the pipeline-file input element that provides an artifact before any stage ran
INPUT_ELEMENTS: dict[str, str] = {
    "model": "input_model_file",
    "osimx": "input_osimx_file",
    "data_directory": "data_directory",
    "motion_data": "motion_data_directory",
    "surrogate_data": "surrogate_model_data_directory",
}


@attrs.frozen
class Artifact:
    """One available artifact: where it is and who made it (a stage name, or ``inputs``)."""

    name: str
    path: Path
    source: str


@attrs.define
class Artifacts:
    """The artifacts available at a point of the pipeline (latest producer wins)."""

    items: dict[str, Artifact] = attrs.field(factory=dict)

    def provide(self, name: str, path: Path, source: str) -> None:
        if name not in ARTIFACTS:
            raise KeyError(f"unknown artifact '{name}'")
        self.items[name] = Artifact(name, Path(path), source)

    def get(self, name: str) -> Artifact | None:
        return self.items.get(name)

    def __contains__(self, name: object) -> bool:
        return name in self.items

    def __iter__(self) -> Iterator[Artifact]:
        return iter(self.items.values())

    def copy(self) -> Artifacts:
        return Artifacts(dict(self.items))
