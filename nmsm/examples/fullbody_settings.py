"""TO, VO and DO settings of the full-body gait case, and their solver files.

Two controller set-ups (:class:`Controllers`):

* ``stress`` - all 86 leg muscles synergy-driven (``right_leg``/``left_leg``, 5 + 5
  synergies from the case's NCP, vectors optimized in TO and DO), surrogate on the 14 leg
  coordinates; torques on the lumbar and arm coordinates;
* ``combined`` - the NCP tutorial's right-leg synergies (9 muscles, ``RightLeg_1..4``) on its
  surrogate coordinates, torques on every other non-root state coordinate.

Every tool has the 31 state coordinates (:func:`nmsm.examples.fullbody_data.state_coordinates`),
both feet's GCP contact from the ``.osimx``, kinetic consistency on every non-root
load and the pelvis residual loads as constraints. TO tracks coordinates, speeds, ID loads,
both feet's ground reactions and the muscle activations of the initial guess; VO tracks the
TO's controls from the TO's start; DO tracks the VO's controls with the stroke plugin's
``synergy_amplitude_symmetry`` term on paired right/left synergies and its
``scaleSynergyActivation`` model function scaling the first right-leg synergy (the
paretic side's drive) between 0.6 and 1. Chained by folders: TO -> ``results/to``, VO reads
it and writes ``results/vo``, DO reads ``results/vo``.

The writers of the built-in example (:mod:`nmsm.examples.subject_settings`) make the
terms, constraints and solver files.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import attrs

from nmsm.examples import fullbody_data as fd
from nmsm.examples.subject_settings import SOLVER_XML, _constraint, _relative, _term

#: mesh variants: (intervals, collocation points per interval)
MESHES = {"full": (25, 4), "coarse": (5, 4)}
#: IPOPT tolerance and iteration limit of TO/VO and of DO (Design Optimization caps at 1e-6);
#: with limited-memory Hessians (see :func:`solver_xml`) IPOPT takes more, cheaper iterations
SOLVER_FILES = {"solver.xml": ("1e-3", 3000), "solver_do.xml": ("1e-6", 3000)}
#: the case's Lagrangian Hessian: L-BFGS (docs/treatment.md, "Scale": the exact Hessian of
#: the contact and muscle functions costs most of an iteration and IPOPT regularizes it heavily)
HESSIAN = "limited-memory"
#: tracking errors: rotations (rad), translations (m), their speeds, loads (N·m or N),
#: ground forces (N) and moments (N·m), activations (-)
COORDINATE_ERROR = 0.0873
TRANSLATION_ERROR = 0.02
SPEED_ERROR = 0.873
TRANSLATION_SPEED_ERROR = 0.2
LOAD_ERROR = 10.0
FORCE_ERROR = 20.0
MOMENT_ERROR = 10.0
ACTIVATION_ERROR = 0.1
#: constraint half-widths: kinetic consistency (N·m), pelvis residual loads (N·m or N)
CONSISTENCY = 1.0
RESIDUAL = 5.0
#: DO: the paretic synergy's drive bounds and the symmetry term's allowed amplitude difference
PARETIC_SCALE = (0.6, 1.0)
SYMMETRY_ERROR = 0.05
TOOLS = ("to", "vo", "do")


@attrs.frozen
class Controllers:
    """One controller set-up: synergy groups (names, synergies), surrogate coordinates,
    torque-driven coordinates, the muscles whose activations TO tracks, and the DO's
    (right, left) synergy pairs of the symmetry term and the paretic synergy."""

    name: str
    synergy_names: tuple[str, ...]
    surrogate_coordinates: tuple[str, ...]
    torque_coordinates: tuple[str, ...]
    muscles: tuple[str, ...]
    optimize_vectors: bool
    max_synergy_activation: float
    pairs: tuple[tuple[str, str], ...]
    paretic: str

    @property
    def consistency_coordinates(self) -> tuple[str, ...]:
        """Non-root state coordinates: muscles, torques or both drive each of them."""
        return tuple(c for c in fd.state_coordinates() if c not in fd.PELVIS)


@attrs.frozen
class CaseFolders:
    """Where a case's inputs are (absolute): model, osimx, tracked data, the TO's initial guess,
    the surrogate data; ``settings`` is the folder the settings files go to, ``results``
    the chained results' parent."""

    settings: Path
    model: Path
    osimx: Path
    tracked: Path
    guess: Path
    surrogate: Path
    results: Path

    def ref(self, path: Path) -> str:
        """``path`` as the settings name it: relative to the settings folder when it is in
        the case folder (the settings folder's parent), else absolute."""
        if path.resolve().is_relative_to(self.settings.parent.resolve()):
            return _relative(path, self.settings)
        return str(path.resolve())


def _load(coordinate: str) -> str:
    return f"{coordinate}_force" if coordinate in ("pelvis_tx", "pelvis_ty", "pelvis_tz") else f"{coordinate}_moment"


def _loads(coordinates: Sequence[str]) -> str:
    return " ".join(_load(c) for c in coordinates)


def solver_xml(mesh: str, file_name: str) -> str:
    intervals, points = MESHES[mesh]
    tolerance, iterations = SOLVER_FILES[file_name]
    text = SOLVER_XML.format(tolerance=tolerance, intervals=intervals, points=points, max_iterations=iterations)
    return text.replace("    </GpopsSettings>",
                        f"      <hessian_approximation>{HESSIAN}</hessian_approximation>\n    </GpopsSettings>", 1)


def _common(folders: CaseFolders, results: Path, guess: Path, tracked: Path, solver: str) -> str:
    r = folders.ref
    return f"""<results_directory>{r(results)}</results_directory>
    <initial_guess_directory>{r(guess)}</initial_guess_directory>
    <tracked_quantities_directory>{r(tracked)}</tracked_quantities_directory>
    <input_model_file>{r(folders.model)}</input_model_file>
    <input_osimx_file>{r(folders.osimx)}</input_osimx_file>
    <optimal_control_solver_settings_file>{solver}</optimal_control_solver_settings_file>
    <trial_name>{fd.TRIAL}</trial_name>
    <states_coordinate_list>{" ".join(fd.state_coordinates())}</states_coordinate_list>"""


def _controllers_xml(controllers: Controllers, folders: CaseFolders, optimize_vectors: bool) -> str:
    return f"""<RCNLSynergyController>
      <surrogate_model_coordinate_list>{" ".join(controllers.surrogate_coordinates)}</surrogate_model_coordinate_list>
      <surrogate_model_data_directory>{folders.ref(folders.surrogate)}</surrogate_model_data_directory>
      <surrogate_model_polynomial_degree>5</surrogate_model_polynomial_degree>
      <optimize_synergy_vectors>{"true" if optimize_vectors else "false"}</optimize_synergy_vectors>
      <synergy_vector_normalization_method>sum</synergy_vector_normalization_method>
      <synergy_vector_normalization_value>1</synergy_vector_normalization_value>
      <maximum_allowable_synergy_activation>{controllers.max_synergy_activation:g}\
</maximum_allowable_synergy_activation>
    </RCNLSynergyController>
    <RCNLTorqueController>
      <coordinate_list>{" ".join(controllers.torque_coordinates)}</coordinate_list>
    </RCNLTorqueController>"""


def _feet_contact() -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Both plates' force and moment columns (GRFData of the case)."""
    forces = tuple(f"ground_force_{p}_v{a}" for p in (2, 1) for a in "xyz")
    moments = tuple(f"ground_moment_{p}_m{a}" for p in (2, 1) for a in "xyz")
    return forces, moments


def _tracking_terms(controllers: Controllers) -> str:
    states = fd.state_coordinates()
    rotations = [c for c in states if c not in ("pelvis_tx", "pelvis_ty", "pelvis_tz")]
    translations = ["pelvis_tx", "pelvis_ty", "pelvis_tz"]
    forces, moments = _feet_contact()
    return (_term("generalized_coordinate_tracking", COORDINATE_ERROR, coordinate_list=" ".join(rotations))
            + _term("generalized_coordinate_tracking", TRANSLATION_ERROR, coordinate_list=" ".join(translations))
            + _term("generalized_speed_tracking", SPEED_ERROR, coordinate_list=" ".join(rotations))
            + _term("generalized_speed_tracking", TRANSLATION_SPEED_ERROR, coordinate_list=" ".join(translations))
            + _term("inverse_dynamics_load_tracking", LOAD_ERROR,
                    load_list=_loads(controllers.consistency_coordinates))
            + _term("external_force_tracking", FORCE_ERROR, force_list=" ".join(forces))
            + _term("external_moment_tracking", MOMENT_ERROR, moment_list=" ".join(moments))
            + _term("muscle_activation_tracking", ACTIVATION_ERROR, muscle_list=" ".join(controllers.muscles)))


def _dynamics_constraints(controllers: Controllers) -> str:
    return (_constraint("kinetic_consistency", -CONSISTENCY, CONSISTENCY,
                        load_list=_loads(controllers.consistency_coordinates))
            + _constraint("root_segment_residual_load", -RESIDUAL, RESIDUAL, load_list=_loads(fd.PELVIS)))


def _initial_state() -> str:
    """VO and DO start at the positions where the motion they verify or change starts.

    The initial speeds are not constrained: the tracked speeds are the derivatives of the
    splined positions the previous tool wrote, and in Radau collocation the first mesh point is
    not collocated, so that tool's own speed there is not its positions' derivative;
    constraining them would make the previous tool's solution infeasible from the start.
    """
    coordinates = " ".join(fd.state_coordinates())
    return _constraint("initial_generalized_coordinate_deviation", -1e-3, 1e-3, coordinate_list=coordinates)


def _controller_tracking(controllers: Controllers) -> str:
    names = list(controllers.synergy_names) + [_load(c) for c in controllers.torque_coordinates]
    return _term("controller_tracking", 1.0, controller_list=" ".join(names))


def treatment_xml(tool: str, controllers: Controllers, folders: CaseFolders) -> str:
    """``to``, ``vo`` or ``do`` settings (paths relative to ``folders.settings``)."""
    results = {t: folders.results / t for t in TOOLS}
    header = f"<!-- Full-body gait case ({controllers.name}): {tool.upper()}. -->"
    if tool == "to":
        body = f"""<TrackingOptimizationTool>
    {_common(folders, results["to"], folders.guess, folders.tracked, "solver.xml")}
    {_controllers_xml(controllers, folders, controllers.optimize_vectors)}
    <RCNLCostTermSet>{_tracking_terms(controllers)}</RCNLCostTermSet>
    <RCNLConstraintTermSet>{_dynamics_constraints(controllers)}</RCNLConstraintTermSet>
  </TrackingOptimizationTool>"""
    elif tool == "vo":
        body = f"""<VerificationOptimizationTool>
    {_common(folders, results["vo"], results["to"], results["to"], "solver.xml")}
    {_controllers_xml(controllers, folders, False)}
    <RCNLCostTermSet>{_controller_tracking(controllers)}</RCNLCostTermSet>
    <RCNLConstraintTermSet>{_dynamics_constraints(controllers)}{_initial_state()}</RCNLConstraintTermSet>
  </VerificationOptimizationTool>"""
    elif tool == "do":
        pairs = " ".join(f"{a}:{b}" for a, b in controllers.pairs)
        low, high = PARETIC_SCALE
        costs = _controller_tracking(controllers) + _term("synergy_amplitude_symmetry", SYMMETRY_ERROR,
                                                           synergy_pairs=pairs, amplitude="rms")
        body = f"""<DesignOptimizationTool>
    {_common(folders, results["do"], results["vo"], results["vo"], "solver_do.xml")}
    {_controllers_xml(controllers, folders, controllers.optimize_vectors)}
    <model_functions>scaleSynergyActivation</model_functions>
    <RCNLParameterTermSet><RCNLParameterTerm><type>paretic_synergy_scale</type>
      <synergy>{controllers.paretic}</synergy><initial_values>1</initial_values>
      <lower_bounds>{low:g}</lower_bounds><upper_bounds>{high:g}</upper_bounds>
    </RCNLParameterTerm></RCNLParameterTermSet>
    <RCNLCostTermSet>{costs}</RCNLCostTermSet>
    <RCNLConstraintTermSet>{_dynamics_constraints(controllers)}{_initial_state()}</RCNLConstraintTermSet>
  </DesignOptimizationTool>"""
    else:
        raise ValueError(f"tool must be one of {TOOLS}, got '{tool}'")
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n{header}\n<NMSMPipelineDocument Version="1.5.3">\n'
            f"  {body}\n</NMSMPipelineDocument>\n")


def write_treatment_settings(controllers: Controllers, folders: CaseFolders, mesh: str) -> dict[str, Path]:
    """``<settings>/{TO,VO,DO}Settings.xml``, ``solver.xml`` and ``solver_do.xml``; the paths by tool."""
    if mesh not in MESHES:
        raise ValueError(f"mesh must be one of {tuple(MESHES)}, got '{mesh}'")
    folders.settings.mkdir(parents=True, exist_ok=True)
    for name in SOLVER_FILES:
        (folders.settings / name).write_text(solver_xml(mesh, name), encoding="utf-8")
    paths = {}
    for tool in TOOLS:
        path = folders.settings / f"{tool.upper()}Settings.xml"
        path.write_text(treatment_xml(tool, controllers, folders), encoding="utf-8")
        paths[tool] = path
    return paths
