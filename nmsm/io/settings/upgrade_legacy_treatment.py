"""Upgrade schema ``0.1.0`` Treatment Optimization settings and ``<GpopsDocument>`` solver files.

Schema 0.1.0 (toy-arm examples, 2023): controls were joint *jerks*; terms were split in
``RCNLTrackingCostTerms``, ``RCNLMinimizationCostTerms``, ``RCNLPathConstraintTerms`` and
``RCNLTerminalConstraintTerms`` with short type names; every IK coordinate was a state.
Each rule is listed in ``docs/settings-upgrade.md``.
"""

from __future__ import annotations

import difflib

from lxml import etree

from nmsm.errors import InputError
from nmsm.io.paths import resolve_path
from nmsm.io.settings.document import elements
from nmsm.io.settings.upgrader import Upgrader, child_of

#: 0.1.0 ``<type_of_controller>`` values (the original accepts only these two controllers)
CONTROLLER_TYPES = ("torque_driven", "synergy_driven")
#: 0.1.0 tracking cost types -> current
TRACKING_TYPES = {
    "coordinate": "generalized_coordinate_tracking",
    "generalized_coordinate": "generalized_coordinate_tracking",
    "inverse_dynamics_load": "inverse_dynamics_load_tracking",
    "controller": "controller_tracking",
    "marker_position": "marker_position_tracking",
    "muscle_activation": "muscle_activation_tracking",
    "external_force": "external_force_tracking",
    "external_moment": "external_moment_tracking",
}
#: 0.1.0 minimization cost types -> current (joint_jerk has none: jerk controls are gone)
MINIMIZATION_TYPES = {
    "controller": "controller_minimization",
    "muscle_activation": "muscle_activation_minimization",
    "inverse_dynamics_load": "inverse_dynamics_load_minimization",
    "joint_acceleration": "generalized_acceleration_minimization",
}
#: 0.1.0 constraint types -> current
CONSTRAINT_TYPES = {
    "torque_model_moment_consistency": "kinetic_consistency",
    "muscle_model_moment_consistency": "kinetic_consistency",
    "root_segment_residual_load": "root_segment_residual_load",
}
#: ``RCNLDesignVariableBoundsTerms`` children -> (current element, True if it goes in the controller)
BOUNDS = {
    "joint_positions_multiple": ("joint_position_range_scale_factor", False),
    "joint_velocities_multiple": ("joint_velocity_range_scale_factor", False),
    "joint_accelerations_multiple": ("joint_acceleration_range_scale_factor", False),
    "torque_controls_max": ("torque_controls_range_scale_factor", True),
    "synergy_commands_max": ("maximum_allowable_synergy_activation", True),
    "synergy_activations_max": ("maximum_allowable_synergy_activation", True),
}
#: ``GpopsDocument/GpopsSettings`` children -> current ``GpopsSettings`` children
GPOPS_NAMES = {
    "solver_type": "setup_nlp_solver",
    "linear_solver_type": "setup_nlp_linear_solver",
    "solver_tolerance": "setup_nlp_tolerance",
    "step_size": "setup_derivatives_step_size",
    "max_iterations": "setup_nlp_max_iterations",
    "derivative_approximation": "setup_derivatives_supplier",
    "derivative_order": "setup_derivatives_level",
    "derivative_dependencies": "setup_derivatives_dependencies",
    "mesh_method": "setup_mesh_method",
    "mesh_tolerance": "setup_mesh_tolerance",
    "mesh_max_iterations": "setup_mesh_max_iterations",
    "method": "setup_method",
}


def _text(element: etree._Element | None) -> str:
    return "" if element is None else (element.text or "").strip()


def upgrade(up: Upgrader) -> None:
    """0.1.0 ``<TrackingOptimizationTool>`` / ``Verification`` / ``Design`` -> current."""
    tool = next(elements(up.root), None)
    if tool is None:  # an emptied file: say so rather than fail inside the upgrade
        raise InputError(
            f"<{up.root.tag}> holds 0 elements", file=up.path, line=up.root.sourceline, element=f"<{up.root.tag}>",
            expected="one tool element: <TrackingOptimizationTool>, <VerificationOptimizationTool> or "
            "<DesignOptimizationTool>",
        )
    up.flatten_sets()
    if tool.tag not in ("TrackingOptimizationTool", "VerificationOptimizationTool", "DesignOptimizationTool"):
        up.note(tool, f"version {up.root.get('Version')} <{tool.tag}>: no known 0.x differences; read as current")
        up.set_root(tool)
        return
    _directories(up, tool)
    for old, new in (
        ("osimx_file", "input_osimx_file"),
        ("optimal_control_settings_file", "optimal_control_solver_settings_file"),
    ):
        up.rename_child(tool, old, new)
    controller = _controller(up, tool)
    _bounds(up, tool, controller)
    _cost_terms(up, tool)
    _constraint_terms(up, tool)
    _trial_and_states(up, tool)
    up.set_root(tool)


def _directories(up: Upgrader, tool: etree._Element) -> None:
    data = child_of(tool, "data_directory")
    if data is not None:
        up.rename(data, "tracked_quantities_directory")
        guess = up.new("initial_guess_directory", data.text, like=data)
        tool.insert(tool.index(data), guess)
        up.note(
            data,
            "<data_directory> -> <tracked_quantities_directory> and <initial_guess_directory> (0.1.0 read both from it)",
        )
    for tag in ("initial_states_file", "initial_controls_file"):
        element = child_of(tool, tag)
        if element is None:
            continue
        if _text(element):
            up.drop(
                element,
                "0.1.0 initial-guess files (jerk-control layout) have no current equivalent; the initial guess "
                "comes from <initial_guess_directory> (<trial>_states.sto, _torqueControls.sto, ...) or the tracked IK/ID",
            )
        else:
            tool.remove(element)


def _controller(up: Upgrader, tool: etree._Element) -> etree._Element | None:
    kind = child_of(tool, "type_of_controller")
    coordinates = child_of(tool, "coordinate_list")
    optimize = child_of(tool, "optimize_synergy_vectors")
    if kind is None:
        return None
    _check_controller_type(up, kind)
    for element in (kind, coordinates, optimize):
        if element is not None:
            up.remove_description(element)
    position = tool.index(kind)
    if _text(kind) == "synergy_driven":
        controller = up.new("RCNLSynergyController", like=kind)
        if coordinates is not None:
            up.rename(coordinates, "surrogate_model_coordinate_list")
            controller.append(coordinates)
        if optimize is not None:
            controller.append(optimize)
        up.note(
            kind,
            "synergy_driven -> <RCNLSynergyController>; add <surrogate_model_data_directory> "
            "(sampled poses for the surrogate muscle model)",
        )
    else:
        controller = up.new("RCNLTorqueController", like=kind)
        if coordinates is not None:
            controller.append(coordinates)
        if optimize is not None:
            if _text(optimize) == "true":
                up.drop(optimize, "synergy vectors cannot be optimized with a torque controller")
            else:
                tool.remove(optimize)
        up.note(kind, "torque_driven -> <RCNLTorqueController> with the old <coordinate_list>")
    tool.insert(position, controller)
    tool.remove(kind)
    return controller


def _check_controller_type(up: Upgrader, kind: etree._Element) -> None:
    """An :class:`InputError` unless ``<type_of_controller>`` is one of :data:`CONTROLLER_TYPES`."""
    value = _text(kind)
    if value in CONTROLLER_TYPES:
        return
    close = difflib.get_close_matches(value, CONTROLLER_TYPES, n=1, cutoff=0.8)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    problem = f"'{value}' is not a controller type" if value else "empty controller type"
    raise InputError(
        f"{problem} of the 0.1.0 schema{hint}",
        file=up.path,
        line=kind.sourceline,
        element="<type_of_controller>",
        expected=" or ".join(CONTROLLER_TYPES),
    )


def _bounds(up: Upgrader, tool: etree._Element, controller: etree._Element | None) -> None:
    block = child_of(tool, "RCNLDesignVariableBoundsTerms")
    if block is None:
        return
    position = tool.index(block)
    for child in list(elements(block)):
        target = BOUNDS.get(str(child.tag))
        if target is None:
            why = (
                "jerk controls are gone (controls are accelerations); no current equivalent"
                if child.tag == "joint_jerks_multiple"
                else "no current equivalent"
            )
            up.drop(child, why)
            continue
        name, in_controller = target
        child.tag = name
        if in_controller and controller is not None:
            controller.append(child)
        elif in_controller:
            up.drop(child, "no controller to hold it")
        else:
            tool.insert(position, child)
            position += 1
    leftovers = list(block)  # comments quoting dropped elements
    for item in leftovers:
        tool.insert(position, item)
        position += 1
    tool.remove(block)
    up.note(block, "<RCNLDesignVariableBoundsTerms> multiples -> *_range_scale_factor elements")


def _retype(up: Upgrader, term: etree._Element, table: dict[str, str], family: str) -> bool:
    """Rename the term's type; False (term dropped) when it has no current equivalent."""
    type_element = child_of(term, "type")
    old = _text(type_element)
    if old == "joint_jerk":
        up.drop(
            term, "joint_jerk minimization: jerk controls are gone (controls are accelerations); no current equivalent"
        )
        return False
    new = table.get(old)
    if new is None:
        up.note(term, f"{family} term type '{old}' has no known current name; kept as is")
        return True
    type_element.text = new
    up.note(type_element, f"{family} term type '{old}' -> '{new}'")
    return True


def _cost_terms(up: Upgrader, tool: etree._Element) -> None:
    container = child_of(tool, "RCNLContinuousCostTermSet")
    if container is None:
        return
    term_set = up.new("RCNLCostTermSet", like=container)
    for block_name, table, family in (
        ("RCNLTrackingCostTerms", TRACKING_TYPES, "tracking"),
        ("RCNLMinimizationCostTerms", MINIMIZATION_TYPES, "minimization"),
    ):
        block = child_of(container, block_name)
        if block is None:
            continue
        for old_set in [c for c in elements(block) if c.tag == "RCNLCostTermSet"]:
            for term in list(elements(old_set)):
                term_set.append(term)
                _retype(up, term, table, family)
    tool.replace(container, term_set)


def _constraint_terms(up: Upgrader, tool: etree._Element) -> None:
    blocks = [child_of(tool, "RCNLPathConstraintTerms"), child_of(tool, "RCNLTerminalConstraintTerms")]
    present = [b for b in blocks if b is not None]
    if not present:
        return
    term_set = up.new("RCNLConstraintTermSet", like=present[0])
    tool.insert(tool.index(present[0]), term_set)
    for block in present:
        for old_set in [c for c in elements(block) if c.tag == "RCNLConstraintTermSet"]:
            for term in list(elements(old_set)):
                term_set.append(term)
                _retype(up, term, CONSTRAINT_TYPES, "constraint")
        tool.remove(block)


def _trial_and_states(up: Upgrader, tool: etree._Element) -> None:
    """``trial_prefix`` -> ``trial_name``; ``states_coordinate_list`` from the IK file's columns."""
    from nmsm.io.storage import read_storage
    from nmsm.io.trials import find_trial_file, trial_prefixes

    prefix = child_of(tool, "trial_prefix")
    name = _text(prefix)
    tracked = child_of(tool, "tracked_quantities_directory")
    ik_dir = None
    if tracked is not None:
        try:
            base = resolve_path(
                _text(tracked) or ".",
                settings_file=up.path,
                line=tracked.sourceline,
                element="tracked_quantities_directory",
                kind="dir",
            )
            ik_dir = base / "IKData"
        except InputError as exc:
            up.note(tracked, f"tracked data folder not found ({exc.detail})")
    if not name and ik_dir is not None and ik_dir.is_dir():
        found = trial_prefixes(ik_dir)
        if len(found) == 1:
            name = found[0]
            up.note(
                prefix if prefix is not None else tool,
                f"<trial_name>{name}</trial_name> added: the only trial in {ik_dir}",
            )
        else:
            up.note(
                prefix if prefix is not None else tool,
                f"empty trial prefix and {len(found)} trials in {ik_dir}: set <trial_name>",
            )
    trial = up.new("trial_name", name, like=prefix if prefix is not None else tool)
    if prefix is not None:
        tool.replace(prefix, trial)
    else:
        tool.append(trial)
    if child_of(tool, "states_coordinate_list") is not None:
        return
    states = up.new("states_coordinate_list", "", like=trial)
    tool.insert(tool.index(trial) + 1, states)
    if name and ik_dir is not None and ik_dir.is_dir():
        try:
            table = read_storage(find_trial_file(ik_dir, name))
            states.text = " ".join(table.labels)
            up.note(
                trial,
                f"<states_coordinate_list> added: every column of {table.source.name} (0.1.0 made every IK coordinate a state)",
            )
            return
        except InputError as exc:
            up.note(trial, f"IK file not readable ({exc.detail})")
    up.note(trial, "<states_coordinate_list> is required by the current schema: fill it in")


def upgrade_gpops(up: Upgrader) -> None:
    """``<GpopsDocument><GpopsSettings>`` -> ``<OptimalControlSolverSettings><GpopsSettings>``."""
    settings = child_of(up.root, "GpopsSettings")
    if settings is None:
        raise InputError(
            "no <GpopsSettings> in <GpopsDocument>", file=up.path, line=up.root.sourceline, expected="<GpopsSettings>"
        )
    intervals = child_of(settings, "collocation_points")
    mesh_iterations = _text(child_of(settings, "mesh_max_iterations"))
    for child in list(elements(settings)):
        if child is intervals:
            continue
        new = GPOPS_NAMES.get(str(child.tag))
        if new is None:
            up.drop(child, "no current equivalent")
            continue
        if not _text(child):
            if child.tag == "mesh_method" and mesh_iterations in ("0", "0.0"):
                child.tag, child.text = new, "none"
                up.note(
                    child,
                    "empty <mesh_method> with <mesh_max_iterations>0 -> <setup_mesh_method>none (a fixed mesh, as before)",
                )
            else:
                settings.remove(child)
                up.note(child, f"empty <{child.tag}> removed: the current default of <{new}> applies")
            continue
        child.tag = new
    if intervals is not None:
        count = _text(intervals) or "5"
        position = settings.index(intervals)
        settings.insert(position, up.new("setup_mesh_phase_intervals", count, like=intervals))
        settings.insert(position + 1, up.new("setup_mesh_phase_colpoints_per_Interval", "10", like=intervals))
        settings.remove(intervals)
        up.note(
            intervals,
            f"<collocation_points>{count} (intervals of 10 points each in 0.1.0) -> "
            f"<setup_mesh_phase_intervals>{count} and <setup_mesh_phase_colpoints_per_Interval>10",
        )
    wrapper = up.new("OptimalControlSolverSettings", like=up.root)
    wrapper.append(settings)
    up.set_root(wrapper)
