"""``nmsm export``: personalized .osimx into a plain .osim that OpenSim loads, and a solution's
modeled ground reactions as ExternalLoads with which OpenSim's Inverse Dynamics tool
reproduces the solution's joint moments.

The "solution" is the synthetic subject's forward simulation: its motion, its foot springs'
forces (written as a treatment results folder writes them: force, point = midfoot marker at
the resting spring length, moment about it) and its joint moments (exactly the muscles',
by construction of the simulation)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.examples.subject import TRIAL_WINDOW, make_subject
from nmsm.interop.external_loads import reaction_from_resultant, write_external_loads
from nmsm.interop.osim_export import export_osimx, hunt_crossley_stiffness
from nmsm.interop.treatment_loads import export_treatment_loads, solution_reactions
from nmsm.io.osimx import OsimxModel, OsimxMuscle, OsimxSynergy, read_osimx, write_osimx
from nmsm.io.storage import read_storage, table_from_columns, write_storage


@pytest.fixture(scope="module")
def subject(tmp_path_factory):
    return make_subject(tmp_path_factory.mktemp("subject"))


def _personalized_osimx(subject, folder: Path) -> Path:
    truth = subject.truth
    contact = read_osimx(subject.true_contact)
    muscles = {name: OsimxMuscle(name=name, electromechanical_delay=10 * m["delay"],
                                 activation_time_constant=100 * m["activation_time_constant"],
                                 activation_nonlinearity_constant=m["nonlinearity"], emg_scale_factor=m["emg_scale"],
                                 optimal_fiber_length=1.1 * m["optimal_fiber_length"],
                                 tendon_slack_length=0.95 * m["tendon_slack_length"],
                                 max_isometric_force=0.8 * m["max_isometric_force"])
               for name, m in truth["muscles"].items()}
    path = folder / "subject_personalized.osimx"
    write_osimx(path, OsimxModel(name="synthetic_subject", associated_osim_model=str(subject.true_model),
                                 muscles=muscles, contact_surfaces=contact.contact_surfaces,
                                 synergies=(OsimxSynergy("RightLeg", 5),)))
    return path


def test_export_writes_parameters_and_contact(subject, tmp_path: Path) -> None:
    from nmsm.model.osim import load_model

    osimx = _personalized_osimx(subject, tmp_path)
    report = export_osimx(osimx, tmp_path / "exported.osim")
    model = load_model(report.model)
    truth = subject.truth["muscles"]
    for muscle in model.muscles:
        assert muscle.optimal_fiber_length == pytest.approx(1.1 * truth[muscle.name]["optimal_fiber_length"], rel=1e-12)
        assert muscle.tendon_slack_length == pytest.approx(0.95 * truth[muscle.name]["tendon_slack_length"], rel=1e-12)
        assert muscle.max_isometric_force == pytest.approx(0.8 * truth[muscle.name]["max_isometric_force"], rel=1e-12)
    springs = len(read_osimx(subject.true_contact).contact_surfaces[0].springs)
    assert report.contact_spheres == springs
    assert len(model.contact_forces) == springs and len(model.contact_geometry) == springs + 1
    assert any("synergy" in n for n in report.notes) and any("delays" in n for n in report.notes)
    # the exported Hunt-Crossley sphere gives the spring's force K d at the reference depth
    force = model.contact_forces[0]
    sphere = model.contact_geometry[force.sphere]
    spring = read_osimx(subject.true_contact).contact_surfaces[0].springs[0]
    assert force.stiffness == pytest.approx(hunt_crossley_stiffness(spring.spring_constant, sphere.radius))
    depth = 0.005
    hertz = 4 / 3 * force.stiffness / (2 * np.sqrt(2)) * np.sqrt(sphere.radius) * depth**1.5
    assert hertz == pytest.approx(spring.spring_constant * depth, rel=1e-9)


def test_export_never_overwrites_its_input(subject, tmp_path: Path) -> None:
    osimx = _personalized_osimx(subject, tmp_path)
    with pytest.raises(InputError, match="overwrite its input model"):
        export_osimx(osimx, subject.true_model)


@pytest.mark.opensim
def test_exported_model_loads_in_opensim(subject, bridge, tmp_path: Path) -> None:
    osimx = _personalized_osimx(subject, tmp_path)
    report = export_osimx(osimx, tmp_path / "exported.osim")
    summary = bridge.call("exported_model_summary", path=str(report.model))
    truth = subject.truth["muscles"]
    assert set(summary["muscles"]) == set(truth)
    for name, values in summary["muscles"].items():
        assert values["optimal_fiber_length"] == pytest.approx(1.1 * truth[name]["optimal_fiber_length"], rel=1e-12)
        assert values["activation_time_constant"] == pytest.approx(truth[name]["activation_time_constant"], rel=1e-12)
        assert values["deactivation_time_constant"] == pytest.approx(4 * truth[name]["activation_time_constant"],
                                                                     rel=1e-12)
    springs = report.contact_spheres
    assert summary["contact_geometry"] == springs + 1
    assert summary["forces"]["SmoothSphereHalfSpaceForce"] == springs
    # default pose: the sole is on the floor, within the resting length: the contact pushes up
    assert summary["contact_force"][1] > 10.0


def _solution_folder(subject, folder: Path) -> tuple[Path, np.ndarray, np.ndarray]:
    """A treatment-like results folder of the simulation: IKData (deg), GRFData with the
    .osimx columns (force, midfoot point at y = L0, moment about it). Returns the folder,
    the times and the simulation's hip/knee/ankle moments on them."""
    from nmsm.model.casadi_model import CasadiModel
    from nmsm.model.osim import load_model

    simulation = np.load(subject.folder / "truth" / "simulation.npz")
    keep = np.arange(0, simulation["time"].size, 2)  # 1 kHz
    time = simulation["time"][keep]
    q = simulation["q"][keep]
    model = load_model(subject.true_model)
    rotational = [c.motion_type == "rotational" for c in model.coordinates]
    degrees = np.where(rotational, np.degrees(q), q)
    (folder / "IKData").mkdir(parents=True)
    write_storage(folder / "IKData" / "gait.sto",
                  table_from_columns(time, dict(zip(model.coordinate_names, degrees.T)), in_degrees=True))
    surface = read_osimx(subject.true_contact).contact_surfaces[0]
    midfoot = np.array(CasadiModel(model).marker_function([surface.midfoot_superior_marker]).map(time.size)(q.T)).T
    point = np.column_stack([midfoot[:, 0], np.full(time.size, surface.resting_spring_length), midfoot[:, 2]])
    force, moment_origin = simulation["force"][keep], simulation["moment"][keep]
    moment = moment_origin - np.cross(point, force)
    columns = {}
    for names, values in ((surface.force_columns, force), (surface.electrical_center_columns, point),
                          (surface.moment_columns, moment)):
        columns.update(dict(zip(names, values.T)))
    (folder / "GRFData").mkdir()
    write_storage(folder / "GRFData" / "gait.sto", table_from_columns(time, columns))
    return folder, time, simulation["muscle_moments"][keep]


@pytest.mark.opensim
def test_opensim_id_with_exported_loads_reproduces_the_joint_moments(subject, bridge, tmp_path: Path) -> None:
    osimx = _personalized_osimx(subject, tmp_path)
    model = export_osimx(osimx, tmp_path / "no_contact.osim", include_contact=False).model
    solution, time, moments = _solution_folder(subject, tmp_path / "solution")
    xml, data = export_treatment_loads(solution, osimx, tmp_path / "loads.xml")
    assert xml.is_file() and data.is_file()
    out = tmp_path / "opensim_id.sto"
    bridge.call("oracle_inverse_dynamics_tool", model_path=str(model),
                coordinates_file=str(solution / "IKData" / "gait.sto"), output_file=str(out),
                external_loads_file=str(xml), lowpass_hz=-1.0)
    table = read_storage(out)
    window = (table.time >= TRIAL_WINDOW[0]) & (table.time <= TRIAL_WINDOW[1])
    for k, coordinate in enumerate(("hip_flexion_r", "knee_angle_r", "ankle_angle_r")):
        expected = np.interp(table.time[window], time, moments[:, k])
        rms = np.sqrt(np.mean((table.column(f"{coordinate}_moment")[window] - expected) ** 2))
        print(f"{coordinate}: OpenSim ID vs the solution's moments {rms:.4f} N m RMS")
        assert rms < 1.0, f"{coordinate}: OpenSim ID differs from the solution by {rms:.3f} N m RMS"


def test_solution_loads_bad_input(subject, tmp_path: Path) -> None:
    osimx = _personalized_osimx(subject, tmp_path)
    with pytest.raises(InputError, match="no GRFData folder"):
        solution_reactions(tmp_path, osimx)
    solution, _, _ = _solution_folder(subject, tmp_path / "solution")
    no_contact = tmp_path / "no_contact.osimx"
    write_osimx(no_contact, OsimxModel(name="x", associated_osim_model=str(subject.true_model)))
    with pytest.raises(InputError, match="no contact surface"):
        solution_reactions(solution, no_contact)


def test_reaction_from_resultant_round_trip(tmp_path: Path) -> None:
    time = np.linspace(0, 1, 11)
    force = np.column_stack([20 * np.sin(time), 600 * np.ones(11), -5 * time])
    force[0, 1] = 1.0  # below the threshold: swing
    point = np.column_stack([0.3 + 0.1 * time, np.zeros(11), 0.08 * np.ones(11)])
    free = np.column_stack([np.zeros(11), 2 * time, np.zeros(11)])
    moment = np.cross(point, force) + free
    reaction = reaction_from_resultant("g", "calcn_r", time, force, moment)
    assert np.isnan(reaction.point[0]).all() and np.all(reaction.force[0] == 0)
    assert np.allclose(reaction.point[1:], point[1:]) and np.allclose(reaction.torque[1:], free[1:])
    xml, data = write_external_loads(tmp_path / "loads.xml", [reaction])
    from nmsm.model.external_loads import read_external_loads

    loads = read_external_loads(xml)
    assert loads.data_file == data.resolve() or loads.data_file.resolve() == data.resolve()
    assert loads.forces[0].body == "calcn_r" and loads.forces[0].point_identifier == "g_force_p"


@pytest.mark.parametrize("error", ["disk", "stop"])
def test_export_writes_the_model_and_the_loads_all_or_none(error: str, subject, tmp_path: Path, capsys,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """``nmsm export -o MODEL --treatment DIR --loads LOADS.xml`` fails writing the XML, after
    the .osim and the .mot: none of the three is left, the earlier .mot is unchanged; then the
    three are written together."""
    from nmsm.cli import main

    osimx = _personalized_osimx(subject, tmp_path)
    solution, _, _ = _solution_folder(subject, tmp_path / "solution")
    out = tmp_path / "out"
    out.mkdir()
    (out / "loads.mot").write_text("earlier\n")
    argv = ["export", str(osimx), "-o", str(out / "model.osim"), "--no-contact", "--treatment", str(solution),
            "--loads", str(out / "loads.xml")]
    real = Path.write_bytes
    calls: list[Path] = []

    def failing(self: Path, data: bytes) -> int:
        calls.append(self)
        if self.suffix == ".xml":
            raise KeyboardInterrupt if error == "stop" else OSError(28, "No space left on device", str(self))
        return real(self, data)

    capsys.readouterr()
    with monkeypatch.context() as patch:
        patch.setattr(Path, "write_bytes", failing)
        assert main(argv) == (130 if error == "stop" else 1)
    assert [p.name for p in calls] == ["loads.xml"]
    if error == "disk":
        assert f"nmsm: error: {out / 'loads.xml'}: cannot write the output file: No space left on device" \
               in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["loads.mot"]  # no .osim, no staging folder
    assert (out / "loads.mot").read_text() == "earlier\n"
    assert main(argv) == 0
    assert sorted(p.name for p in out.iterdir()) == ["loads.mot", "loads.xml", "model.osim"]
    assert "<datafile>loads.mot</datafile>" in (out / "loads.xml").read_text()
    assert read_storage(out / "loads.mot").n_rows > 100
