"""A personalized ``.osimx`` folded into a plain OpenSim model (``nmsm export``).

What goes where:

* MTP/NCP muscle parameters: ``optimal_fiber_length``, ``tendon_slack_length`` and
  ``max_isometric_force`` replace the model's values (:class:`~nmsm.model.osim_writer.OsimWriter`,
  every other byte of the file kept); the activation time constant becomes the muscle's
  ``activation_time_constant`` (s) and 4x it its ``deactivation_time_constant``, as NMSM's
  activation model assumes.
* GCP contact surfaces: one ``ContactSphere`` per spring (on the spring's body, at its
  location, radius = the resting spring length, so contact starts where the GCP spring
  does) and a ``SmoothSphereHalfSpaceForce`` against a ``floor`` ``ContactHalfSpace``.
  OpenSim's Hunt-Crossley force grows as depth^1.5, GCP's spring linearly: the plane-strain
  stiffness is chosen so that both give ``K * d`` at the reference depth ``d_ref``
  (``reference_depth``, 5 mm): ``E = K (3 sqrt(2) / 2) / sqrt(r d_ref)``; dissipation
  ``2 D / 3`` (GCP's ``1 - D v`` vs Hunt-Crossley's ``1 + 3/2 c v`` with downward v),
  static and dynamic friction ``mu_d``, viscous friction ``mu_v``, transition velocity the
  latching velocity.
* Not representable in OpenSim, listed in :attr:`ExportReport.notes` and in an XML comment:
  electromechanical delays, activation nonlinearity, EMG scale factors, synergy groups
  (NMSM's synergy controller has no OpenSim counterpart), and the exact GCP force law.

The writer never overwrites its input model.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import attrs
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.names import close_matches
from nmsm.io.xml_input import xml_parser
from nmsm.io.osimx import (
    OsimxContactSurface,
    OsimxModel,
    check_contact_surfaces,
    check_muscles_in_model,
    read_osimx,
)
from nmsm.model.hill import time_constants_from_osimx
from nmsm.model.osim_writer import OsimWriter, format_number, format_vector
from nmsm.model.parse_forces import MUSCLE_TAGS

#: depth (m) at which exported Hunt-Crossley contact matches the GCP spring's force
REFERENCE_DEPTH = 0.005
FLOOR = "floor"


@attrs.frozen
class ExportReport:
    """What :func:`export_osimx` wrote and what it could not represent."""

    model: Path
    muscles: tuple[str, ...]
    contact_spheres: int
    notes: tuple[str, ...]

    def text(self) -> str:
        lines = [f"wrote {self.model}", f"  muscle parameters of {len(self.muscles)} muscles",
                 f"  {self.contact_spheres} contact spheres with SmoothSphereHalfSpaceForce"]
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def associated_model(osimx_path: Path, osimx: OsimxModel) -> Path:
    """The ``.osim`` an ``.osimx`` names (relative to the ``.osimx`` folder)."""
    text = osimx.associated_osim_model.strip().replace("\\", "/")
    path = Path(text)
    if not path.is_absolute():
        path = osimx_path.parent / path
    if not path.is_file():
        raise InputError(f"the associated model '{text}' does not exist", file=osimx_path,
                         element="<associated_osim_model>", expected="an existing .osim (or give the model explicitly)")
    return path


def hunt_crossley_stiffness(spring_constant: float, radius: float, reference_depth: float = REFERENCE_DEPTH) -> float:
    """Plane-strain modulus (Pa) whose smooth Hunt-Crossley force equals ``K d`` at ``d_ref``."""
    return spring_constant * 1.5 * math.sqrt(2.0) / math.sqrt(radius * reference_depth)


def _sub(parent: etree._Element, tag: str, text: str | None = None, **attributes: str) -> etree._Element:
    element = etree.SubElement(parent, tag, **attributes)
    if text is not None:
        element.text = text
    return element


def _model_element(root: etree._Element, file: Path) -> etree._Element:
    model = root.find("Model")
    if model is None:
        raise InputError("no <Model> element", file=file, expected="an OpenSim 4 model file")
    return model


def _set_child(element: etree._Element, tag: str, text: str) -> None:
    child = element.find(tag)
    if child is None:
        child = _sub(element, tag)
    child.text = text


def _activation_constants(model: etree._Element, osimx: OsimxModel) -> list[str]:
    done = []
    for muscle in model.iter():
        name = muscle.get("name")
        if name not in osimx.muscles or muscle.find("GeometryPath") is None:
            continue
        value = osimx.muscles[name].activation_time_constant
        if value is None:
            continue
        tau_a, tau_d = time_constants_from_osimx(value)
        _set_child(muscle, "activation_time_constant", format_number(tau_a))
        _set_child(muscle, "deactivation_time_constant", format_number(tau_d))
        done.append(name)
    return done


def _container(model: etree._Element, tag: str, name: str) -> etree._Element:
    """The ``objects`` list of the model's ``<tag name=...>`` set (created if absent)."""
    found = model.find(tag)
    if found is None:
        found = _sub(model, tag, name=name)
    objects = found.find("objects")
    if objects is None:
        objects = _sub(found, "objects")
    return objects


def _add_contact(model: etree._Element, surfaces: tuple[OsimxContactSurface, ...], reference_depth: float) -> int:
    geometry = _container(model, "ContactGeometrySet", "contactgeometryset")
    forces = _container(model, "ForceSet", "forceset")
    if not any(g.get("name") == FLOOR for g in geometry):
        floor = _sub(geometry, "ContactHalfSpace", name=FLOOR)
        _sub(floor, "socket_frame", "/ground")
        _sub(floor, "location", "0 0 0")
        _sub(floor, "orientation", format_vector([0.0, 0.0, -math.pi / 2]))
    count = 0
    for k, surface in enumerate(surfaces, start=1):
        radius = surface.resting_spring_length
        prefix = f"gcp{k}_{surface.hindfoot_body}"
        for spring in surface.springs:
            sphere_name = f"{prefix}_{spring.name}"
            sphere = _sub(geometry, "ContactSphere", name=sphere_name)
            _sub(sphere, "socket_frame", f"/bodyset/{spring.parent_body}")
            _sub(sphere, "location", format_vector(spring.location))
            _sub(sphere, "orientation", "0 0 0")
            _sub(sphere, "radius", format_number(radius))
            force = _sub(forces, "SmoothSphereHalfSpaceForce", name=f"{sphere_name}_force")
            _sub(force, "socket_sphere", f"/contactgeometryset/{sphere_name}")
            _sub(force, "socket_half_space", f"/contactgeometryset/{FLOOR}")
            _sub(force, "stiffness", format_number(hunt_crossley_stiffness(spring.spring_constant, radius,
                                                                        reference_depth)))
            _sub(force, "dissipation", format_number(2.0 * surface.damping_factor / 3.0))
            _sub(force, "static_friction", format_number(surface.dynamic_friction_coefficient))
            _sub(force, "dynamic_friction", format_number(surface.dynamic_friction_coefficient))
            _sub(force, "viscous_friction", format_number(surface.viscous_friction_coefficient))
            _sub(force, "transition_velocity", format_number(surface.latching_velocity))
            count += 1
    return count


def _check_spring_bodies(osimx: OsimxModel, bodies: list[str], osimx_path: Path, source: Path) -> None:
    """Each spring's ``parent_body`` is a body of the model: the contact sphere's frame (an unknown
    one was written as ``/bodyset/<name>`` and the exported model failed to load in OpenSim)."""
    for k, surface in enumerate(osimx.contact_surfaces, start=1):
        for spring in surface.springs:
            if spring.parent_body in bodies:
                continue
            close = close_matches(spring.parent_body, bodies, n=3)
            hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
            raise InputError(
                f"the parent body '{spring.parent_body}' of spring '{spring.name}' (contact surface {k}) is not a "
                f"body of the model {source}{hint}",
                file=osimx_path, element="<parent_body>", expected="a body of the model: " + ", ".join(bodies))


def export_osimx(osimx_path: str | os.PathLike[str], output: str | os.PathLike[str], *,
                 model_path: str | os.PathLike[str] | None = None, include_contact: bool = True,
                 reference_depth: float = REFERENCE_DEPTH) -> ExportReport:
    """Write ``output`` (.osim): the model of ``osimx_path`` (or ``model_path``) with the
    personalized quantities it can hold (see module docstring)."""
    osimx_path = Path(osimx_path)
    osimx = read_osimx(osimx_path)
    source = Path(model_path) if model_path is not None else associated_model(osimx_path, osimx)
    output = Path(output)
    if output.resolve() == source.resolve():
        raise InputError("the export would overwrite its input model", file=output,
                         expected="another output file name")
    if include_contact:
        check_contact_surfaces(osimx)
        for surface in osimx.contact_surfaces:
            if not surface.resting_spring_length > 0:  # the sphere radius (module docstring)
                raise InputError(
                    f"the resting spring length {surface.resting_spring_length:g} m of the contact surface on "
                    f"'{surface.hindfoot_body}' is not positive: it cannot be an OpenSim contact sphere's radius",
                    file=osimx_path, element="<resting_spring_length>",
                    expected="--no-contact to export the model without the foot contact "
                             "(apply the ground reactions as ExternalLoads)")
    writer = OsimWriter(source)
    # every RCNLMuscle, also one holding only what OpenSim cannot hold (delays, EMG scales):
    # such an entry naming no muscle of the model was exported silently
    check_muscles_in_model(osimx, [e.get("name") for e in writer.reader.elements(MUSCLE_TAGS)], model_file=source,
                           osimx_file=osimx_path)
    if include_contact:
        _check_spring_bodies(osimx, [e.get("name") for e in writer.reader.elements(["Body"])], osimx_path, source)
    updated = []
    for name, muscle in osimx.muscles.items():
        changed = False
        for field in ("optimal_fiber_length", "tendon_slack_length", "max_isometric_force"):
            value = getattr(muscle, field)
            if value is not None:
                try:
                    writer.set_muscle_property(name, field, float(value))
                except (KeyError, InputError) as exc:
                    raise InputError(f"muscle '{name}' of the .osimx is not in the model ({exc})", file=osimx_path,
                                     element=f"<RCNLMuscle name=\"{name}\">", expected=f"a muscle of {source}") from None
                changed = True
        if changed:
            updated.append(name)
    writer.write(output)
    tree = etree.parse(str(output), xml_parser(huge_tree=True, remove_comments=False))
    model = _model_element(tree.getroot(), output)
    _activation_constants(model, osimx)
    notes = []
    spheres = 0
    if include_contact and osimx.contact_surfaces:
        spheres = _add_contact(model, osimx.contact_surfaces, reference_depth)
        notes.append(f"contact: Hunt-Crossley spheres matched to the GCP springs' force at {1000 * reference_depth:g} "
                     "mm depth (OpenSim has no linear-spring foot contact); friction from mu_d, mu_v")
    elif osimx.contact_surfaces:
        notes.append("contact surfaces left out (include_contact=False): apply ground reactions as ExternalLoads")
    delays = [m for m, p in osimx.muscles.items() if p.electromechanical_delay is not None]
    if delays:
        notes.append("electromechanical delays, activation nonlinearity and EMG scale factors have no OpenSim "
                     f"muscle property ({len(delays)} muscles): kept in the .osimx only")
    if osimx.synergies:
        groups = ", ".join(f"{s.muscle_group_name} ({s.num_synergies})" for s in osimx.synergies)
        notes.append(f"synergy groups {groups}: NMSM's synergy controller has no OpenSim equivalent; drive the "
                     "muscles with the synergy activations (<trial>_combinedActivations.sto) as controls instead")
    if notes:
        model.insert(0, etree.Comment(" exported by nmsm from " + osimx_path.name + ": " + "; ".join(notes) + " "))
    tree.write(str(output), xml_declaration=True, encoding="UTF-8")
    return ExportReport(output, tuple(updated), spheres, tuple(notes))
