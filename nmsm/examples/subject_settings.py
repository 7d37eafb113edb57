"""The pipeline file of the built-in example (``nmsm example``) for a generated subject.

:func:`write_example_pipeline` writes ``<folder>/pipeline.xml``: JMP from the subject's
range-of-motion settings file, then every other stage embedded (the analyses of the passive
trials and of the gait trial on the personalized model, preprocessing, MTP with MTLI, NCP,
GCP, surrogate data, and the
treatment stages TO, VO, DO with their solver files ``<folder>/settings/solver.xml`` and, for the
DO, ``solver_do.xml``).
Paths are relative to the pipeline file; inputs the runner rewires (model, osimx, data
folders) name the subject's own files so each embedded block also reads on its own.
"""

from __future__ import annotations

import os
from pathlib import Path

from nmsm.examples import subject_model as sm
from nmsm.examples.subject import EMG_LOW_PASS, GCP_WINDOW, GRF_NAME, SIMULATION, TRIAL, TRIAL_WINDOW, Subject

#: the stages of the example, in order (``nmsm example <stage>`` runs up to one of them)
STAGES = ("jmp", "passive", "analysis", "preprocess", "mtp", "ncp", "gcp", "surrogate", "to", "vo", "do")
PREPROCESSED_TRIAL = f"{TRIAL}_1"
#: EMG padding (s) before and after the trial: the padded EMG starts before the simulation,
#: where the recorded excitations are constant. MTP samples the EMG spline at
#: ``t - delay`` from the first padded frame on, so for the first ``delay`` seconds it
#: extrapolates the spline's first cubic piece (as the original's ``ppval`` does); on a
#: steep envelope that gives large negative excitations, and the activation dynamics
#: (``(c1 e + c2) < 0``) amplify them into a transient that outlasts a shorter padding
#: (docs/pipeline.md, "The built-in example").
EMG_PADDING = 0.35


def _term(kind: str, error: float, **fields: str) -> str:
    extra = "".join(f"<{k}>{v}</{k}>" for k, v in fields.items())
    return (f"<RCNLCostTerm><is_enabled>true</is_enabled><type>{kind}</type>"
            f"<max_allowable_error>{error:g}</max_allowable_error>{extra}</RCNLCostTerm>")


def _constraint(kind: str, low: float, high: float, **fields: str) -> str:
    extra = "".join(f"<{k}>{v}</{k}>" for k, v in fields.items())
    return (f"<RCNLConstraintTerm><is_enabled>true</is_enabled><type>{kind}</type>"
            f"<min_error>{low:g}</min_error><max_error>{high:g}</max_error>{extra}</RCNLConstraintTerm>")


def _relative(path: Path, folder: Path) -> str:
    return Path(os.path.relpath(path.resolve(), folder.resolve())).as_posix()


def analysis_xml(subject: Subject, folder: Path) -> str:
    r = lambda p: _relative(p, folder)  # noqa: E731
    return f"""<ModelAnalysisTool>
        <results_directory>analysis</results_directory>
        <input_model_file>{r(subject.generic_model)}</input_model_file>
        <TrialSet>
          <Trial name="{TRIAL}">
            <marker_file>{r(subject.gait_markers)}</marker_file>
            <grf_file>{r(subject.grf_file)}</grf_file>
            <external_loads_file>{r(subject.external_loads)}</external_loads_file>
            <emg_file>{r(subject.emg_file)}</emg_file>
            <time_range>{SIMULATION[0]:g} {SIMULATION[1]:g}</time_range>
          </Trial>
        </TrialSet>
        <accuracy>1e-8</accuracy>
        <muscle_analysis_coordinate_list>{" ".join(sm.MUSCLE_COORDINATES)}</muscle_analysis_coordinate_list>
      </ModelAnalysisTool>"""


def passive_xml(subject: Subject, folder: Path) -> str:
    """IK and muscle analysis of the passive trials on the personalized model; their joint
    moments are the measured ones (MTLI's passive data: ``results/passive``)."""
    r = lambda p: _relative(p, folder)  # noqa: E731
    trials = "".join(f"""
          <Trial name="{name}">
            <marker_file>{r(markers)}</marker_file>
            <inverse_dynamics_file>{r(moments)}</inverse_dynamics_file>
          </Trial>""" for name, markers, moments in subject.passive_trials)
    return f"""<ModelAnalysisTool>
        <results_directory>passive</results_directory>
        <input_model_file>{r(subject.generic_model)}</input_model_file>
        <TrialSet>{trials}
        </TrialSet>
        <accuracy>1e-8</accuracy>
        <muscle_analysis_coordinate_list>{" ".join(sm.MUSCLE_COORDINATES)}</muscle_analysis_coordinate_list>
      </ModelAnalysisTool>"""


def preprocess_xml(subject: Subject, folder: Path) -> str:
    return f"""<DataPreprocessingTool>
        <results_directory>preprocessed</results_directory>
        <input_model_file>{_relative(subject.generic_model, folder)}</input_model_file>
        <motion_data_directory>results/analysis</motion_data_directory>
        <TrialSet><Trial name="{TRIAL}"><time_ranges>{TRIAL_WINDOW[0]:g} {TRIAL_WINDOW[1]:g}</time_ranges></Trial></TrialSet>
        <rows_per_trial>101</rows_per_trial>
        <cutoff_frequency>15</cutoff_frequency>
        <emg_low_pass_frequency>{EMG_LOW_PASS:g}</emg_low_pass_frequency>
        <emg_padding_time>{EMG_PADDING:g}</emg_padding_time>
      </DataPreprocessingTool>"""


def mtp_xml(subject: Subject, folder: Path) -> str:
    """MTLI fits the optimal fiber and tendon slack lengths to the passive trials; the MTP
    tasks then keep them and personalize delays, time constants, EMG scales and
    nonlinearities. (With the lengths free, one gait trial's moments trade them off against
    the EMG scales; docs/developing.md, "Pipeline: measurements and audit trail".)"""
    channels = " ".join(spec.channel for spec in sm.MUSCLES.values())
    terms = _term("inverse_dynamics_joint_moment", 1.0)
    return f"""<MuscleTendonPersonalizationTool>
        <results_directory>mtp</results_directory>
        <input_model_file>{_relative(subject.generic_model, folder)}</input_model_file>
        <input_osimx_file/>
        <data_directory>results/preprocessed</data_directory>
        <coordinate_list>{" ".join(sm.MUSCLE_COORDINATES)}</coordinate_list>
        <activation_muscle_groups/>
        <normalized_fiber_length_muscle_groups/>
        <collected_emg_channel_muscle_groups>{channels}</collected_emg_channel_muscle_groups>
        <MuscleTendonLengthInitialization>
          <is_enabled>true</is_enabled>
          <passive_data_input_directory>results/passive</passive_data_input_directory>
          <optimize_maximum_muscle_stress>false</optimize_maximum_muscle_stress>
          <optimize_isometric_max_force>false</optimize_isometric_max_force>
          <RCNLCostTermSet>{_term("passive_joint_moment", 1.0)}</RCNLCostTermSet>
        </MuscleTendonLengthInitialization>
        <MTPSynergyExtrapolation><is_enabled>false</is_enabled></MTPSynergyExtrapolation>
        <MTPTaskList>
          <MTPTask>
            <is_enabled>true</is_enabled><index>1</index>
            <muscle_specific_electromechanical_delays>true</muscle_specific_electromechanical_delays>
            <optimize_activation_nonlinearity_constants>false</optimize_activation_nonlinearity_constants>
            <optimize_optimal_fiber_lengths>false</optimize_optimal_fiber_lengths>
            <optimize_tendon_slack_lengths>false</optimize_tendon_slack_lengths>
            <RCNLCostTermSet>{terms}</RCNLCostTermSet>
          </MTPTask>
          <MTPTask>
            <is_enabled>true</is_enabled><index>2</index>
            <muscle_specific_electromechanical_delays>true</muscle_specific_electromechanical_delays>
            <optimize_optimal_fiber_lengths>false</optimize_optimal_fiber_lengths>
            <optimize_tendon_slack_lengths>false</optimize_tendon_slack_lengths>
            <RCNLCostTermSet>{terms}</RCNLCostTermSet>
          </MTPTask>
        </MTPTaskList>
        <max_iterations>500</max_iterations>
      </MuscleTendonPersonalizationTool>"""


def ncp_xml(subject: Subject, folder: Path, n_synergies: int) -> str:
    """The NCP stage: 5 synergies of 8 muscles leave the weights nearly free, so IPOPT takes
    many iterations, more with fewer BLAS threads (docs/pipeline.md, "The built-in example"),
    hence ``max_iterations`` 3000."""
    terms = _term("moment_tracking", 1.0) + _term("activation_tracking", 0.02)
    return f"""<NeuralControlPersonalizationTool>
        <results_directory>ncp</results_directory>
        <input_model_file>{_relative(subject.generic_model, folder)}</input_model_file>
        <input_osimx_file/>
        <data_directory>results/preprocessed</data_directory>
        <coordinate_list>{" ".join(sm.MUSCLE_COORDINATES)}</coordinate_list>
        <activation_muscle_groups/>
        <normalized_fiber_length_muscle_groups/>
        <MuscleTendonLengthInitialization><is_enabled>false</is_enabled></MuscleTendonLengthInitialization>
        <mtp_results_directory>results/mtp</mtp_results_directory>
        <max_iterations>3000</max_iterations>
        <RCNLCostTermSet>{terms}</RCNLCostTermSet>
        <RCNLSynergySet>
          <RCNLSynergy><muscle_group_name>{sm.SYNERGY_GROUP}</muscle_group_name><num_synergies>{n_synergies}</num_synergies></RCNLSynergy>
        </RCNLSynergySet>
      </NeuralControlPersonalizationTool>"""


def gcp_xml(subject: Subject, folder: Path) -> str:
    columns = {k: " ".join(f"{GRF_NAME}{s}{a}" for a in "xyz") for k, s in
               (("force", "_force_v"), ("center", "_force_p"), ("moment", "_torque_"))}
    markers = sm.FOOT_MARKERS
    # markers to 0.5 mm (the tutorials' 2 mm is for lab markers; these are noise-free): most
    # of the friction comes from slip slower than the latching velocity, where only mu_d x
    # slip speed counts and the foot kinematics set that speed; tighter marker tracking
    # brings the dynamic friction closer to the truth (docs/developing.md, "Pipeline: measurements")
    terms = lambda v, h, m: (_term("marker_position", 0.0005) + _term("rotation", 0.01)  # noqa: E731
                             + _term("vertical_grf", v) + _term("horizontal_grf", h)
                             + _term("ground_reaction_moment", m)
                             # as the original's tutorial: neighbouring springs alike (N/m); without it
                             # the heel-to-toe stiffness profile trades off against the foot
                             # kinematics (docs/developing.md, "Pipeline: measurements")
                             + _term("neighbor_spring_constant", 500))
    flags = ("<springConstants>true</springConstants><dampingFactor>true</dampingFactor>"
             "<dynamicFrictionCoefficient>true</dynamicFrictionCoefficient>"
             "<viscousFrictionCoefficient>true</viscousFrictionCoefficient>"
             "<restingSpringLength>{rest}</restingSpringLength>"
             "<kinematicsBSplineCoefficients>true</kinematicsBSplineCoefficients>")
    tasks = "".join(f"<GCPTask><is_enabled>true</is_enabled><index>{i}</index>{flags.format(rest=rest)}"
                    f"<RCNLCostTermSet>{terms(v, h, m)}</RCNLCostTermSet></GCPTask>"
                    for i, rest, v, h, m in ((1, "true", 5, 5, 2), (2, "false", 1, 1, 0.2)))
    return f"""<GroundContactPersonalizationTool>
        <results_directory>gcp</results_directory>
        <input_directory>results/preprocessed</input_directory>
        <input_model_file>{_relative(subject.generic_model, folder)}</input_model_file>
        <input_motion_file>IKData/{PREPROCESSED_TRIAL}.sto</input_motion_file>
        <input_grf_file>GRFData/{PREPROCESSED_TRIAL}.sto</input_grf_file>
        <kinematics_filter_cutoff>10</kinematics_filter_cutoff>
        <initialize_resting_spring_length>true</initialize_resting_spring_length>
        <GCPContactSurfaceSet>
          <GCPContactSurface name="right">
            <is_enabled>true</is_enabled><is_left_foot>false</is_left_foot>
            <start_time>{GCP_WINDOW[0]:g}</start_time><end_time>{GCP_WINDOW[1]:g}</end_time><belt_speed>0</belt_speed>
            <force_columns>{columns["force"]}</force_columns>
            <moment_columns>{columns["moment"]}</moment_columns>
            <electrical_center_columns>{columns["center"]}</electrical_center_columns>
            <hindfoot_body>calcn_r</hindfoot_body>
            <toe_marker>{markers["toe"]}</toe_marker><medial_marker>{markers["medial"]}</medial_marker>
            <lateral_marker>{markers["lateral"]}</lateral_marker><heel_marker>{markers["heel"]}</heel_marker>
            <midfoot_superior_marker>{markers["midfoot_superior"]}</midfoot_superior_marker>
          </GCPContactSurface>
        </GCPContactSurfaceSet>
        <GCPTaskList>{tasks}</GCPTaskList>
        <initial_resting_spring_length>0.02</initial_resting_spring_length>
        <initial_spring_constant>2500</initial_spring_constant>
        <initial_damping_factor>0.1</initial_damping_factor>
        <initial_dynamic_friction_coefficient>0.5</initial_dynamic_friction_coefficient>
        <initial_viscous_friction_coefficient>0.5</initial_viscous_friction_coefficient>
        <latching_velocity>0.05</latching_velocity>
        <max_iterations>60</max_iterations>
      </GroundContactPersonalizationTool>"""


def surrogate_xml(subject: Subject, folder: Path) -> str:
    return f"""<SurrogateDataTool>
        <results_directory>surrogate</results_directory>
        <input_model_file>{_relative(subject.generic_model, folder)}</input_model_file>
        <data_directory>results/preprocessed</data_directory>
        <trial_name>{PREPROCESSED_TRIAL}</trial_name>
        <coordinate_list>{" ".join(sm.MUSCLE_COORDINATES)}</coordinate_list>
        <samples_per_frame>10</samples_per_frame>
        <angular_padding>15</angular_padding>
        <frame_stride>2</frame_stride>
      </SurrogateDataTool>"""


SOLVER_XML = """<?xml version="1.0" encoding="UTF-8"?>
<NMSMPipelineDocument Version="1.5.3">
  <OptimalControlSolverSettings>
    <GpopsSettings>
      <setup_mesh_method>none</setup_mesh_method>
      <setup_mesh_phase_intervals>{intervals}</setup_mesh_phase_intervals>
      <setup_mesh_phase_colpoints_per_Interval>{points}</setup_mesh_phase_colpoints_per_Interval>
      <setup_nlp_solver>ipopt</setup_nlp_solver>
      <setup_nlp_linear_solver>mumps</setup_nlp_linear_solver>
      <setup_nlp_tolerance>{tolerance}</setup_nlp_tolerance>
      <setup_nlp_max_iterations>{max_iterations}</setup_nlp_max_iterations>
    </GpopsSettings>
  </OptimalControlSolverSettings>
</NMSMPipelineDocument>
"""
#: the example's mesh (one interval of 12 collocation points) and iteration limit
EXAMPLE_MESH = {"intervals": 1, "points": 12, "max_iterations": 300}
#: IPOPT tolerance of the example's solver files: TO and VO ``solver.xml``, DO ``solver_do.xml``
#: (Design Optimization applies at most 1e-6, ``solver_options.DESIGN_MAX_TOLERANCE``)
SOLVER_TOLERANCES = {"solver.xml": "1e-3", "solver_do.xml": "1e-6"}
#: the DO's "condition": strength (max isometric force scale) of the plantarflexors; the DO
#: tracks the VO's synergy commands as the VO does, so its change from the VO is the
#: predicted effect of the weakness alone (no compensation)
PLANTARFLEXORS = ("gastroc_r", "soleus_r")
PLANTARFLEXOR_STRENGTH = 0.7


def _treatment_common(subject: Subject, folder: Path, results: str, guess: str, tracked: str,
                      solver: str = "solver.xml") -> str:
    coordinates = " ".join(sm.MUSCLE_COORDINATES)
    return f"""<results_directory>{results}</results_directory>
        <initial_guess_directory>{guess}</initial_guess_directory>
        <tracked_quantities_directory>{tracked}</tracked_quantities_directory>
        <input_model_file>{_relative(subject.generic_model, folder)}</input_model_file>
        <input_osimx_file>results/gcp/personalized_mtp_ncp_gcp.osimx</input_osimx_file>
        <optimal_control_solver_settings_file>settings/{solver}</optimal_control_solver_settings_file>
        <trial_name>{PREPROCESSED_TRIAL}</trial_name>
        <states_coordinate_list>{coordinates}</states_coordinate_list>"""


def _synergy_controller(optimize_vectors: bool) -> str:
    coordinates = " ".join(sm.MUSCLE_COORDINATES)
    return f"""<RCNLSynergyController>
          <surrogate_model_coordinate_list>{coordinates}</surrogate_model_coordinate_list>
          <surrogate_model_data_directory>results/surrogate</surrogate_model_data_directory>
          <surrogate_model_polynomial_degree>3</surrogate_model_polynomial_degree>
          <optimize_synergy_vectors>{"true" if optimize_vectors else "false"}</optimize_synergy_vectors>
          <maximum_allowable_synergy_activation>5</maximum_allowable_synergy_activation>
        </RCNLSynergyController>"""


def _consistency() -> str:
    loads = " ".join(f"{c}_moment" for c in sm.MUSCLE_COORDINATES)
    return _constraint("kinetic_consistency", -1.0, 1.0, load_list=loads)


def _initial_state() -> str:
    """The TO's (VO's) initial state: VO and DO start where the motion they verify or change
    starts. Without it, controller tracking alone leaves the start free and the kinetic
    consistency band lets IPOPT settle anywhere on a flat objective."""
    coordinates = " ".join(sm.MUSCLE_COORDINATES)
    return (_constraint("initial_generalized_coordinate_deviation", -1e-3, 1e-3, coordinate_list=coordinates)
            + _constraint("initial_generalized_speed_deviation", -1e-2, 1e-2, coordinate_list=coordinates))


def _synergy_scale_term(n_synergies: int, scale: float) -> str:
    """A DO parameter term fixing the scale of every synergy's activation at ``scale``."""
    synergies = " ".join(f"{sm.SYNERGY_GROUP}_{k}" for k in range(1, n_synergies + 1))
    return (f"""<RCNLParameterTerm><type>synergy_activation_scale</type>
          <synergy_list>{synergies}</synergy_list>
          <initial_values>{scale:g}</initial_values><lower_bounds>{scale:g}</lower_bounds>
          <upper_bounds>{scale:g}</upper_bounds></RCNLParameterTerm>""")


def treatment_xml(kind: str, subject: Subject, folder: Path, n_synergies: int, *,
                  synergy_scale: float | None = None) -> str:
    """``to``, ``vo`` or ``do`` settings of the example (synergy-driven, foot springs from GCP).
    ``synergy_scale``: the DO also scales every synergy's activation by this (fixed) value."""
    coordinates = " ".join(sm.MUSCLE_COORDINATES)
    loads = " ".join(f"{c}_moment" for c in sm.MUSCLE_COORDINATES)
    muscles = " ".join(sm.MUSCLES)
    synergies = " ".join(f"{sm.SYNERGY_GROUP}_{k}" for k in range(1, n_synergies + 1))
    if kind == "to":
        common = _treatment_common(subject, folder, "to", "results/ncp", "results/preprocess")
        costs = (_term("generalized_coordinate_tracking", 0.05, coordinate_list=coordinates)
                 + _term("generalized_speed_tracking", 0.5, coordinate_list=coordinates)
                 + _term("inverse_dynamics_load_tracking", 10, load_list=loads)
                 + _term("muscle_activation_tracking", 0.1, muscle_list=muscles))
        return f"""<TrackingOptimizationTool>
        {common}
        {_synergy_controller(False)}
        <RCNLCostTermSet>{costs}</RCNLCostTermSet>
        <RCNLConstraintTermSet>{_consistency()}</RCNLConstraintTermSet>
      </TrackingOptimizationTool>"""
    if kind == "vo":
        common = _treatment_common(subject, folder, "vo", "results/to", "results/to")
        return f"""<VerificationOptimizationTool>
        {common}
        {_synergy_controller(False)}
        <RCNLCostTermSet>{_term("controller_tracking", 1.0, controller_list=synergies)}</RCNLCostTermSet>
        <RCNLConstraintTermSet>{_consistency()}{_initial_state()}</RCNLConstraintTermSet>
      </VerificationOptimizationTool>"""
    common = _treatment_common(subject, folder, "do", "results/vo", "results/vo", solver="solver_do.xml")
    strength = PLANTARFLEXOR_STRENGTH
    costs = _term("controller_tracking", 1.0, controller_list=synergies)  # as VO: only the strength differs
    functions = "scaleMaxIsometricForce" + (" scaleSynergyActivations" if synergy_scale is not None else "")
    scale = "" if synergy_scale is None else _synergy_scale_term(n_synergies, synergy_scale)
    return f"""<DesignOptimizationTool>
        {common}
        {_synergy_controller(False)}
        <model_functions>{functions}</model_functions>
        <RCNLParameterTermSet><RCNLParameterTerm><type>max_isometric_force_scale</type>
          <muscle_list>{" ".join(PLANTARFLEXORS)}</muscle_list>
          <initial_values>{strength:g}</initial_values><lower_bounds>{strength:g}</lower_bounds>
          <upper_bounds>{strength:g}</upper_bounds></RCNLParameterTerm>{scale}</RCNLParameterTermSet>
        <RCNLCostTermSet>{costs}</RCNLCostTermSet>
        <RCNLConstraintTermSet>{_consistency()}{_initial_state()}</RCNLConstraintTermSet>
      </DesignOptimizationTool>"""


def stage_blocks(subject: Subject, folder: Path, n_synergies: int) -> dict[str, str]:
    """``<Stage>`` elements by stage name."""
    jmp = _relative(subject.calibration_settings, folder)
    blocks = {
        "jmp": f"<settings_file>{jmp}</settings_file>",
        "passive": passive_xml(subject, folder),
        "analysis": analysis_xml(subject, folder),
        "preprocess": preprocess_xml(subject, folder),
        "mtp": mtp_xml(subject, folder),
        "ncp": ncp_xml(subject, folder, n_synergies),
        # GCP's tasks stop at their <max_iterations> residual evaluations (as the tutorials' do)
        # before scipy's tolerances: the example accepts those results, stamped as unconverged
        "gcp": "<accept_unconverged>true</accept_unconverged>\n      " + gcp_xml(subject, folder),
        "surrogate": surrogate_xml(subject, folder),
        "to": treatment_xml("to", subject, folder, n_synergies),
        "vo": treatment_xml("vo", subject, folder, n_synergies),
        "do": treatment_xml("do", subject, folder, n_synergies),
    }
    return {name: f'<Stage name="{name}">\n      {body}\n    </Stage>' for name, body in blocks.items()}


def write_example_pipeline(subject: Subject, folder: str | os.PathLike[str], *, n_synergies: int,
                           stages: tuple[str, ...] | None = None, results: str = "results") -> Path:
    """Write ``<folder>/pipeline.xml`` with ``stages`` (default: all available, in order)."""
    folder = Path(folder)
    (folder / "settings").mkdir(parents=True, exist_ok=True)
    for name, tolerance in SOLVER_TOLERANCES.items():
        (folder / "settings" / name).write_text(SOLVER_XML.format(tolerance=tolerance, **EXAMPLE_MESH),
                                                encoding="utf-8")
    blocks = stage_blocks(subject, folder, n_synergies)
    chosen = [s for s in (stages or STAGES) if s in blocks]
    body = "\n    ".join(blocks[s] for s in chosen)
    path = folder / "pipeline.xml"
    path.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- The built-in example: a synthetic subject from lab data to treatment (nmsm example). -->
<NMSMPipelineDocument Version="1.5.3">
  <PipelineTool name="synthetic subject">
    <results_directory>{results}</results_directory>
    <input_model_file>{_relative(subject.generic_model, folder)}</input_model_file>
    <StageList>
    {body}
    </StageList>
  </PipelineTool>
</NMSMPipelineDocument>
""", encoding="utf-8")
    return path
