"""The full-body gait case: ``python -m nmsm.examples.fullbody write DIR --case stress --mesh full``.

Writes into ``DIR`` (reading the shared data at run time, never copying it into the
repository) the prepared inputs of :mod:`nmsm.examples.fullbody_prepare` and, in
``DIR/<case>_<mesh>/``, the ``TOSettings.xml``, ``VOSettings.xml``, ``DOSettings.xml`` and
solver files of :mod:`nmsm.examples.fullbody_settings`; prints the TO settings path. Run
them in order with ``nmsm run``: each tool's results go to ``DIR/<case>_<mesh>/results/<tool>``
and the next tool reads them.

``--quick`` (tests): no GCP runs (the GCP tutorial's right foot and its mirror image) and
fewer surrogate samples; settings in ``DIR/<case>_<mesh>_quick/``.

Cases: ``stress`` (86 muscles synergy-driven, 5 + 5 synergies from an NCP of
static-optimization activations: synthetic) and ``combined`` (the NCP tutorial's right-leg
synergies, torques elsewhere). Meshes: ``full`` (25 intervals x 4 points) and ``coarse``
(5 x 4).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from nmsm.examples import fullbody_data as fd
from nmsm.examples import fullbody_prepare as fp
from nmsm.examples.fullbody_settings import MESHES, CaseFolders, Controllers, write_treatment_settings

CASES = ("stress", "combined")


def _mirror(muscle: str) -> str:
    return muscle[:-2] + ("_l" if muscle.endswith("_r") else "_r")


def synergy_pairs(ncp_results: Path) -> tuple[tuple[str, str], ...]:
    """Each right-leg synergy paired with the left-leg synergy whose vector is most alike
    (cosine of the mirrored weights; one-to-one, ``scipy.optimize.linear_sum_assignment``)."""
    from scipy.optimize import linear_sum_assignment

    from nmsm.io.storage import read_storage

    weights = read_storage(ncp_results / "synergyWeights.sto")
    commands = read_storage(next(ncp_results.glob("*_synergyCommands.sto")))
    names = list(commands.labels)
    right = [k for k, n in enumerate(names) if n.startswith(fd.LEG_GROUPS["r"])]
    left = [k for k, n in enumerate(names) if n.startswith(fd.LEG_GROUPS["l"])]
    right_muscles = [m for m in weights.labels if m.endswith("_r")]
    W_r = weights.data[np.ix_(right, [weights.labels.index(m) for m in right_muscles])]
    W_l = weights.data[np.ix_(left, [weights.labels.index(_mirror(m)) for m in right_muscles])]
    unit = lambda W: W / np.maximum(np.linalg.norm(W, axis=1, keepdims=True), 1e-12)  # noqa: E731
    rows, cols = linear_sum_assignment(-(unit(W_r) @ unit(W_l).T))
    return tuple((names[right[i]], names[left[j]]) for i, j in zip(rows, cols))


def _suffix(quick: bool) -> str:
    return "_quick" if quick else ""


def stress_case(folder: Path, shared: fd.SharedInputs,
                quick: bool = False) -> tuple[Controllers, fp.Prepared, Path, Path, Path]:
    prepared = fp.Prepared(folder)
    fp.prepare_model(shared, prepared)
    fp.prepare_data(shared, prepared)
    feet = fp.prepare_contact(shared, prepared, quick)
    ncp = fp.prepare_stress_synergies(prepared)
    surrogate = fp.prepare_surrogate(prepared, "surrogate_stress" + _suffix(quick), prepared.model,
                                     fd.muscle_coordinates(),
                                     samples_per_frame=fp.QUICK_SAMPLES_PER_FRAME if quick else None)
    osimx = fp.merged_osimx(prepared, "stress" + _suffix(quick), next(ncp.glob("*.osimx")), feet)
    from nmsm.model import load_model

    pairs = synergy_pairs(ncp)
    controllers = Controllers(
        name="stress", synergy_names=tuple(n for p in pairs for n in p),
        surrogate_coordinates=fd.muscle_coordinates(), torque_coordinates=fd.LUMBAR + fd.arm_coordinates(),
        muscles=tuple(load_model(prepared.model).muscle_names), optimize_vectors=True,
        max_synergy_activation=fp.max_synergy_activation(ncp), pairs=pairs, paretic=pairs[0][0])
    return controllers, prepared, osimx, ncp, surrogate


def combined_case(folder: Path, shared: fd.SharedInputs,
                  quick: bool = False) -> tuple[Controllers, fp.Prepared, Path, Path, Path]:
    prepared = fp.Prepared(folder)
    fp.prepare_model(shared, prepared)
    fp.prepare_data(shared, prepared)
    feet = fp.prepare_contact(shared, prepared, quick)
    surrogate = fp.prepare_surrogate(prepared, "surrogate_combined" + _suffix(quick), shared.ncp_model,
                                     fp.COMBINED_SURROGATE,
                                     samples_per_frame=fp.QUICK_SAMPLES_PER_FRAME if quick else None)
    osimx = fp.merged_osimx(prepared, "combined" + _suffix(quick), shared.ncp_osimx, feet)
    from nmsm.io.osimx import read_osimx

    synergies = read_osimx(shared.ncp_osimx).synergies
    names = tuple(f"{s.muscle_group_name}_{k}" for s in synergies for k in range(1, s.num_synergies + 1))
    ncp_coordinates = ("hip_flexion_r", "knee_angle_r", "ankle_angle_r")
    torques = tuple(c for c in fd.state_coordinates() if c not in fd.PELVIS and c not in ncp_coordinates)
    from nmsm.model import load_model

    controllers = Controllers(
        name="combined", synergy_names=names, surrogate_coordinates=fp.COMBINED_SURROGATE, torque_coordinates=torques,
        muscles=tuple(load_model(shared.ncp_model).muscle_names), optimize_vectors=False,
        max_synergy_activation=fp.max_synergy_activation(shared.ncp_results),
        pairs=((names[0], names[-1]),), paretic=names[0])
    return controllers, prepared, osimx, shared.ncp_results, surrogate


def write_case(folder: str | os.PathLike[str], case: str = "stress", mesh: str = "full",
               shared_root: str | os.PathLike[str] | None = None, *, quick: bool = False) -> dict[str, Path]:
    """Prepare ``folder`` and write the case's settings into ``folder/<case>_<mesh>[_quick]``;
    the settings paths by tool. ``quick``: :mod:`nmsm.examples.fullbody_prepare`'s quick
    preparation (mirrored tutorial contact, fewer surrogate samples; for tests)."""
    if case not in CASES:
        raise ValueError(f"case must be one of {CASES}, got '{case}'")
    if mesh not in MESHES:
        raise ValueError(f"mesh must be one of {tuple(MESHES)}, got '{mesh}'")
    folder = Path(folder).resolve()
    folder.mkdir(parents=True, exist_ok=True)
    shared = fd.shared_inputs(shared_root)
    build = stress_case if case == "stress" else combined_case
    controllers, prepared, osimx, guess, surrogate = build(folder, shared, quick)
    settings = folder / f"{case}_{mesh}{_suffix(quick)}"
    model = prepared.model if case == "stress" else shared.ncp_model
    folders = CaseFolders(settings=settings, model=model, osimx=osimx, tracked=prepared.data, guess=guess,
                          surrogate=surrogate, results=settings / "results")
    return write_treatment_settings(controllers, folders, mesh)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m nmsm.examples.fullbody", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    write = sub.add_parser("write", help="prepare a case folder and write its TO/VO/DO settings")
    write.add_argument("folder", help="case folder (created; prepared inputs are reused when present)")
    write.add_argument("--case", choices=CASES, default="stress")
    write.add_argument("--mesh", choices=tuple(MESHES), default="full")
    write.add_argument("--shared", default=None,
                       help="shared data folder (default $NMSM_SHARED_DATA or /work/shared/data)")
    write.add_argument("--quick", action="store_true",
                       help="no GCP runs (the tutorial's right foot and its mirror) and fewer surrogate samples")
    args = parser.parse_args(argv)
    paths = write_case(args.folder, args.case, args.mesh, args.shared, quick=args.quick)
    for tool, path in paths.items():
        print(f"{tool.upper()}: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
