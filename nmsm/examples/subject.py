"""The built-in synthetic subject: one lab visit generated in code, with known answers.

:func:`make_subject` writes into a folder::

    subject/model.osim               the generic model the pipeline starts from (joint frames
                                     of knee and ankle rotated, muscle lengths off)
    subject/calibration/markers.trc  a range-of-motion trial (JMP), from
                                     :func:`nmsm.examples.synthetic_jmp.make_synthetic_jmp_case`
    subject/calibration/JMPSettings.xml
    subject/gait.trc                 markers of the simulated gait (100 Hz, mm)
    subject/gait_grf.mot, .xml       its ground reactions (1000 Hz) and their ExternalLoads
    subject/gait_emg.mot             raw EMG of the eight channels (1000 Hz, mV, -0.3-1.2 s)
    subject/passive/<trial>.trc      passive trials (MTLI): markers of slow sweeps of the
    subject/passive/<trial>_moments.sto   relaxed leg and the joint moments (N m) a
                                     dynamometer measures (:mod:`nmsm.examples.subject_passive`)
    truth/true.osim                  the subject's true model
    truth/true_contact.osimx         the true foot springs
    truth/truth.json                 every known parameter (:func:`read_truth`)
    truth/simulation.npz             the simulated states, activations, loads

The gait comes from the project's own forward simulation of the true model
(:mod:`nmsm.examples.subject_simulation`): muscles driven by synergies through Hill-type
muscles with activation dynamics, the foot on Ground Contact Personalization's springs.
Everything uses nmsm's model core only (no OpenSim), a few seconds of work.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.examples import subject_model as sm
from nmsm.examples import subject_truth as st
from nmsm.examples.subject_motion import HEEL_STRIKE, foot_pose, leg_inverse_kinematics

#: simulated span (s); the span of the EMG recording (before the simulation starts the
#: excitations hold their initial values, so filtering transients stay out of the trials);
#: the gait trial (heel strike, stance, toe-off) the personalization and treatment tools
#: use, and GCP's window
SIMULATION = (0.0, 1.05)
EMG_SPAN = (-0.3, 1.2)
TRIAL_WINDOW = (0.21, 0.79)
GCP_WINDOW = (0.21, 0.79)
#: sample rates (Hz) of the marker, force-plate and EMG files
MARKER_RATE, ANALOG_RATE = 100.0, 1000.0
#: EMG envelope low-pass cutoff (Hz) of the example's preprocessing
EMG_LOW_PASS = 30.0
GRF_NAME = "ground"  # columns ground_force_vx ... ground_torque_z
TRIAL = "gait"


@attrs.frozen
class Subject:
    """Paths of a generated subject and its truth (:func:`read_truth` of ``truth_file``)."""

    folder: Path
    generic_model: Path
    true_model: Path
    calibration_settings: Path
    calibration_markers: Path
    gait_markers: Path
    grf_file: Path
    external_loads: Path
    emg_file: Path
    truth_file: Path
    true_contact: Path
    passive_folder: Path

    @property
    def passive_trials(self) -> list[tuple[str, Path, Path]]:
        """``(name, markers .trc, moments .sto)`` of each passive trial."""
        from nmsm.examples.subject_passive import PASSIVE_TRIALS

        return [(name, self.passive_folder / f"{name}.trc", self.passive_folder / f"{name}_moments.sto")
                for name in PASSIVE_TRIALS]

    @property
    def truth(self) -> dict[str, Any]:
        return read_truth(self.truth_file)


def subject_in(folder: str | os.PathLike[str]) -> Subject | None:
    """The subject :func:`make_subject` wrote into ``folder``, or None when there is none."""
    folder = Path(folder)
    inputs, truth = folder / "subject", folder / "truth"
    subject = Subject(folder=folder, generic_model=inputs / "model.osim", true_model=truth / "true.osim",
                      calibration_settings=inputs / "calibration" / "JMPSettings.xml",
                      calibration_markers=inputs / "calibration" / "markers.trc", gait_markers=inputs / f"{TRIAL}.trc",
                      grf_file=inputs / f"{TRIAL}_grf.mot", external_loads=inputs / f"{TRIAL}_grf.xml",
                      emg_file=inputs / f"{TRIAL}_emg.mot", truth_file=truth / "truth.json",
                      true_contact=truth / "true_contact.osimx", passive_folder=inputs / "passive")
    paths = [getattr(subject, f.name) for f in attrs.fields(Subject) if f.name not in ("folder", "passive_folder")]
    paths += [p for _, markers, moments in subject.passive_trials for p in (markers, moments)]
    return subject if all(Path(p).is_file() for p in paths) else None


def read_truth(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The truth file's content (see :func:`make_subject`)."""
    return json.loads(Path(path).read_text(encoding="utf-8"))


def _contact_surface(model, layout, constants):
    from nmsm.io.osimx import GcpSpring, OsimxContactSurface

    columns = {k: tuple(f"{GRF_NAME}{s}{a}" for a in "xyz") for k, s in
               (("force", "_force_v"), ("center", "_force_p"), ("moment", "_torque_"))}
    springs = tuple(GcpSpring(name, body, tuple(float(v) for v in location), float(k))
                    for name, body, location, k in zip(layout.names, layout.bodies, layout.locations, constants))
    return OsimxContactSurface(
        is_left_foot=False, belt_speed=0.0, force_columns=columns["force"], moment_columns=columns["moment"],
        electrical_center_columns=columns["center"], hindfoot_body="calcn_r",
        toe_marker=sm.FOOT_MARKERS["toe"], medial_marker=sm.FOOT_MARKERS["medial"],
        lateral_marker=sm.FOOT_MARKERS["lateral"], heel_marker=sm.FOOT_MARKERS["heel"],
        midfoot_superior_marker=sm.FOOT_MARKERS["midfoot_superior"], springs=springs, **st.CONTACT)


def effective_emg_scales(emg_time: np.ndarray, raw: np.ndarray, time: np.ndarray, excitation: np.ndarray,
                         delays: list[float]) -> list[float]:
    """Per channel, the factor ``s`` with ``s * EMG(t - delay) = e(t)`` in the least-squares
    sense over the trial window, ``EMG`` the raw recording processed as the example's
    preprocessing processes it (high-pass 40 Hz, rectified, low-pass :data:`EMG_LOW_PASS`,
    normalized by its maximum): the EMG scale factor MTP should find."""
    from nmsm.io.storage import Table
    from nmsm.tools.pipeline.preprocess_stage import process_emg

    envelope = process_emg(Table(time=emg_time, labels=tuple(str(k) for k in range(raw.shape[1])), data=raw),
                           40.0, EMG_LOW_PASS, 4)
    window = (time >= TRIAL_WINDOW[0]) & (time <= TRIAL_WINDOW[1])
    out = []
    for k, delay in enumerate(delays):
        recorded = np.interp(time[window] - delay, emg_time, envelope[:, k])
        out.append(float(recorded @ excitation[window, k] / (recorded @ recorded)))
    return out


def _write_passive_trials(folder: Path, model: Any, casadi_model: Any, muscles: Sequence[st.MuscleTruth]) -> Path:
    """Markers (100 Hz, of ``casadi_model`` built on the true ``model``) and the measured joint
    moments of each passive trial, written into ``folder``."""
    from nmsm.examples.subject_data import marker_table
    from nmsm.examples.subject_passive import PASSIVE_DURATION, PASSIVE_TRIALS, passive_moments, passive_poses
    from nmsm.io.storage import table_from_columns, write_storage
    from nmsm.io.trc import write_trc

    folder.mkdir(parents=True, exist_ok=True)
    time = np.round(np.arange(0.0, PASSIVE_DURATION + 1e-9, 1.0 / MARKER_RATE), 9)
    for name in PASSIVE_TRIALS:
        q = passive_poses(model.coordinate_names, name, time, sm.STANDING_HEIGHT)
        write_trc(folder / f"{name}.trc", marker_table(casadi_model, model.marker_names, time, q), units="mm")
        moments = passive_moments(model, muscles, q)
        columns = {f"{c}_moment": moments[:, k] for k, c in enumerate(sm.MUSCLE_COORDINATES)}
        write_storage(folder / f"{name}_moments.sto",
                      table_from_columns(time, columns, name="passive joint moments (N m)"))
    return folder


def make_subject(folder: str | os.PathLike[str], *, seed: int = 0, log=None) -> Subject:
    """Generate the subject into ``folder`` (see module docstring); ``log``: progress lines.

    The files are written into a staging folder inside ``folder`` and moved into place all or
    none when every one is complete (:class:`~nmsm.core.results.ResultsDirectory`, as results
    are): a stop, a kill or a full disk while generating never leaves a truncated subject that
    :func:`subject_in` would take as complete.
    """
    from nmsm.core.results import ResultsDirectory

    say = log or (lambda text: None)
    folder = Path(folder)
    with ResultsDirectory(folder).task("subject") as stage:
        peak = _write_subject(stage, seed=seed, say=say)
    subject = subject_in(folder)
    if subject is None:
        raise RuntimeError(f"{folder}: the subject's files were moved into place but are incomplete")
    say(f"subject written to {folder} (peak vertical ground reaction {peak:.0f} N)")
    return subject


def _write_subject(folder: Path, *, seed: int, say: Any) -> float:
    """Write the subject's files into ``folder``; returns the peak vertical ground reaction (N)."""
    from nmsm.examples.subject_data import (excitations_from_activations, ground_reaction, marker_table,
                                            raw_emg)
    from nmsm.examples.subject_simulation import (MuscleArrays, SubjectDynamics, design_synergies,
                                                  reference_from_samples, simulate)
    from nmsm.examples.synthetic_jmp import make_synthetic_jmp_case
    from nmsm.interop.external_loads import write_external_loads
    from nmsm.io.osimx import OsimxModel, write_osimx
    from nmsm.io.storage import table_from_columns, write_storage
    from nmsm.io.trc import write_trc
    from nmsm.model.casadi_model import CasadiModel
    from nmsm.model.foot_contact import ContactSurfaceModel
    from nmsm.model.muscle_geometry import MuscleGeometry
    from nmsm.model.osim import load_model
    from nmsm.tools.gcp.foot_model import FootMarkers, FootModel
    from nmsm.tools.gcp.spring_grid import place_springs

    inputs, truth_dir = folder / "subject", folder / "truth"
    inputs.mkdir(parents=True, exist_ok=True)
    truth_dir.mkdir(parents=True, exist_ok=True)
    optimal = {name: spec.optimal_fiber_length for name, spec in sm.MUSCLES.items()}

    # reference gait and the tendon slack lengths that put fibers near optimal length on it
    geometry_file = truth_dir / "geometry.osim"
    geometry_file.write_bytes(sm.subject_model_xml(optimal, {m: 0.0 for m in sm.MUSCLES}))
    model = load_model(geometry_file)
    names = model.coordinate_names
    coarse = np.round(np.arange(SIMULATION[0] - 0.2, SIMULATION[1] + 0.2 + 1e-9, 0.005), 9)
    pose = foot_pose(coarse, sm.MARKERS["R_Heel"][1], sm.MTP_JOINT, sm.SOLE_DEPTH)
    reference_q = leg_inverse_kinematics(model, coarse, pose, sm.STANDING_HEIGHT)
    fine = np.round(np.arange(SIMULATION[0] - 0.1, SIMULATION[1] + 0.1 + 1e-9, 0.00025), 9)
    reference = reference_from_samples(coarse, reference_q, names, fine)
    cycle = (fine >= HEEL_STRIKE) & (fine < HEEL_STRIKE + 1.1)
    lengths_f = MuscleGeometry(model, list(sm.MUSCLES), list(sm.MUSCLE_COORDINATES)).function().map(int(cycle.sum()))
    lengths = np.array(lengths_f(reference.q[cycle].T, reference.u[cycle].T)[0]).T
    tendon_slack = st.tendon_slack_lengths(lengths)
    geometry_file.unlink()
    muscles = st.muscle_truths(tendon_slack)

    # the true model, its springs, the generic model
    true_model = truth_dir / "true.osim"
    true_model.write_bytes(sm.subject_model_xml(optimal, tendon_slack))
    model = load_model(true_model)
    foot = FootModel(model, "calcn_r", FootMarkers(**sm.FOOT_MARKERS), False)
    layout = place_springs(foot, 5, 15, spring_height=-sm.SOLE_DEPTH)
    along = np.array([foot.points_in_hindfoot([point])[0][0] for point in layout.points()])
    constants = st.spring_constants(along)
    surface = _contact_surface(model, layout, constants)
    true_contact = truth_dir / "true_contact.osimx"
    write_osimx(true_contact, OsimxModel(name=model.name, associated_osim_model="true.osim",
                                         contact_surfaces=(surface,)))
    generic_optimal, generic_slack = st.generic_lengths(muscles)
    generic_model = inputs / "model.osim"
    generic_model.write_bytes(sm.subject_model_xml(generic_optimal, generic_slack, st.generic_frame_orientations(),
                                                   name="generic_subject"))

    # forward simulation
    say("simulating the subject's gait (nmsm model core, muscles, foot springs)")
    dynamics = SubjectDynamics(model, MuscleArrays.of(muscles), ContactSurfaceModel.from_osimx(surface, model))
    design_time = np.round(np.arange(SIMULATION[0], SIMULATION[1] + 1e-9, 0.005), 9)
    design = design_synergies(dynamics, reference, design_time, st.N_SYNERGIES)
    simulation = simulate(dynamics, reference, design.weights, *SIMULATION)

    # recordings
    cm = CasadiModel(model)
    marker_times = np.round(np.arange(SIMULATION[0], SIMULATION[1] + 1e-9, 1.0 / MARKER_RATE), 9)
    marker_index = np.searchsorted(simulation.time, marker_times - 1e-9)
    gait_markers = inputs / f"{TRIAL}.trc"
    write_trc(gait_markers, marker_table(cm, model.marker_names, marker_times, simulation.q[marker_index]),
              units="mm")
    analog_times = np.round(np.arange(SIMULATION[0], SIMULATION[1] + 1e-9, 1.0 / ANALOG_RATE), 9)
    analog_index = np.searchsorted(simulation.time, analog_times - 1e-9)
    reaction = ground_reaction(GRF_NAME, "calcn_r", analog_times, simulation.force[analog_index],
                               simulation.moment[analog_index])
    write_external_loads(inputs / f"{TRIAL}_grf.xml", [reaction], inputs / f"{TRIAL}_grf.mot")
    arrays = MuscleArrays.of(muscles)
    excitation, clipped = excitations_from_activations(simulation.time, simulation.a, arrays.tau_a,
                                                      arrays.nonlinearity)
    delays = [m.delay for m in muscles]
    emg_times = np.round(np.arange(EMG_SPAN[0], EMG_SPAN[1] + 1e-9, 1.0 / ANALOG_RATE), 9)
    emg, gains = raw_emg(simulation.time, excitation, delays, emg_times, seed=seed)  # before the start: e(0)
    emg_file = inputs / f"{TRIAL}_emg.mot"
    write_storage(emg_file, table_from_columns(emg_times, {m.channel: emg[:, k] for k, m in enumerate(muscles)},
                                               name="raw EMG (mV)"))

    # the range-of-motion trial for JMP (its own generator, on the true model)
    say("writing the range-of-motion trial for JMP")
    jmp_case = make_synthetic_jmp_case(inputs / "calibration", model_file=true_model, knee="knee_r", ankle="ankle_r",
                                       seed=seed, duration=2.0)

    say("writing the passive trials for MTLI")
    _write_passive_trials(inputs / "passive", model, cm, muscles)

    # truth
    np.savez_compressed(truth_dir / "simulation.npz", time=simulation.time, q=simulation.q, u=simulation.u,
                        udot=simulation.udot, a=simulation.a, c=simulation.c, e=excitation, force=simulation.force,
                        moment=simulation.moment, muscle_moments=simulation.moments, coordinates=np.array(names))
    emg_scale = effective_emg_scales(emg_times, emg, simulation.time, excitation, delays)
    truth = {
        "trial": TRIAL, "trial_window": list(TRIAL_WINDOW), "gcp_window": list(GCP_WINDOW),
        "coordinates": list(sm.MUSCLE_COORDINATES),
        "joints": {label: float(value) for label, value in jmp_case.truth.items()},
        "muscles": {m.name: {**attrs.asdict(m), "emg_scale": emg_scale[k], "emg_gain_mV": float(gains[k])}
                    for k, m in enumerate(muscles)},
        "excitation_clipping": clipped,
        "synergy_group": sm.SYNERGY_GROUP,
        "synergy_weights": design.weights.tolist(),
        "muscle_order": list(sm.MUSCLES),
        "contact": {**st.CONTACT, "springs": [
            {"name": s.name, "body": s.parent_body, "location": list(s.location), "spring_constant": s.spring_constant}
            for s in surface.springs]},
        "peak_vertical_force": float(simulation.force[:, 1].max()),
    }
    (truth_dir / "truth.json").write_text(json.dumps(truth, indent=1), encoding="utf-8")
    return float(truth["peak_vertical_force"])
