"""From NCP settings to :class:`NcpInputs`: model, synergy groups, trials, MTP results.

Reads (docs/ncp.md):

* the model (muscles crossing ``coordinate_list``; ForceSet groups for synergy groups,
  activation groups and normalized-fiber-length groups);
* per trial ``IDData/<trial>.sto`` and ``MAData/<trial>/`` (lengths, velocities, moment
  arms), through MTP's reader;
* with ``mtp_results_directory``: ``muscleActivations/<trial>*.sto``, and muscle
  parameters from ``input_osimx_file`` (absolute l_o, l_ts, F0 of its RCNLMuscle entries).

Tracked coordinates are those of ``coordinate_list`` with an ID column (the others still
select muscles; a warning names them).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.core.term import Term
from nmsm.core.registry import build_terms
from nmsm.errors import InputError
from nmsm.io.osimx import OsimxModel, check_muscles_in_model, read_osimx
from nmsm.io.settings.ncp import NeuralControlPersonalizationSettings
from nmsm.io.storage import Table, read_storage
from nmsm.io.trials import find_trial_file
from nmsm.model import load_model
from nmsm.model.components import Model
from nmsm.tools.mtp.data import check_same_times, find_prefixes, load_trial
from nmsm.tools.mtp.muscles import MuscleParameters, resolve_groups
from nmsm.tools.ncp.inputs import NcpInputs, NcpTrial
from nmsm.tools.ncp.muscle_set import muscles_crossing, synergy_groups
from nmsm.tools.ncp.spline import DEFAULT_NODE_COUNT
from nmsm.tools.ncp.symmetry import mirror_muscle_map
from nmsm.tools.ncp.synergies import SynergyLayout
from nmsm.tools.ncp.vaf import non_negative


@attrs.frozen(eq=False)
class NcpSetup:
    """Everything a run needs: the arrays, the terms, and where they came from.

    ``mtp_activation_files`` per trial (None without MTP results); ``osimx`` the input
    ``.osimx`` (None if not given).
    """

    settings: NeuralControlPersonalizationSettings
    model: Model
    inputs: NcpInputs
    terms: tuple[Term, ...]
    osimx: OsimxModel | None
    mtp_activation_files: tuple[Path, ...] | None
    dropped_coordinates: tuple[str, ...] = ()
    osimx_file: Path | None = None
    #: muscles whose parameters MTLI replaced (those without MTP activations), and whether F0 was updated
    mtli_muscles: tuple[str, ...] = ()
    mtli_updated_force: bool = False


def tracked_coordinates(settings: NeuralControlPersonalizationSettings, prefix: str) -> tuple[list[str], list[str]]:
    """``coordinate_list`` entries with an ID column in trial ``prefix`` (and those without)."""
    table = read_storage(find_trial_file(Path(settings.data_directory) / "IDData", prefix))
    labels = set(table.labels)
    kept, dropped = [], []
    for c in settings.coordinate_list:
        (kept if {c, c + "_moment", c + "_force"} & labels else dropped).append(c)
    if not kept:
        raise InputError(
            "no coordinate of <coordinate_list> has a column in the inverse-dynamics file",
            file=table.source,
            element="<coordinate_list>",
            expected="ID columns named <coordinate>, <coordinate>_moment or <coordinate>_force",
        )
    return kept, dropped


#: 2023 ``.osimx`` children (inside ``<MTPMuscleSet>``) holding MTP's length scale factors
_OLD_SCALE_FACTORS = {
    "optimal_fiber_length_scale_factor": "optimal_fiber_length",
    "slack_tendon_length_scale_factor": "tendon_slack_length",
    "tendon_slack_length_scale_factor": "tendon_slack_length",
}


def _old_scale_factors(extra: Sequence[str]) -> dict[str, float]:
    """``{field: factor}`` from a 2023 RCNLMuscle's unknown children (``*_scale_factor``)."""
    from lxml import etree

    from nmsm.io.xml_input import xml_parser

    out = {}
    for item in extra:
        element = etree.fromstring(item, xml_parser())
        field = _OLD_SCALE_FACTORS.get(element.tag)
        if field is not None and (element.text or "").strip():
            out[field] = float(element.text)
    return out


def _muscle_parameters(model: Model, muscles: Sequence[str], osimx: OsimxModel | None) -> MuscleParameters:
    """Model parameters of ``muscles``, replaced by the osimx's values where given.

    Current ``.osimx`` files hold absolute l_o, l_ts, F0; 2023 files hold l_o and l_ts scale
    factors (``optimal_fiber_length_scale_factor``, ``slack_tendon_length_scale_factor``), applied
    to the model's values here. Every ``RCNLMuscle`` must be a muscle of the model
    (``InputError`` otherwise).
    """
    if osimx is not None:
        check_muscles_in_model(osimx, model.muscle_names, model_file=model.file)
    f0, lo, lts, alpha = [], [], [], []
    scaled = 0
    for name in muscles:
        m = model.muscle(name)
        personal = osimx.muscles.get(name) if osimx is not None else None
        values = {
            "max_isometric_force": m.max_isometric_force,
            "optimal_fiber_length": m.optimal_fiber_length,
            "tendon_slack_length": m.tendon_slack_length,
        }
        if personal is not None:
            for field, factor in _old_scale_factors(personal.extra).items():
                if getattr(personal, field) is None:
                    values[field] = values[field] * factor
                    scaled += 1
            for field in values:
                if getattr(personal, field) is not None:
                    values[field] = getattr(personal, field)
        f0.append(values["max_isometric_force"])
        lo.append(values["optimal_fiber_length"])
        lts.append(values["tendon_slack_length"])
        alpha.append(m.pennation_angle_at_optimal)
    if scaled:
        warnings.warn(
            f"{scaled} 2023-style length scale factor(s) of the .osimx applied to the model's "
            "optimal fiber / tendon slack lengths",
            stacklevel=3,
        )
    return MuscleParameters(muscles, f0, lo, lts, alpha)


def _osimx_file(settings: NeuralControlPersonalizationSettings) -> Path | None:
    """``input_osimx_file``; when empty, the single ``.osimx`` of ``mtp_results_directory`` (2023 layout)."""
    if settings.input_osimx_file:
        return Path(settings.input_osimx_file)
    if settings.mtp_results_directory is None:
        return None
    found = sorted(Path(settings.mtp_results_directory).glob("*.osimx"))
    if len(found) == 1:
        warnings.warn(
            f"{settings.settings_file}: <input_osimx_file> is empty; using the MTP results' {found[0].name} "
            "for the MTP muscle parameters (as the 2023 NCP read <mtp_results_directory>/model.osimx)",
            stacklevel=3,
        )
        return found[0]
    return None


def _mtp_activations(
    directory: Path, prefixes: Sequence[str], muscles: Sequence[str], frames: Sequence[int],
    id_times: Sequence[Table] | None = None,
) -> tuple[tuple[str, ...], list[np.ndarray], list[Path]]:
    """MTP activations of the NCP muscles present in every trial's file.

    A muscle present in one trial's file and absent from another's is an error naming the
    file and column; so is a file whose row count differs from the trial's ID rows, or whose
    times differ from them (``id_times``: each trial's ID times; rows are paired by position).
    Activations below -0.01 are an error, slightly negative ones are set to 0 (as ``nmsm vaf``:
    :func:`nmsm.tools.ncp.vaf.non_negative`).
    """
    folder = directory / "muscleActivations"
    tables, files = [], []
    for prefix in prefixes:
        path = find_trial_file(folder, prefix)
        tables.append(read_storage(path))
        files.append(path)
    present = [set(t.labels) for t in tables]
    union = [m for m in muscles if any(m in p for p in present)]
    for table, labels in zip(tables, present):
        missing = [m for m in union if m not in labels]
        if missing:
            raise InputError(
                f"MTP activations lack muscle(s) {', '.join(missing)} that other trials' MTP activations have",
                file=table.source,
                element=f"column '{missing[0]}'",
                expected="the same muscles in every trial's muscleActivations file",
            )
    for table, n, prefix in zip(tables, frames, prefixes):
        if table.n_rows != n:
            raise InputError(
                f"MTP activations of trial '{prefix}' have {table.n_rows} rows but its ID/MA data have {n}",
                file=table.source,
                expected=f"{n} rows (MTP output of the same trial)",
            )
    for table, prefix, reference in zip(tables, prefixes, id_times or [None] * len(tables)):
        if reference is not None:
            check_same_times(reference, table, prefix)
    arrays = [non_negative(t.columns(union), union, t.time, t.source, t.label_line) for t in tables]
    return tuple(union), arrays, files


def load_ncp(
    settings: NeuralControlPersonalizationSettings,
    *,
    enforce_bilateral_symmetry: bool | None = None,
    n_nodes: int = DEFAULT_NODE_COUNT,
) -> NcpSetup:
    """Read everything NCP needs (see module docstring); ``enforce_bilateral_symmetry`` overrides the setting."""
    settings_file = settings.settings_file
    model = load_model(settings.input_model_file)
    crossing = muscles_crossing(model, settings.coordinate_list, settings_file=settings_file)
    requested = [(g.muscle_group_name, g.num_synergies) for g in settings.synergy_groups]
    groups = synergy_groups(model, requested, crossing, settings_file=settings_file)
    symmetric = settings.enforce_bilateral_symmetry if enforce_bilateral_symmetry is None else enforce_bilateral_symmetry
    shared = None
    if symmetric:
        if len(groups) != 2:
            raise InputError(
                f"bilateral symmetry needs exactly two synergy groups, found {len(groups)}",
                file=settings_file,
                element="<enforce_bilateral_symmetry>",
                expected="two <RCNLSynergy> elements (left and right)",
            )
        if groups[0].n_synergies != groups[1].n_synergies or groups[0].n_muscles != groups[1].n_muscles:
            raise InputError(
                f"bilateral symmetry needs groups of equal size: '{groups[0].name}' has {groups[0].n_muscles} muscles "
                f"and {groups[0].n_synergies} synergies, '{groups[1].name}' {groups[1].n_muscles} and {groups[1].n_synergies}",
                file=settings_file,
                element="<enforce_bilateral_symmetry>",
                expected="mirror-image synergy groups",
            )
        shared = (None, (0, mirror_muscle_map(groups[0].muscles, groups[1].muscles)))
    layout = SynergyLayout(groups, n_nodes=n_nodes, shared_from=shared)
    muscles = layout.muscles
    prefixes = find_prefixes(settings.data_directory, settings.trial_prefixes)
    coordinates, dropped = tracked_coordinates(settings, prefixes[0])
    if dropped:
        warnings.warn(
            f"{settings_file}: coordinate(s) {', '.join(dropped)} of <coordinate_list> have no inverse-dynamics "
            "column; they select muscles but their moments are not tracked",
            stacklevel=2,
        )
    raw = [load_trial(settings.data_directory, p, coordinates, muscles) for p in prefixes]
    osimx_path = _osimx_file(settings)
    osimx = read_osimx(osimx_path) if osimx_path is not None else None
    mtp_muscles: tuple[str, ...] = ()
    mtp_data: list[np.ndarray | None] = [None] * len(raw)
    files = None
    if settings.mtp_results_directory is not None:
        mtp_muscles, arrays, paths = _mtp_activations(
            Path(settings.mtp_results_directory), prefixes, muscles, [t.n_frames for t in raw],
            [Table(time=t.time, labels=(), data=np.zeros((t.n_frames, 0)),
                   source=find_trial_file(Path(settings.data_directory) / "IDData", t.name)) for t in raw],
        )
        mtp_data = list(arrays)
        files = tuple(paths)
        if osimx is None:
            warnings.warn(
                f"{settings_file}: MTP activations are tracked but <input_osimx_file> is empty: the model's "
                "muscle parameters are used, not MTP's",
                stacklevel=2,
            )
    id_labels = _load_labels(settings, prefixes[0], coordinates)
    trials = [
        NcpTrial(
            name=t.name,
            time=t.time,
            lengths=t.muscle_tendon_length,
            velocities=t.muscle_tendon_velocity,
            moment_arms=t.moment_arms,
            moments=t.inverse_dynamics_moments,
            mtp_activations=a if mtp_muscles else None,
            load_labels=id_labels,
        )
        for t, a in zip(raw, mtp_data)
    ]
    parameters = _muscle_parameters(model, muscles, osimx)
    activation_groups = resolve_groups(
        settings.activation_muscle_groups, model.groups, muscles, setting="activation_muscle_groups",
        model_file=str(settings.input_model_file),
        settings_file=str(settings.settings_file),
    )
    fiber_groups = resolve_groups(
        settings.normalized_fiber_length_muscle_groups, model.groups, muscles,
        setting="normalized_fiber_length_muscle_groups", model_file=str(settings.input_model_file),
        settings_file=str(settings.settings_file),
    )
    inputs = NcpInputs(
        layout=layout,
        coordinates=coordinates,
        trials=trials,
        muscles=parameters,
        mtp_muscles=mtp_muscles,
        activation_groups=activation_groups,
        fiber_length_groups=fiber_groups,
        v_max_factor=settings.v_max_factor,
    )
    terms = tuple(build_terms(list(settings.cost_terms), "NCP"))
    mtli_muscles: tuple[str, ...] = ()
    mtli = settings.muscle_tendon_length_initialization
    if mtli.is_enabled:
        inputs, mtli_muscles = _initialize_lengths(settings, inputs)
    return NcpSetup(
        settings, model, inputs, terms, osimx, files, tuple(dropped), osimx_path,
        mtli_muscles=mtli_muscles, mtli_updated_force=bool(mtli_muscles) and mtli.optimize_isometric_max_force,
    )


def _passive_coordinates(directory: Path, coordinates: Sequence[str]) -> list[str]:
    """Tracked coordinates with a column in the first passive trial's ID file."""
    prefix = find_prefixes(directory)[0]
    labels = set(read_storage(find_trial_file(directory / "IDData", prefix)).labels)
    return [c for c in coordinates if {c, c + "_moment", c + "_force"} & labels]


def _initialize_lengths(settings: NeuralControlPersonalizationSettings, inputs: NcpInputs) -> tuple[NcpInputs, tuple[str, ...]]:
    """Run MTLI (docs/mtp.md) on the NCP muscles; keep its l_o, l_ts (F0) for muscles without MTP activations."""
    from nmsm.tools.mtp.mtli import MtliOptions, load_passive_trials, run_mtli

    mtli = settings.muscle_tendon_length_initialization
    muscles = inputs.layout.muscles
    passive = ()
    if mtli.passive_data_input_directory is not None:
        directory = Path(mtli.passive_data_input_directory)
        passive = load_passive_trials(directory, _passive_coordinates(directory, inputs.coordinates), muscles)
    options = MtliOptions(
        max_normalized_fiber_length=mtli.max_normalized_muscle_fiber_length or 1.0,
        min_normalized_fiber_length=mtli.min_normalized_muscle_fiber_length or 0.6,
        optimize_maximum_muscle_stress=bool(mtli.optimize_maximum_muscle_stress),
        update_max_isometric_force=mtli.optimize_isometric_max_force,
        absolute_lengths=mtli.optimize_absolute_length_changes,
        maximum_muscle_stress=mtli.maximum_muscle_stress,
    )
    terms = build_terms(list(mtli.cost_terms), "MTLI")
    result = run_mtli(inputs.muscles, [t.lengths for t in inputs.trials], passive, inputs.fiber_length_groups, terms, options)
    replace = np.array([i not in set(inputs.mtp_indices) for i in range(len(muscles))])
    current, fitted = inputs.muscles, result.muscles
    updated = attrs.evolve(
        current,
        optimal_fiber_length=np.where(replace, fitted.optimal_fiber_length, current.optimal_fiber_length),
        tendon_slack_length=np.where(replace, fitted.tendon_slack_length, current.tendon_slack_length),
        max_isometric_force=np.where(replace, fitted.max_isometric_force, current.max_isometric_force),
    )
    return attrs.evolve(inputs, muscles=updated), tuple(m for m, r in zip(muscles, replace) if r)


def _load_labels(settings: NeuralControlPersonalizationSettings, prefix: str, coordinates: Sequence[str]) -> tuple[str, ...]:
    """ID column label of each tracked coordinate (``<c>_moment``, ``<c>_force`` or ``<c>``)."""
    table = read_storage(find_trial_file(Path(settings.data_directory) / "IDData", prefix))
    out = []
    for c in coordinates:
        for label in (c + "_moment", c + "_force", c):
            if table.has(label):
                out.append(label)
                break
    return tuple(out)
