"""Where the full-body gait case's inputs live in the shared data, and its names.

The case is the UF subject-3 tutorial's gait trial ``gait_1`` (0.5-1.6 s, 101 frames, one
stride on a treadmill at 1.4 m/s): IK, ID and two force plates (plate 1 under the left
foot, plate 2 under the right foot) from the GCP tutorial's ``preprocessed`` folder, its
skeleton ``bodyModel.osim`` (two-segment feet), the 86 leg muscles of the JMP tutorial's
``UF_Subject_3_Scaled.osim`` (same subject, same muscle paths) and the NCP tutorial's
right-leg synergies. :func:`shared_inputs` checks the files exist and names the missing one.
"""

from __future__ import annotations

import os
from pathlib import Path

import attrs

from nmsm.errors import InputError

TRIAL = "gait_1"
SIDES = ("r", "l")
#: leg coordinates spanned by the leg muscles, per side (the surrogate's 14 coordinates)
LEG_COORDINATES = ("hip_flexion", "hip_adduction", "hip_rotation", "knee_angle", "ankle_angle",
                   "subtalar_angle", "mtp_angle")
PELVIS = ("pelvis_tilt", "pelvis_list", "pelvis_rotation", "pelvis_tx", "pelvis_ty", "pelvis_tz")
LUMBAR = ("lumbar_extension", "lumbar_bending", "lumbar_rotation")
ARM_COORDINATES = ("arm_flex", "arm_add", "arm_rot", "elbow_flex")
#: the model's ForceSet groups of each leg's 43 muscles (synergy groups of the stress case)
LEG_GROUPS = {"r": "right_leg", "l": "left_leg"}
#: the NCP tutorial's synergy group (9 right-leg muscles, 4 synergies; the combined case)
NCP_TUTORIAL_GROUP = "RightLeg"


def leg_coordinates(side: str) -> tuple[str, ...]:
    """The 7 muscle-driven coordinates of one leg (``side`` 'r' or 'l')."""
    return tuple(f"{c}_{side}" for c in LEG_COORDINATES)


def muscle_coordinates() -> tuple[str, ...]:
    """The 14 coordinates the 86 leg muscles span, right leg first."""
    return leg_coordinates("r") + leg_coordinates("l")


def arm_coordinates() -> tuple[str, ...]:
    return tuple(f"{c}_{s}" for s in SIDES for c in ARM_COORDINATES)


def state_coordinates() -> tuple[str, ...]:
    """The 31 unlocked independent coordinates (pelvis, legs, lumbar, arms): the treatment
    states. The locked ones (knee adduction, forearm, wrist) and the patella couplers
    (``knee_angle_*_beta``) follow the data or their coupler."""
    return PELVIS + muscle_coordinates() + LUMBAR + arm_coordinates()


@attrs.frozen
class SharedInputs:
    """Absolute paths of the shared files the case reads (never written)."""

    root: Path
    body_model: Path  #: GCP tutorial skeleton (9 MTP muscles), matches the IK/ID/GRF
    muscle_model: Path  #: JMP tutorial scaled model: 86 muscles, same paths and frames of the muscles
    preprocessed: Path  #: GCP tutorial IKData, IDData, GRFData (two plates) of gait_1
    gcp_settings: Path  #: GCP tutorial's right-foot settings (V4: three tasks)
    ncp_folder: Path  #: NCP tutorial folder (model, NCPResultsV3, preprocessed MAData)

    @property
    def ik(self) -> Path:
        return self.preprocessed / "IKData" / f"{TRIAL}.sto"

    @property
    def id(self) -> Path:
        return self.preprocessed / "IDData" / f"{TRIAL}.sto"

    @property
    def grf(self) -> Path:
        return self.preprocessed / "GRFData" / f"{TRIAL}.sto"

    @property
    def gcp_result(self) -> Path:
        """The original's GCP result of the right foot (tutorial V4), for quick cases."""
        return self.gcp_settings.parent / "GCPResultsV4" / "bodyModel_gcp.osimx"

    @property
    def ncp_model(self) -> Path:
        return self.ncp_folder / "UF_Subject_3_reduced_muscles.osim"

    @property
    def ncp_results(self) -> Path:
        return self.ncp_folder / "CompletedSettingsFiles" / "NCPResultsV3"

    @property
    def ncp_osimx(self) -> Path:
        return self.ncp_results / "UF_Subject_3_reduced_muscles_mtp_ncp.osimx"


def default_root() -> Path:
    """``$NMSM_SHARED_DATA`` or ``/work/shared/data``."""
    return Path(os.environ.get("NMSM_SHARED_DATA", "/work/shared/data"))


def shared_inputs(root: str | os.PathLike[str] | None = None) -> SharedInputs:
    """The case's inputs under ``root`` (default :func:`default_root`); ``InputError`` naming
    the first missing file."""
    root = Path(root) if root is not None else default_root()
    gcp = root / "gcp" / "uf_subject3_tutorial"
    inputs = SharedInputs(
        root=root,
        body_model=gcp / "bodyModel.osim",
        muscle_model=root / "jmp" / "uf_subject3_tutorial" / "CompletedSettingsFiles" / "UF_Subject_3_Scaled.osim",
        preprocessed=gcp / "preprocessed",
        gcp_settings=gcp / "CompletedSettingsFiles" / "GCPSettingsV4.xml",
        ncp_folder=root / "ncp" / "uf_subject3_tutorial",
    )
    for path in (inputs.body_model, inputs.muscle_model, inputs.ik, inputs.id, inputs.grf, inputs.gcp_settings,
                 inputs.gcp_result,
                 inputs.ncp_model, inputs.ncp_osimx, inputs.ncp_results / "synergyWeights.sto"):
        if not path.is_file():
            raise InputError(f"{path} does not exist", element="shared data",
                             expected="the shared data folder (set NMSM_SHARED_DATA)")
    return inputs
