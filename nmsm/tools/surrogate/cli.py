"""``nmsm surrogate`` (Surrogate Model Creation) and ``nmsm muscle-analysis``.

Surrogate, three ways to give the samples:

* ``nmsm surrogate SETTINGS.xml`` - a TO/VO/DO settings file: its
  ``RCNLSynergyController`` names the data folder, coordinates, degree, epsilon and the
  model file (``input_model_file``); the model is written to ``--output`` or next to the
  settings file (``surrogateMuscles.json``);
* ``--model M.osim --data-dir DIR --coordinates ...`` - a surrogate data folder
  (``IKData/<trial>.sto`` + ``MAData/<trial>/*_Length.sto``, ``*_MomentArm_<coord>.sto``);
* ``--model M.osim --motion IK.sto --coordinates ...`` - Latin-hypercube poses around
  the motion's frames, geometry computed by OpenSim (``--write-samples DIR`` keeps them
  in the data-folder layout).

Muscle analysis: ``nmsm muscle-analysis MODEL MOTION --output MAData`` writes
``MAData/<trial>/<trial>_Length.sto``, ``_Velocity.sto`` and ``_MomentArm_<coord>.sto``.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from nmsm.errors import InputError


def _fit(args: argparse.Namespace) -> tuple[Any, Path, bool]:
    """The surrogate the arguments ask for, where it goes, and whether it is already there."""
    import attrs

    from nmsm.io.storage import read_storage
    from nmsm.model.surrogate import fit_surrogate_model
    from nmsm.tools.surrogate.settings import read_surrogate_settings
    from nmsm.tools.surrogate.tool import fit_from_data_directory, surrogate_from_settings

    if args.settings:
        settings = read_surrogate_settings(args.settings)
        settings = attrs.evolve(settings, save=True)  # the command's purpose is the file
        if args.output:
            settings = attrs.evolve(settings, model_path=Path(args.output).resolve())
        return surrogate_from_settings(settings), settings.model_path, True
    if not args.model or not args.coordinates or not args.output:
        raise InputError("without a settings file, --model, --coordinates and --output are required",
                         element="nmsm surrogate", expected="SETTINGS.xml, or --model M --coordinates ... --output F")
    if bool(args.data_dir) == bool(args.motion):
        raise InputError("give exactly one of --data-dir and --motion", element="nmsm surrogate",
                         expected="a surrogate data folder or a reference motion")
    if args.data_dir:
        model = fit_from_data_directory(args.model, args.data_dir, args.coordinates, degree=args.degree,
                                        epsilon=args.epsilon, holdout_fraction=args.holdout, seed=args.seed)
        return model, Path(args.output), False
    from nmsm.tools.surrogate.sampling import opensim_samples, poses_around_motion

    motion = read_storage(args.motion)
    coords, poses = poses_around_motion(args.model, motion, angular_padding=math.radians(args.angular_padding),
                                        linear_padding=args.linear_padding, samples_per_frame=args.samples_per_frame,
                                        seed=args.seed, varied=None if args.vary_all else args.coordinates)
    samples = opensim_samples(args.model, coords, poses, args.coordinates, muscles=args.muscles,
                              moment_arms=args.moment_arms)
    if args.write_samples:
        _write_samples(Path(args.write_samples), Path(args.motion).stem, coords, poses, samples)
    meta = {"model_file": str(Path(args.model).resolve()), "motion": str(Path(args.motion).resolve()),
            "samples_per_frame": args.samples_per_frame, "angular_padding_deg": args.angular_padding,
            "linear_padding_m": args.linear_padding, "moment_arms": args.moment_arms, "seed": args.seed,
            "varied": "all" if args.vary_all else list(args.coordinates)}
    model = fit_surrogate_model(samples, args.degree, args.epsilon, holdout_fraction=args.holdout, seed=args.seed,
                                metadata=meta)
    return model, Path(args.output), False


def _write_samples(folder: Path, trial: str, coords: tuple[str, ...], poses: Any, samples: Any) -> None:
    """Poses and geometry in the surrogate data-folder layout (time = k * 1 ms, as the original)."""
    import numpy as np

    from nmsm.io.storage import Table, write_storage
    from nmsm.model.muscle_analysis import MuscleAnalysisResult

    time = (np.arange(len(poses)) + 1) * 1e-3
    (folder / "IKData").mkdir(parents=True, exist_ok=True)
    write_storage(folder / "IKData" / f"{trial}.sto", Table(time=time, labels=coords, data=poses, name=trial))
    result = MuscleAnalysisResult(time, samples.muscles, samples.coordinates, samples.lengths,
                                  np.zeros_like(samples.lengths), samples.moment_arms)
    paths = result.write(folder / "MAData", trial)
    paths[1].unlink()  # no velocities for independent poses


def _surrogate(args: argparse.Namespace) -> int:
    from nmsm.tools.surrogate.tool import accuracy_report

    model, path, saved = _fit(args)
    if not saved:
        model.save(path)
    print(accuracy_report(model))
    print(f"surrogate of {len(model.muscles)} muscles, degree {model.degree}, written to {path}")
    return 0


def _muscle_analysis(args: argparse.Namespace) -> int:
    from nmsm.model.muscle_analysis import analyze_motion
    from nmsm.model.surrogate import SurrogateModel

    surrogate = SurrogateModel.load(args.surrogate) if args.surrogate else None
    result = analyze_motion(args.model, args.motion, muscles=args.muscles, coordinates=args.coordinates,
                            engine=args.engine, surrogate=surrogate, lowpass_hz=args.lowpass)
    trial = args.trial or Path(args.motion).stem
    paths = result.write(args.output, trial)
    counts: dict[str, int] = {}
    for source in result.sources.values():
        counts[source] = counts.get(source, 0) + 1
    how = ", ".join(f"{n} by {s}" for s, n in sorted(counts.items()))
    print(f"{len(result.muscles)} muscles ({how}), {len(result.time)} frames: {len(paths)} files in {Path(args.output) / trial}")
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("surrogate", help="fit polynomial surrogate muscle geometry (Surrogate Model Creation)",
                              description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("settings", nargs="?", help="TO/VO/DO settings XML with an RCNLSynergyController")
    p.add_argument("--model", help="model .osim (without a settings file)")
    p.add_argument("--data-dir", help="surrogate data folder (IKData + MAData)")
    p.add_argument("--motion", help="reference motion to sample poses around (OpenSim computes the geometry)")
    p.add_argument("--coordinates", nargs="+", help="surrogate coordinate list")
    p.add_argument("--muscles", nargs="+", help="muscles to fit (default: all)")
    p.add_argument("--degree", type=int, default=5, help="polynomial degree (default 5)")
    p.add_argument("--epsilon", type=float, default=1e-4, help="moment arm (m) above which a coordinate counts (1e-4)")
    p.add_argument("--holdout", type=float, default=0.2, help="share of poses held out to measure accuracy (0.2)")
    p.add_argument("--seed", type=int, default=0, help="random seed for sampling and the hold-out split")
    p.add_argument("--samples-per-frame", type=int, default=25, help="Latin-hypercube poses per motion frame (25)")
    p.add_argument("--angular-padding", type=float, default=10.0, help="sampling half-width of rotations, degrees (10)")
    p.add_argument("--linear-padding", type=float, default=0.0, help="sampling half-width of translations, m (0)")
    p.add_argument("--vary-all", action="store_true",
                   help="with --motion: vary every coordinate of the motion (the original), not only --coordinates")
    p.add_argument("--moment-arms", choices=["derivative", "opensim"], default="derivative",
                   help="fit -dL/dq (central differences, default) or OpenSim's computeMomentArm")
    p.add_argument("--write-samples", help="with --motion: also write the samples as a surrogate data folder")
    p.add_argument("--output", "-o", help="surrogate model file to write (.json)")
    p.set_defaults(func=_surrogate)

    p = subparsers.add_parser("muscle-analysis", help="muscle-tendon lengths, velocities and moment arms of a motion",
                              description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model", help="model .osim")
    p.add_argument("motion", help="motion (.mot/.sto, IK output)")
    p.add_argument("--output", "-o", default="MAData", help="output folder (default MAData); files go in <output>/<trial>/")
    p.add_argument("--trial", help="trial name (default: the motion file's stem)")
    p.add_argument("--muscles", nargs="+", help="muscles (default: all)")
    p.add_argument("--coordinates", nargs="+", help="moment-arm coordinates (default: all)")
    p.add_argument("--engine", choices=["auto", "nmsm", "opensim"], default="auto",
                   help="auto: exact paths, OpenSim (or --surrogate) for wrapping muscles")
    p.add_argument("--surrogate", help="surrogate model (.json) for wrapping muscles")
    p.add_argument("--lowpass", type=float, default=None,
                   help="low-pass cut-off (Hz) for the coordinates, as OpenSim's AnalyzeTool (default: none)")
    p.set_defaults(func=_muscle_analysis)
