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

Both write their files all or nothing (:func:`nmsm.io.output_file.staged_outputs`): the
surrogate file and the ``--write-samples`` folder together, the muscle analysis's files
together; a failure or Ctrl-C leaves the earlier files and no new ones.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from nmsm.cli_types import fraction, non_negative_float, number, positive_float, positive_int
from nmsm.errors import InputError

if TYPE_CHECKING:
    from nmsm.io.output_file import StagedOutputs


def _check_arguments(args: argparse.Namespace) -> None:
    """The argument combinations ``nmsm surrogate`` needs without a settings file."""
    if not args.model or not args.coordinates or not args.output:
        raise InputError("without a settings file, --model, --coordinates and --output are required",
                         element="nmsm surrogate", expected="SETTINGS.xml, or --model M --coordinates ... --output F")
    if bool(args.data_dir) == bool(args.motion):
        raise InputError("give exactly one of --data-dir and --motion", element="nmsm surrogate",
                         expected="a surrogate data folder or a reference motion")
    if args.write_samples and not args.motion:
        raise InputError("--write-samples keeps the poses sampled around a --motion; with --data-dir there are "
                         "none to write", element="nmsm surrogate", expected="--write-samples with --motion only")


def _check_samples_folder(args: argparse.Namespace, inputs: dict[Path, str]) -> None:
    """``--write-samples DIR``: a folder (created if its parent exists) whose files to be
    written (``IKData/<trial>.sto``, ``MAData/<trial>/``) are none of the inputs."""
    from nmsm.io.output_file import check_output_folder

    folder = check_output_folder(args.write_samples, option="--write-samples",
                                 what="a folder for the samples (IKData/, MAData/)").resolve()
    trial = Path(args.motion).stem
    written = (folder / "IKData" / f"{trial}.sto", folder / "MAData" / trial)
    for path, what in inputs.items():
        real = path.resolve()
        if real == written[0] or real.is_relative_to(written[1]):
            raise InputError(f"--write-samples would overwrite {what}", file=path,
                             expected="another --write-samples folder than the one holding the inputs")


def _check_outputs(args: argparse.Namespace, settings: Any) -> None:
    """:class:`InputError` unless the surrogate file (and ``--write-samples``) may be written:
    no input replaced, folders existing (nothing checked when the settings load an existing file)."""
    from nmsm.io.output_file import check_outputs, existing_inputs

    if settings is not None:
        option, output = ("--output", Path(args.output)) if args.output else (
            f"<surrogate_model_file_name> of {settings.settings_file}", settings.model_path)
        if settings.load and output.is_file():
            return  # load_surrogate_model: read, not written
        inputs = existing_inputs({settings.settings_file: "the settings file (SETTINGS.xml)",
                                  settings.model_file: "the model file the settings name in <input_model_file>"})
        folders = {settings.data_directory: "the surrogate data folder the settings name"}
    else:
        _check_arguments(args)
        option, output = "--output", Path(args.output)
        inputs = existing_inputs({args.model: "the --model file", args.motion: "the --motion file"})
        folders = {Path(args.data_dir): "the --data-dir folder"} if args.data_dir else {}
        if args.write_samples and args.motion:
            _check_samples_folder(args, inputs)
    check_outputs({option: output}, inputs, protected_folders=folders, example_names={option: "surrogateMuscles.json"})


def _fit(args: argparse.Namespace, staged: StagedOutputs) -> tuple[Any, Path, bool]:
    """The surrogate the arguments ask for, where it goes, and whether it is written already
    (a settings file that loads an existing surrogate). Every output is checked first;
    ``--write-samples`` is written into ``staged``."""
    import attrs

    from nmsm.io.storage import read_storage
    from nmsm.model.surrogate import fit_surrogate_model
    from nmsm.tools.surrogate.settings import read_surrogate_settings
    from nmsm.model.surrogate_fitting import fit_from_data_directory, surrogate_from_settings

    settings = read_surrogate_settings(args.settings) if args.settings else None
    _check_outputs(args, settings)
    if settings is not None:
        # the command's purpose is the file: written by _surrogate (atomically) unless loaded
        target = Path(args.output).resolve() if args.output else settings.model_path
        settings = attrs.evolve(settings, save=False, model_path=target)
        loaded = settings.load and target.is_file()
        return surrogate_from_settings(settings), target, loaded
    if args.data_dir:
        model = fit_from_data_directory(args.model, args.data_dir, args.coordinates, degree=args.degree,
                                        epsilon=args.epsilon, holdout_fraction=args.holdout, seed=args.seed,
                                        muscles=args.muscles)
        return model, Path(args.output), False
    from nmsm.tools.surrogate.sampling import opensim_samples, poses_around_motion

    motion = read_storage(args.motion)
    coords, poses = poses_around_motion(args.model, motion, angular_padding=math.radians(args.angular_padding),
                                        linear_padding=args.linear_padding, samples_per_frame=args.samples_per_frame,
                                        seed=args.seed, varied=None if args.vary_all else args.coordinates)
    from nmsm.core.console import announce

    announce("surrogate", settings=None, model=args.model, trials=[Path(args.motion).name],
             problem=f"{poses.shape[0]} poses ({args.samples_per_frame} per frame) varying {len(coords)} coordinates, "
                     f"moment arms of {len(args.coordinates)} coordinates, degree {args.degree}")
    samples = opensim_samples(args.model, coords, poses, args.coordinates, muscles=args.muscles,
                              moment_arms=args.moment_arms)
    if args.write_samples:
        _write_samples(staged.folder(args.write_samples), Path(args.motion).stem, coords, poses, samples)
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
    """``nmsm surrogate``: outputs checked, the surrogate fitted; its file and the samples
    (``--write-samples``) moved into place together."""
    from nmsm.io.output_file import staged_outputs
    from nmsm.tools.surrogate.accuracy import accuracy_report

    with staged_outputs() as staged:
        model, path, saved = _fit(args, staged)
        if not saved:
            model.save(staged.file(path))
    print(accuracy_report(model))
    print(f"surrogate of {len(model.muscles)} muscles, degree {model.degree}, written to {path}")
    return 0


def _check_analysis_folder(args: argparse.Namespace, trial: str) -> Path:
    """``-o``: a folder (created if its parent exists) whose ``<trial>/<trial>_*.sto`` files
    are none of the inputs; returns it."""
    from nmsm.io.output_file import check_output_folder, existing_inputs

    folder = check_output_folder(args.output, option="-o",
                                 what="the output folder: the files go in <output>/<trial>/")
    trial_folder = folder / trial
    if trial_folder.exists() and not trial_folder.is_dir():
        raise InputError("the trial's output folder is a file", file=trial_folder,
                         expected=f"a folder for {trial}_Length.sto, ... (or another --trial or -o)")
    inputs = existing_inputs({args.model: "the input model (MODEL)", args.motion: "the input motion (MOTION)",
                              args.surrogate: "the --surrogate file"})
    for path, what in inputs.items():
        real = path.resolve()
        if real.parent == trial_folder.resolve() and real.name.startswith(f"{trial}_") and real.suffix == ".sto":
            raise InputError(f"the output would overwrite {what}", file=path,
                             expected="another -o folder or --trial than the ones holding the inputs")
    return folder


def _muscle_analysis(args: argparse.Namespace) -> int:
    """``nmsm muscle-analysis``: the output folder checked, the geometry computed, the files
    moved into place together."""
    from nmsm.io.output_file import staged_outputs
    from nmsm.model.muscle_analysis import analyze_motion, check_trial_name
    from nmsm.model.surrogate import SurrogateModel

    trial = check_trial_name(args.trial or Path(args.motion).stem)  # before any work
    folder = _check_analysis_folder(args, trial)
    surrogate = SurrogateModel.load(args.surrogate) if args.surrogate else None
    result = analyze_motion(args.model, args.motion, muscles=args.muscles, coordinates=args.coordinates,
                            engine=args.engine, surrogate=surrogate, lowpass_hz=args.lowpass)
    with staged_outputs() as staged:
        paths = [staged.destination(p) for p in result.write(staged.folder(folder), trial)]
    counts: dict[str, int] = {}
    for source in result.sources.values():
        counts[source] = counts.get(source, 0) + 1
    how = ", ".join(f"{n} by {s}" for s, n in sorted(counts.items()))
    print(f"{len(result.muscles)} muscles ({how}), {len(result.time)} frames: {len(paths)} files in {folder / trial}")
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
    p.add_argument("--degree", type=number(0, integer=True, name="degree"), default=5,
                   help="polynomial degree (>= 0, default 5)")
    p.add_argument("--epsilon", type=non_negative_float, default=1e-4,
                   help="moment arm (m, >= 0) above which a coordinate counts (1e-4)")
    p.add_argument("--holdout", type=fraction, default=0.2,
                   help="share of poses held out to measure accuracy (in [0, 1), default 0.2)")
    p.add_argument("--seed", type=int, default=0, help="random seed for sampling and the hold-out split")
    p.add_argument("--samples-per-frame", type=positive_int, default=25,
                   help="Latin-hypercube poses per motion frame (>= 1, default 25)")
    p.add_argument("--angular-padding", type=non_negative_float, default=10.0,
                   help="sampling half-width of rotations, degrees (>= 0, default 10)")
    p.add_argument("--linear-padding", type=non_negative_float, default=0.0,
                   help="sampling half-width of translations, m (>= 0, default 0)")
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
    p.add_argument("--lowpass", type=positive_float, default=None,
                   help="low-pass cut-off (Hz, > 0) for the coordinates, as OpenSim's AnalyzeTool (default: none)")
    p.set_defaults(func=_muscle_analysis)
