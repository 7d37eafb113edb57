"""NCP result files (docs/ncp.md) and reading them back.

Written into the results folder (normalized synergies: largest weight of each vector 1):

* ``synergyWeights.sto``: one row per synergy (time column 1..S), one column per muscle;
* ``<trial>_synergyCommands.sto``: columns ``<group>_<k>``, the trial's time;
* ``<trial>_combinedActivations.sto``: NCP activations with the muscles that have MTP
  activations replaced by MTP's;
* ``modelMoments/<trial>_modeledMomentsMtpNcpCombined.sto`` and ``_modeledMomentsNcp.sto``:
  muscle joint moments from the combined and from the NCP activations (ID labels);
* ``<osimxBase>_ncp.osimx``: the input ``.osimx`` (or a new one named after the model) with
  the synergy groups, and l_o / l_ts (F0 too when given) for every NCP muscle lacking them;
  its ``associated_osim_model`` is NCP's input model (relative to the results folder).

:func:`read_solution` reads ``synergyWeights.sto`` and the command files back into a
:class:`SynergySolution` (used to score the MATLAB original's results and by Treatment
Optimization for its initial guess).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.osimx import OsimxModel, OsimxMuscle, OsimxSynergy, write_osimx
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.io.trials import find_trial_file
from nmsm.tools.ncp.forces import moment_gains
from nmsm.tools.ncp.inputs import NcpInputs
from nmsm.tools.ncp.solution import SynergySolution
from nmsm.tools.ncp.synergies import SynergyGroup, SynergyLayout

WEIGHTS_FILE = "synergyWeights.sto"
COMMANDS_SUFFIX = "_synergyCommands.sto"
COMBINED_SUFFIX = "_combinedActivations.sto"
MOMENTS_FOLDER = "modelMoments"
COMBINED_MOMENTS_SUFFIX = "_modeledMomentsMtpNcpCombined.sto"
NCP_MOMENTS_SUFFIX = "_modeledMomentsNcp.sto"
#: machine-readable description of a run (inputs used), read by the plots
RUN_INFO_FILE = "ncpRunInfo.json"


def combined_activations(inputs: NcpInputs, solution: SynergySolution, trial: int) -> np.ndarray:
    """NCP activations (P, M) of ``trial`` with MTP activations where MTP has them."""
    a = solution.activations(trial).copy()
    mtp = inputs.trials[trial].mtp_activations
    if mtp is not None and inputs.mtp_muscles:
        a[:, list(inputs.mtp_indices)] = mtp
    return a


def write_synergy_weights(path: Path, solution: SynergySolution) -> Path:
    """``synergyWeights.sto``: rows = synergies (time 1..S), columns = muscles."""
    layout = solution.layout
    time = np.arange(1, layout.n_synergies + 1, dtype=float)
    columns = {name: solution.weights[:, i] for i, name in enumerate(layout.muscles)}
    return write_storage(path, table_from_columns(time, columns, name="synergyWeights"))


def write_trial_files(folder: Path, inputs: NcpInputs, solution: SynergySolution) -> list[Path]:
    """Commands, combined activations and model moments of every trial."""
    layout = inputs.layout
    written = []
    (folder / MOMENTS_FOLDER).mkdir(parents=True, exist_ok=True)
    for t, trial in enumerate(inputs.trials):
        commands = solution.commands[t]
        cols = {name: commands[:, s] for s, name in enumerate(layout.synergy_names)}
        written.append(write_storage(folder / f"{trial.name}{COMMANDS_SUFFIX}", table_from_columns(trial.time, cols)))
        combined = combined_activations(inputs, solution, t)
        cols = {name: combined[:, m] for m, name in enumerate(layout.muscles)}
        written.append(write_storage(folder / f"{trial.name}{COMBINED_SUFFIX}", table_from_columns(trial.time, cols)))
        gains = moment_gains(trial, inputs.muscles, inputs.v_max_factor, inputs.curves)
        labels = trial.load_labels or tuple(f"{c}_moment" for c in inputs.coordinates)
        for suffix, activations in ((COMBINED_MOMENTS_SUFFIX, combined), (NCP_MOMENTS_SUFFIX, solution.activations(t))):
            moments = gains.moments(activations)
            cols = {label: moments[:, j] for j, label in enumerate(labels)}
            written.append(write_storage(folder / MOMENTS_FOLDER / f"{trial.name}{suffix}", table_from_columns(trial.time, cols)))
    return written


def write_run_info(path: Path, setup: object) -> Path:
    """``ncpRunInfo.json``: absolute paths of the inputs and the layout, for :mod:`nmsm.plots.ncp`."""
    import json

    from nmsm.io.trials import find_trial_file as _find

    settings = setup.settings  # type: ignore[attr-defined]
    inputs: NcpInputs = setup.inputs  # type: ignore[attr-defined]
    mtp_files = setup.mtp_activation_files  # type: ignore[attr-defined]
    trials = []
    for t, trial in enumerate(inputs.trials):
        trials.append({
            "name": trial.name,
            "inverse_dynamics": str(_find(Path(settings.data_directory) / "IDData", trial.name).resolve()),
            "mtp_activations": str(Path(mtp_files[t]).resolve()) if mtp_files else None,
        })
    info = {
        "settings_file": str(Path(settings.settings_file).resolve()),
        "model_file": str(Path(settings.input_model_file).resolve()),
        "coordinates": list(inputs.coordinates),
        "load_labels": list(inputs.trials[0].load_labels) if inputs.trials else [],
        "groups": [{"name": g.name, "muscles": list(g.muscles), "synergies": g.n_synergies} for g in inputs.layout.groups],
        "mtp_muscles": list(inputs.mtp_muscles),
        "trials": trials,
    }
    path.write_text(json.dumps(info, indent=1), encoding="utf-8")
    return path


def osimx_file_name(input_osimx: Path | None, model_file: Path) -> str:
    """``<inputOsimxBase>_ncp.osimx``, or ``<modelBase>_ncp.osimx`` without an input ``.osimx``."""
    base = Path(input_osimx).stem if input_osimx else Path(model_file).stem
    return f"{base}_ncp.osimx"


def ncp_osimx(
    input_osimx: OsimxModel | None,
    model_name: str,
    associated_model: str,
    inputs: NcpInputs,
    *,
    mtli_muscles: Sequence[str] = (),
    updated_max_isometric_force: Sequence[str] = (),
) -> OsimxModel:
    """The output ``.osimx`` content (see module docstring).

    Muscle entries of the input are kept; NCP muscles lacking ``optimal_fiber_length`` /
    ``tendon_slack_length`` get the values NCP used, and so do the ``mtli_muscles`` (whose
    lengths MTLI set); ``max_isometric_force`` is written for the muscles in
    ``updated_max_isometric_force``. The synergy set lists the NCP synergy groups
    (replacing groups of the same name, keeping others).
    """
    # the model NCP used, relative to the results folder: the input's own path was relative to the
    # input .osimx's folder (or to the original tool's working folder) and breaks once copied here
    base = (attrs.evolve(input_osimx, associated_osim_model=associated_model) if input_osimx is not None
            else OsimxModel(name=model_name, associated_osim_model=associated_model))
    muscles = dict(base.muscles)
    params = inputs.muscles
    forced = set(updated_max_isometric_force)
    initialized = set(mtli_muscles)
    for i, name in enumerate(params.names):
        current = muscles.get(name, OsimxMuscle(name=name))
        changes = {}
        if current.optimal_fiber_length is None or name in initialized:
            changes["optimal_fiber_length"] = float(params.optimal_fiber_length[i])
        if current.tendon_slack_length is None or name in initialized:
            changes["tendon_slack_length"] = float(params.tendon_slack_length[i])
        if name in forced:
            changes["max_isometric_force"] = float(params.max_isometric_force[i])
        muscles[name] = attrs.evolve(current, **changes) if changes else current
    ours = {g.name for g in inputs.layout.groups}
    synergies = tuple(s for s in base.synergies if s.muscle_group_name not in ours) + tuple(
        OsimxSynergy(g.name, g.n_synergies) for g in inputs.layout.groups
    )
    return attrs.evolve(base, muscles=muscles, synergies=synergies)


def write_ncp_osimx(path: Path, osimx: OsimxModel) -> Path:
    return write_osimx(path, osimx)


def relative_model_path(model_file: Path, results_directory: Path) -> str:
    """The model path as written in ``associated_osim_model`` (relative to the results folder)."""
    try:
        return os.path.relpath(Path(model_file).resolve(), Path(results_directory).resolve())
    except ValueError:  # different drives on Windows
        return str(Path(model_file).resolve())


def layout_from_groups(
    model_groups: Mapping[str, Sequence[str]],
    synergies: Sequence[tuple[str, int]],
    muscles: Sequence[str],
    *,
    source: str | os.PathLike[str] | None = None,
) -> SynergyLayout:
    """The layout of synergy groups ``(ForceSet group, number of synergies)`` restricted to ``muscles``.

    ``muscles`` are the columns of a ``synergyWeights.sto`` (the muscles NCP modeled); each
    group keeps its ForceSet members that are among them, in group order. Used by
    Treatment Optimization with the model's groups and the ``.osimx`` RCNLSynergySet.
    """
    available = set(muscles)
    groups = []
    for name, count in synergies:
        if name not in model_groups:
            raise InputError(
                f"synergy group '{name}' is not a ForceSet group of the model",
                file=source,
                element="<RCNLSynergy>/<muscle_group_name>",
                expected="one of the model's groups: " + ", ".join(sorted(model_groups)),
            )
        members = [m for m in model_groups[name] if m in available]
        groups.append(SynergyGroup(name, members, count))
    return SynergyLayout(groups)


def read_solution(results_directory: str | os.PathLike[str], layout: SynergyLayout, trial_names: Sequence[str]) -> SynergySolution:
    """Synergies written by NCP (ours or the MATLAB original's) for ``layout`` and trials.

    ``synergyWeights.sto`` must have a column for every muscle of ``layout`` and one row per
    synergy; each ``<trial>_synergyCommands.sto`` a column ``<group>_<k>`` per synergy.
    """
    folder = Path(results_directory)
    weights_path = folder / WEIGHTS_FILE
    if not weights_path.is_file():
        raise InputError("synergy weights file not found", file=weights_path, expected="NCP's synergyWeights.sto")
    table = read_storage(weights_path)
    if table.n_rows != layout.n_synergies:
        raise InputError(
            f"{table.n_rows} synergy rows, expected {layout.n_synergies}",
            file=weights_path,
            expected=f"one row per synergy ({', '.join(layout.synergy_names)})",
        )
    weights = table.columns(list(layout.muscles))
    mask = np.zeros_like(weights, dtype=bool)
    for g in range(len(layout.groups)):
        mask[layout.synergy_slice(g), layout.muscle_slice(g)] = True
    weights = np.where(mask, weights, 0.0)
    commands = []
    for trial in trial_names:
        path = find_trial_file(folder, f"{trial}{COMMANDS_SUFFIX[:-4]}")
        commands.append(read_storage(path).columns(list(layout.synergy_names)))
    return SynergySolution(layout=layout, weights=weights, commands=commands, trial_names=trial_names)
