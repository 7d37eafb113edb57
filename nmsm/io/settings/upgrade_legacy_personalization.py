"""Upgrade ``<OpenSimDocument>``-rooted JMP, MTP, NCP and GCP settings (2021-2023 schemas).

Each rule is listed in ``docs/settings-upgrade.md``. Elements without a current equivalent
are replaced by a comment quoting them, with a note.
"""

from __future__ import annotations

from lxml import etree

from nmsm.errors import InputError
from nmsm.io.paths import resolve_path
from nmsm.io.settings.document import TOOL_ELEMENTS, elements
from nmsm.io.settings.upgrader import Upgrader, child_of
from nmsm.io.xml_input import element_text, refuse_entities, set_element_text, xml_parser

#: 2021 JMP option names -> current
JMP_OPTION_NAMES = {
    "diffMinChange": "diff_min_change",
    "optimalityTolerance": "optimality_tolerance",
    "functionTolerance": "function_tolerance",
    "stepTolerance": "step_tolerance",
    "maxFunctionEvaluations": "max_function_evaluations",
    "model_file": "input_model_file",
}
#: old MTLI cost blocks (IndividualMuscles / GroupedMuscles children) -> current term types
MTLI_INDIVIDUAL_TERMS = {
    "PassiveJointMoments": "passive_joint_moment",
    "OptimalMuscleFiberLength": "optimal_muscle_fiber_length",
    "TendonSlackLength": "tendon_slack_length",
    "MinimumNormalizedMuscleFiberLength": "minimum_normalized_muscle_fiber_length",
    "MaximumNormalizedMuscleFiberLength": "maximum_normalized_muscle_fiber_length",
    "MaximumMuscleStress": "maximum_muscle_stress",
    "PassiveMuscleForces": "passive_muscle_force",
}
MTLI_GROUPED_TERMS = {
    "NormalizedMuscleFiberLength": "grouped_normalized_muscle_fiber_length",
    "MaximumNormalizedMuscleFiberLength": "grouped_maximum_normalized_muscle_fiber_length",
}
#: old NCP cost blocks -> current term types
NCP_TERMS = {
    "MomentTracking": "moment_tracking",
    "ActivationTracking": "activation_tracking",
    "ActivationMinimization": "activation_minimization",
    "GroupedActivation": "grouped_activations",
    "GroupedNormalizedMuscleFiberLength": "grouped_fiber_lengths",
}
#: old NCP ``<RCNLCostTerm><type>`` values -> current: the early-2023 NCP named its ID joint-moment
#: tracking term as MTP does (``oldNCPSettingsFile.xml``; ``newNCPSettingsFile.xml`` has the same
#: term, 5 N m, as ``moment_tracking``)
NCP_TERM_TYPES = {"inverse_dynamics_joint_moment": "moment_tracking"}


def upgrade(up: Upgrader) -> None:
    """Dispatch on the tool element; every tool gets the set flattening and the new root."""
    tool = next(c for c in elements(up.root) if c.tag in TOOL_ELEMENTS)
    up.flatten_sets()
    rule = _TOOLS.get(str(tool.tag))
    if rule is not None:
        rule(up, tool)
    _drop_everywhere(up, tool, "min_allowable_error", "not a term field in the current schema")
    up.set_root(tool)


def _drop_everywhere(up: Upgrader, tool: etree._Element, tag: str, why: str) -> None:
    for element in list(tool.iter(tag)):
        up.drop(element, why)


# ----- JMP --------------------------------------------------------------------------------
def _jmp(up: Upgrader, tool: etree._Element) -> None:
    for old, new in JMP_OPTION_NAMES.items():
        up.rename_child(tool, old, new)
    task_set = child_of(tool, "TaskSet")
    if task_set is not None:
        _jmp_2021_tasks(up, tool, task_set)
    task_list = child_of(tool, "JMPTaskList")
    if task_list is None:
        return
    for task in [c for c in elements(task_list) if c.tag == "JMPTask"]:
        for joint in task.iter("JMPJoint"):
            for tag in ("scale_bodies", "optimize_marker_positions"):
                flag = child_of(joint, tag)
                if flag is None:
                    continue
                if (flag.text or "").strip() == "true":
                    up.drop(
                        flag,
                        "no current equivalent inside <JMPJoint>; declare the bodies in a <JMPBodySet> (JMPBody scale_body / move_markers)",
                    )
                else:
                    up.drop(flag, "false, and no current equivalent inside <JMPJoint>")
        ik = child_of(task, "ik_settings_file")
        if ik is not None:
            _jmp_ik_settings(up, task, ik)


def _jmp_2021_tasks(up: Upgrader, tool: etree._Element, task_set: etree._Element) -> None:
    """2021 layout: ``TaskSet/Task/Joint/{parent,child}_frame``."""
    up.rename(task_set, "JMPTaskList")
    tasks = [c for c in elements(task_set) if c.tag == "Task"]
    for i, task in enumerate(tasks, start=1):
        up.rename(task, "JMPTask")
        up.ensure(task, "is_enabled", "true", index=0)
        if len(tasks) > 1:
            up.ensure(task, "index", str(i), index=1)
        joints = [c for c in elements(task) if c.tag == "Joint"]
        if joints:
            joint_set = up.new("JMPJointSet", like=joints[0])
            task.insert(task.index(joints[0]), joint_set)
            for joint in joints:
                up.rename(joint, "JMPJoint")
                joint_set.append(joint)
                up.rename_child(joint, "parent_frame", "parent_frame_transformation")
                up.rename_child(joint, "child_frame", "child_frame_transformation")
    up.note(
        task_set,
        f"2021 <TaskSet>/<Task>/<Joint> layout upgraded to <JMPTaskList>/<JMPTask>/<JMPJointSet> "
        f"({len(tasks)} task(s), all enabled, indexed in file order)",
    )


def _jmp_ik_settings(up: Upgrader, task: etree._Element, ik: etree._Element) -> None:
    """2023 ``<ik_settings_file>``: time range and applied markers move into the task."""
    text = (ik.text or "").strip()
    if not text:
        up.drop(ik, "empty")
        return
    try:
        path = resolve_path(text, settings_file=up.path, line=ik.sourceline, element="ik_settings_file", kind="file")
        root = etree.parse(str(path), xml_parser()).getroot()
        refuse_entities(root, path, "IK settings file")
    except (InputError, OSError, etree.XMLSyntaxError) as exc:
        up.drop(ik, f"the IK settings could not be read ({exc}); set <time_range> and <marker_names> by hand")
        return
    ik_tool = root.find(".//InverseKinematicsTool")
    if ik_tool is None:
        up.drop(ik, f"{path.name} holds no <InverseKinematicsTool>; set <time_range> and <marker_names> by hand")
        return
    time_range = ik_tool.findtext("time_range")
    if time_range and time_range.split() and child_of(task, "time_range") is None:
        element = up.new("time_range", " ".join(time_range.split()), like=ik)
        task.insert(task.index(ik), element)
    applied, weights = [], set()
    for marker_task in ik_tool.iter("IKMarkerTask"):
        if (marker_task.findtext("apply") or "true").strip() == "true":
            applied.append(marker_task.get("name"))
            weights.add((marker_task.findtext("weight") or "1").strip())
    if applied and child_of(task, "marker_names") is None:
        element = up.new("marker_names", " ".join(applied), like=ik)
        task.insert(task.index(ik), element)
    weight_note = (
        ""
        if weights <= {"1", "1.0"}
        else f"; marker weights {sorted(weights)} have no current equivalent (JMP weighs markers equally)"
    )
    up.drop(
        ik,
        f"replaced by <time_range> and <marker_names> ({len(applied)} applied markers) read from {path.name}{weight_note}",
    )


# ----- MTP / NCP --------------------------------------------------------------------------
def _mtp(up: Upgrader, tool: etree._Element) -> None:
    synx = child_of(tool, "MTPSynergyExtrapolation")
    if synx is not None:
        prefixes = child_of(synx, "task_prefixes")
        if prefixes is not None:
            up.drop(prefixes, "no current equivalent in <MTPSynergyExtrapolation>")
    _muscle_common(up, tool)


def _ncp(up: Upgrader, tool: etree._Element) -> None:
    up.rename_child(tool, "mtp_results_input_directory", "mtp_results_directory")
    synergy_set = child_of(tool, "SynergySet")
    if synergy_set is not None:
        up.rename(synergy_set, "RCNLSynergySet")
        for synergy in elements(synergy_set):
            if synergy.tag == "Synergy":
                up.rename(synergy, "RCNLSynergy")
        up.note(synergy_set, "<SynergySet>/<Synergy> renamed <RCNLSynergySet>/<RCNLSynergy>")
    old_terms = child_of(tool, "NeuralControlCostFunctionTerms")
    if old_terms is not None:
        term_set = _blocks_to_terms(up, old_terms, NCP_TERMS)
        tool.replace(old_terms, term_set)
    _rename_term_types(up, tool, NCP_TERM_TYPES)
    init = child_of(tool, "muscle_tendon_parameter_initialization")
    if init is not None:
        up.drop(init, "superseded by <MuscleTendonLengthInitialization><is_enabled>")
    _muscle_common(up, tool)


def _rename_term_types(up: Upgrader, tool: etree._Element, mapping: dict[str, str]) -> None:
    """``<RCNLCostTerm><type>`` values of an already term-shaped old file -> current names."""
    term_set = child_of(tool, "RCNLCostTermSet")
    if term_set is None:
        return
    for term in elements(term_set):
        type_element = child_of(term, "type") if term.tag == "RCNLCostTerm" else None
        old = element_text(type_element)
        if old in mapping:
            set_element_text(type_element, mapping[old])
            up.note(type_element, f"cost <type> {old} renamed {mapping[old]}")


def _muscle_common(up: Upgrader, tool: etree._Element) -> None:
    up.rename_child(tool, "input_directory", "data_directory")
    grouped = child_of(tool, "GroupedMuscles")
    if grouped is not None:
        for old, new in (
            ("activations", "activation_muscle_groups"),
            ("normalized_muscle_fiber_lengths", "normalized_fiber_length_muscle_groups"),
        ):
            element = child_of(grouped, old)
            if element is not None and child_of(tool, new) is None:
                element.tag = new
                tool.insert(tool.index(grouped), element)
        leftover = list(elements(grouped))
        if leftover:
            up.drop(grouped, "no current equivalent for " + ", ".join(f"<{c.tag}>" for c in leftover))
        else:
            tool.remove(grouped)
        up.note(
            grouped,
            "<GroupedMuscles> children moved to <activation_muscle_groups> / <normalized_fiber_length_muscle_groups>",
        )
    mtli = child_of(tool, "MuscleTendonLengthInitialization")
    if mtli is not None:
        old = child_of(mtli, "MuscleTendonLengthInitializationCostFunctionTerms")
        if old is not None:
            table: dict[str, str] = {}
            term_set = up.new("RCNLCostTermSet", like=old)
            for block_name, mapping in (
                ("IndividualMuscles", MTLI_INDIVIDUAL_TERMS),
                ("GroupedMuscles", MTLI_GROUPED_TERMS),
            ):
                block = child_of(old, block_name)
                if block is not None:
                    for term in _blocks_to_terms(up, block, mapping):
                        term_set.append(term)
                    table.update(mapping)
            mtli.replace(old, term_set)
        if child_of(mtli, "is_enabled") is None:
            up.ensure(
                mtli,
                "is_enabled",
                "false",
                index=0,
                why="required by the current schema; the old file did not enable it",
            )
    for tag in ("input_osimx_file", "activation_muscle_groups", "normalized_fiber_length_muscle_groups"):
        if child_of(tool, tag) is None:
            up.ensure(tool, tag, "", why="required element of the current schema (may be empty)")


def _blocks_to_terms(up: Upgrader, container: etree._Element, mapping: dict[str, str]) -> etree._Element:
    """Old ``<CamelCaseTerm><is_enabled/><max_allowable_error/>...`` blocks -> ``RCNLCostTermSet``."""
    term_set = up.new("RCNLCostTermSet", like=container)
    done = []
    for block in list(elements(container)):
        term_type = mapping.get(str(block.tag))
        if term_type is None:
            up.drop(block, f"unknown old cost block; known: {', '.join(mapping)}")
            continue
        term = up.new("RCNLCostTerm", like=block)
        term.append(up.new("type", term_type, like=block))
        for child in list(elements(block)):
            term.append(child)
        term_set.append(term)
        done.append(f"{block.tag} -> {term_type}")
    if done:
        up.note(container, f"<{container.tag}> blocks -> <RCNLCostTerm>s: " + ", ".join(done))
    return term_set


# ----- GCP --------------------------------------------------------------------------------
def _gcp(up: Upgrader, tool: etree._Element) -> None:
    up.rename_child(tool, "resting_spring_length_initialization_is_enabled", "initialize_resting_spring_length")
    surface_set = child_of(tool, "GCPContactSurfaceSet")
    if surface_set is None:
        return
    model_root = None
    for surface in elements(surface_set):
        toe_joint = _first_child(surface, "toe_joint", "toes_joint")
        toe_coordinate = _first_child(surface, "toe_coordinate", "toes_coordinate")
        if toe_joint is None and toe_coordinate is None:
            continue
        if child_of(surface, "hindfoot_body") is None:
            if model_root is None:
                model_root = _read_model(up, tool)
            body = _hindfoot_body(model_root, toe_joint, toe_coordinate)
            anchor = toe_joint if toe_joint is not None else toe_coordinate
            if body is None:
                up.note(anchor, "could not find the toe joint's parent body in the model; add <hindfoot_body> by hand")
            else:
                surface.insert(surface.index(anchor), up.new("hindfoot_body", body, like=anchor))
                up.note(
                    anchor, f"<hindfoot_body>{body}</hindfoot_body> added: parent body of the toe joint in the model"
                )
        for old in (toe_joint, toe_coordinate):
            if old is not None:
                up.drop(old, "replaced by <hindfoot_body> in the current schema")


def _first_child(parent: etree._Element, *tags: str) -> etree._Element | None:
    for tag in tags:
        found = child_of(parent, tag)
        if found is not None:
            return found
    return None


def _read_model(up: Upgrader, tool: etree._Element) -> etree._Element | None:
    element = child_of(tool, "input_model_file")
    text = (element.text or "").strip() if element is not None else ""
    if not text:
        return None
    try:
        path = resolve_path(
            text, settings_file=up.path, line=element.sourceline, element="input_model_file", kind="file"
        )
        root = etree.parse(str(path), xml_parser(huge_tree=True)).getroot()
        refuse_entities(root, path, "model file")
        return root
    except (InputError, OSError, etree.XMLSyntaxError) as exc:
        up.note(element, f"model not readable to find the hindfoot body: {exc}")
        return None


def _last(path_text: str) -> str:
    return path_text.strip().rstrip("/").split("/")[-1]


def _hindfoot_body(
    model: etree._Element | None, toe_joint: etree._Element | None, toe_coordinate: etree._Element | None
) -> str | None:
    """Name of the parent body of the toe joint (by joint name, else by its coordinate)."""
    if model is None:
        return None
    joints = [j for j in model.iter() if isinstance(j.tag, str) and j.tag.endswith("Joint") and j.get("name")]
    joint = None
    if toe_joint is not None:
        name = (toe_joint.text or "").strip()
        joint = next((j for j in joints if j.get("name") == name), None)
    if joint is None and toe_coordinate is not None:
        name = (toe_coordinate.text or "").strip()
        joint = next((j for j in joints if any(c.get("name") == name for c in j.iter("Coordinate"))), None)
    if joint is None:
        return None
    parent_body = joint.findtext("parent_body")  # OpenSim 3 models
    if parent_body:
        return _last(parent_body)
    frame_name = _last(joint.findtext("socket_parent_frame") or "")
    for frame in joint.iter("PhysicalOffsetFrame"):
        if frame.get("name") == frame_name:
            return _last(frame.findtext("socket_parent") or "") or None
    return frame_name or None


_TOOLS = {
    "JointModelPersonalizationTool": _jmp,
    "MuscleTendonPersonalizationTool": _mtp,
    "NeuralControlPersonalizationTool": _ncp,
    "GroundContactPersonalizationTool": _gcp,
}
