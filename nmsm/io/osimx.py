"""``.osimx`` files: NMSM's personalized quantities next to an ``.osim`` model.

Structure (``/work/shared/spec/osimx.md``)::

    NMSMPipelineDocument @Version
      OsimxModel @name
        associated_osim_model
        RCNLMuscleSet/RCNLMuscle @name          (MTP, NCP; every child optional)
        RCNLContactSurfaceSet/RCNLContactSurface (GCP; scalar fields required)
          GCPSpringSet/GCPSpring @name
        RCNLSynergySet/RCNLSynergy              (NCP)

Units as written by the original: ``electromechanical_delay`` in 0.1 s and
``activation_time_constant`` in 0.01 s (MTP's raw design variables), lengths in m, forces
in N, spring constants in N/m. Numbers are written with 15 significant digits.

Compatibility on read:

* OpenSim-style ``<objects>``/``<groups>`` wrappers inside sets (2023 files) are flattened.
* ``<MTPMuscleSet>`` (2023 MTP output) is read as the muscle set, with a warning; its
  ``*_scale_factor`` children are not current fields and are kept as unknown elements.
* Unknown elements are **kept**: each object stores them (``extra``, serialized XML) and the
  writer puts them back at the end of the same element, so nothing a newer or older tool
  wrote is lost. Comments are descriptive and are not kept.
* The old ground-contact layout (``<RCNLGroundContact>``, ``<toes_coordinate>``) is an
  error: GCP must be re-run to name the ``hindfoot_body``.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable, Mapping
from pathlib import Path

import attrs
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.numbers import significant15

#: version written when the model has none
OSIMX_VERSION = "1.5.3"


def _xml_tuple(items: Iterable[str]) -> tuple[str, ...]:
    return tuple(items)


@attrs.frozen
class OsimxMuscle:
    """One ``RCNLMuscle``; ``None`` = not personalized (the model's value applies)."""

    name: str
    electromechanical_delay: float | None = None  #: MTP raw variable, units of 0.1 s
    activation_time_constant: float | None = None  #: MTP raw variable, units of 0.01 s
    activation_nonlinearity_constant: float | None = None  #: A in [0, 0.35]
    emg_scale_factor: float | None = None
    optimal_fiber_length: float | None = None  #: m, absolute
    tendon_slack_length: float | None = None  #: m, absolute
    max_isometric_force: float | None = None  #: N, absolute
    extra: tuple[str, ...] = attrs.field(default=(), converter=_xml_tuple)


@attrs.frozen
class GcpSpring:
    """One contact spring: ``location`` (3,) in the parent body's frame (m), ``spring_constant`` N/m."""

    name: str
    parent_body: str
    location: tuple[float, float, float]
    spring_constant: float
    extra: tuple[str, ...] = attrs.field(default=(), converter=_xml_tuple)


@attrs.frozen
class OsimxContactSurface:
    """One ``RCNLContactSurface`` (foot); the order in the file is the foot index."""

    is_left_foot: bool
    belt_speed: float  #: m/s, 0 overground
    force_columns: tuple[str, str, str]
    moment_columns: tuple[str, str, str]
    electrical_center_columns: tuple[str, str, str]
    hindfoot_body: str
    toe_marker: str
    medial_marker: str
    lateral_marker: str
    heel_marker: str
    midfoot_superior_marker: str
    resting_spring_length: float  #: m
    dynamic_friction_coefficient: float
    viscous_friction_coefficient: float  #: s/m
    damping_factor: float  #: s/m
    latching_velocity: float  #: m/s
    springs: tuple[GcpSpring, ...] = ()
    extra: tuple[str, ...] = attrs.field(default=(), converter=_xml_tuple)


@attrs.frozen
class OsimxSynergy:
    """One ``RCNLSynergy``: a ForceSet group of the model and its number of synergies."""

    muscle_group_name: str
    num_synergies: int
    extra: tuple[str, ...] = attrs.field(default=(), converter=_xml_tuple)


@attrs.frozen
class OsimxModel:
    """The content of an ``.osimx`` file. ``muscles`` is keyed by muscle name (file order kept)."""

    name: str
    associated_osim_model: str
    muscles: Mapping[str, OsimxMuscle] = attrs.field(factory=dict)
    contact_surfaces: tuple[OsimxContactSurface, ...] = ()
    synergies: tuple[OsimxSynergy, ...] = ()
    version: str = OSIMX_VERSION
    extra: tuple[str, ...] = attrs.field(default=(), converter=_xml_tuple)

    def model_path(self, osimx_file: str | os.PathLike[str]) -> Path:
        """The associated model, resolved relative to the ``.osimx`` file's folder."""
        from nmsm.io.paths import resolve_path

        return resolve_path(
            self.associated_osim_model, settings_file=osimx_file, element="associated_osim_model", kind="file"
        )


_MUSCLE_FIELDS = (
    "electromechanical_delay",
    "activation_time_constant",
    "activation_nonlinearity_constant",
    "emg_scale_factor",
    "optimal_fiber_length",
    "tendon_slack_length",
    "max_isometric_force",
)
_SURFACE_TEXT = (
    "hindfoot_body",
    "toe_marker",
    "medial_marker",
    "lateral_marker",
    "heel_marker",
    "midfoot_superior_marker",
)
_SURFACE_COLUMNS = ("force_columns", "moment_columns", "electrical_center_columns")
_SURFACE_FLOATS = (
    "resting_spring_length",
    "dynamic_friction_coefficient",
    "viscous_friction_coefficient",
    "damping_factor",
    "latching_velocity",
)


# ----- reading ----------------------------------------------------------------------------
class _Reader:
    def __init__(self, path: Path | None) -> None:
        self.path = path

    def error(self, element: etree._Element | None, message: str, expected: str | None = None) -> InputError:
        line = element.sourceline if element is not None else None
        tag = f"<{element.tag}>" if element is not None else None
        return InputError(message, file=self.path, line=line, element=tag, expected=expected)

    @staticmethod
    def children(element: etree._Element) -> list[etree._Element]:
        """Element children, with ``<objects>`` wrappers flattened and ``<groups>`` dropped."""
        out: list[etree._Element] = []
        for child in element:
            if not isinstance(child.tag, str):
                continue
            if child.tag == "objects":
                out.extend(c for c in child if isinstance(c.tag, str))
            elif child.tag == "groups":
                continue
            else:
                out.append(child)
        return out

    def text(self, element: etree._Element) -> str:
        return (element.text or "").strip()

    def number(self, element: etree._Element) -> float:
        text = self.text(element)
        try:
            return float(text)
        except ValueError:
            raise self.error(element, f"'{text}' is not a number", "a number") from None

    def boolean(self, element: etree._Element) -> bool:
        text = self.text(element).lower()
        if text not in ("true", "false"):
            raise self.error(element, f"'{self.text(element)}' is not a boolean", "true or false")
        return text == "true"

    def triple(self, element: etree._Element, kind: type) -> tuple:
        parts = self.text(element).split()
        if len(parts) != 3:
            raise self.error(element, f"expected 3 values, got {len(parts)}: '{self.text(element)}'", "three values")
        try:
            return tuple(kind(p) for p in parts)
        except ValueError:
            raise self.error(element, f"'{self.text(element)}' are not numbers", "three numbers") from None

    def muscle(self, element: etree._Element) -> OsimxMuscle:
        name = element.get("name")
        if not name:
            raise self.error(element, "muscle without a name attribute", '<RCNLMuscle name="...">')
        values: dict[str, float] = {}
        extra: list[str] = []
        for child in self.children(element):
            if child.tag in _MUSCLE_FIELDS:
                values[child.tag] = self.number(child)
            else:
                extra.append(_serialize(child))
        return OsimxMuscle(name=name, extra=tuple(extra), **values)

    def spring(self, element: etree._Element) -> GcpSpring:
        found = {c.tag: c for c in self.children(element)}
        missing = [k for k in ("parent_body", "location", "spring_constant") if k not in found]
        if missing:
            raise self.error(element, f"spring lacks <{missing[0]}>", "parent_body, location, spring_constant")
        extra = [
            _serialize(c) for c in self.children(element) if c.tag not in ("parent_body", "location", "spring_constant")
        ]
        return GcpSpring(
            name=element.get("name", ""),
            parent_body=self.text(found["parent_body"]),
            location=self.triple(found["location"], float),
            spring_constant=self.number(found["spring_constant"]),
            extra=tuple(extra),
        )

    def surface(self, element: etree._Element) -> OsimxContactSurface:
        found: dict[str, etree._Element] = {}
        extra: list[str] = []
        springs: list[GcpSpring] = []
        for child in self.children(element):
            if child.tag in ("toes_coordinate", "toes_joint"):
                raise self.error(
                    child,
                    "old ground-contact layout: the contact surface names a toe coordinate/joint instead of "
                    "the hindfoot body; re-run GCP to write a current .osimx",
                    "<hindfoot_body> (osimx.md)",
                )
            if child.tag == "GCPSpringSet":
                springs.extend(self.spring(s) for s in self.children(child) if s.tag == "GCPSpring")
            elif child.tag in ("is_left_foot", "belt_speed", *_SURFACE_TEXT, *_SURFACE_COLUMNS, *_SURFACE_FLOATS):
                found[child.tag] = child
            else:
                extra.append(_serialize(child))
        required = ("is_left_foot", "belt_speed", *_SURFACE_COLUMNS, *_SURFACE_TEXT, *_SURFACE_FLOATS)
        for key in required:
            if key not in found:
                raise self.error(element, f"contact surface lacks <{key}>", "every contact-surface field (osimx.md)")
        return OsimxContactSurface(
            is_left_foot=self.boolean(found["is_left_foot"]),
            belt_speed=self.number(found["belt_speed"]),
            springs=tuple(springs),
            extra=tuple(extra),
            **{k: self.triple(found[k], str) for k in _SURFACE_COLUMNS},
            **{k: self.text(found[k]) for k in _SURFACE_TEXT},
            **{k: self.number(found[k]) for k in _SURFACE_FLOATS},
        )

    def synergy(self, element: etree._Element) -> OsimxSynergy:
        found = {c.tag: c for c in self.children(element)}
        for key in ("muscle_group_name", "num_synergies"):
            if key not in found:
                raise self.error(element, f"synergy lacks <{key}>", "muscle_group_name and num_synergies")
        count = self.number(found["num_synergies"])
        if not count.is_integer() or count < 1:
            raise self.error(
                found["num_synergies"], f"num_synergies must be a positive integer, got {count}", "an integer >= 1"
            )
        extra = [_serialize(c) for c in self.children(element) if c.tag not in ("muscle_group_name", "num_synergies")]
        return OsimxSynergy(self.text(found["muscle_group_name"]), int(count), tuple(extra))

    def model(self, root: etree._Element) -> OsimxModel:
        if root.tag == "OpenSimDocument":
            warnings.warn(
                f"{self.path}: old .osimx root <OpenSimDocument>; read as <NMSMPipelineDocument>", stacklevel=3
            )
        elif root.tag != "NMSMPipelineDocument":
            raise self.error(root, f"root element is <{root.tag}>", "<NMSMPipelineDocument> (an .osimx file)")
        models = [c for c in self.children(root) if c.tag == "OsimxModel"]
        if len(models) != 1:
            raise self.error(root, f"{len(models)} <OsimxModel> elements", "exactly one <OsimxModel>")
        element = models[0]
        associated: str | None = None
        muscles: dict[str, OsimxMuscle] = {}
        surfaces: list[OsimxContactSurface] = []
        synergies: list[OsimxSynergy] = []
        extra: list[str] = []
        for child in self.children(element):
            if child.tag == "associated_osim_model":
                associated = self.text(child)
            elif child.tag in ("RCNLMuscleSet", "MTPMuscleSet"):
                if child.tag == "MTPMuscleSet":
                    warnings.warn(
                        f"{self.path}:{child.sourceline}: old <MTPMuscleSet> read as <RCNLMuscleSet>; its scale "
                        "factors are not current fields and are kept as unknown elements",
                        stacklevel=3,
                    )
                for m in self.children(child):
                    if m.tag != "RCNLMuscle":
                        raise self.error(m, f"unexpected <{m.tag}> in the muscle set", "<RCNLMuscle> elements")
                    muscle = self.muscle(m)
                    if muscle.name in muscles:
                        raise self.error(m, f"muscle '{muscle.name}' appears twice", "one entry per muscle")
                    muscles[muscle.name] = muscle
            elif child.tag == "RCNLContactSurfaceSet":
                surfaces.extend(self.surface(s) for s in self.children(child) if s.tag == "RCNLContactSurface")
            elif child.tag == "RCNLGroundContact":
                raise self.error(
                    child,
                    "old ground-contact layout <RCNLGroundContact> (toe coordinate instead of hindfoot body); "
                    "re-run GCP to write a current .osimx",
                    "<RCNLContactSurfaceSet> (osimx.md)",
                )
            elif child.tag == "RCNLSynergySet":
                synergies.extend(self.synergy(s) for s in self.children(child) if s.tag == "RCNLSynergy")
            else:
                extra.append(_serialize(child))
        if associated is None:
            raise self.error(element, "missing <associated_osim_model>", "the path of the .osim model")
        return OsimxModel(
            name=element.get("name", ""),
            associated_osim_model=associated,
            muscles=muscles,
            contact_surfaces=tuple(surfaces),
            synergies=tuple(synergies),
            version=root.get("Version", OSIMX_VERSION),
            extra=tuple(extra),
        )


def _serialize(element: etree._Element) -> str:
    copy = etree.fromstring(etree.tostring(element))
    copy.tail = None
    return etree.tostring(copy, encoding="unicode")


def read_osimx(path: str | os.PathLike[str]) -> OsimxModel:
    """Read an ``.osimx`` file (see module docstring for compatibility rules)."""
    path = Path(path)
    try:
        root = etree.parse(str(path), etree.XMLParser(remove_blank_text=True)).getroot()
    except OSError as exc:
        raise InputError(f"cannot read .osimx file: {exc}", file=path, expected="a readable .osimx file") from exc
    except etree.XMLSyntaxError as exc:
        raise InputError(f"malformed XML: {exc.msg}", file=path, line=exc.lineno, expected="well-formed XML") from exc
    return _Reader(path).model(root)


def parse_osimx(text: str | bytes, *, source: Path | None = None) -> OsimxModel:
    """Parse ``.osimx`` text (see :func:`read_osimx`)."""
    try:
        root = etree.fromstring(
            text.encode() if isinstance(text, str) else text, etree.XMLParser(remove_blank_text=True)
        )
    except etree.XMLSyntaxError as exc:
        raise InputError(f"malformed XML: {exc.msg}", file=source, line=exc.lineno, expected="well-formed XML") from exc
    return _Reader(source).model(root)


# ----- writing ----------------------------------------------------------------------------
_COMMENTS = {
    "associated_osim_model": "File name of the associated .osim model",
    "electromechanical_delay": "Optimized electromechanical delay (units of 0.1 s)",
    "activation_time_constant": "Optimized activation time constant (units of 0.01 s)",
    "activation_nonlinearity_constant": "Optimized activation nonlinearity constant",
    "emg_scale_factor": "Optimized EMG scale factor",
    "optimal_fiber_length": "Optimized optimal fiber length (m)",
    "tendon_slack_length": "Optimized tendon slack length (m)",
    "max_isometric_force": "Optimized max isometric force (N)",
    "is_left_foot": "Flag indicating whether the foot model is mirrored (left foot)",
    "belt_speed": "Speed of the treadmill belt (m/s); 0 if overground",
    "force_columns": "Force columns of the GRF file, ordered X Y Z",
    "moment_columns": "Moment columns of the GRF file, ordered X Y Z",
    "electrical_center_columns": "Electrical center columns of the GRF file, ordered X Y Z",
    "hindfoot_body": "Hindfoot body of the model",
    "toe_marker": "Markers defining the foot area",
    "resting_spring_length": "Resting spring length of the surface (m)",
    "dynamic_friction_coefficient": "Dynamic friction coefficient of the surface",
    "viscous_friction_coefficient": "Viscous friction coefficient of the surface (s/m)",
    "damping_factor": "Damping factor of the surface (s/m)",
    "latching_velocity": "Latching velocity of the surface (m/s)",
    "GCPSpringSet": "Springs of the contact surface",
    "parent_body": "Body the spring is attached to",
    "location": "Location of the spring in its parent body (m)",
    "spring_constant": "Spring constant (N/m)",
    "RCNLSynergySet": "Synergy groups found by NCP",
    "muscle_group_name": "Muscle group (ForceSet group of the model) of this synergy set",
    "num_synergies": "Number of synergies of this group",
}


def _add(parent: etree._Element, tag: str, text: str, *, comment: bool = True) -> etree._Element:
    if comment and tag in _COMMENTS:
        parent.append(etree.Comment(_COMMENTS[tag]))
    child = etree.SubElement(parent, tag)
    child.text = text
    return child


def _add_extra(parent: etree._Element, extra: Iterable[str]) -> None:
    for item in extra:
        parent.append(etree.fromstring(item))


def _bool(value: bool) -> str:
    return "true" if value else "false"


def build_osimx_tree(model: OsimxModel) -> etree._Element:
    """The XML tree of ``model``."""
    root = etree.Element("NMSMPipelineDocument", Version=model.version or OSIMX_VERSION)
    element = etree.SubElement(root, "OsimxModel", name=model.name)
    _add(element, "associated_osim_model", model.associated_osim_model)
    if model.muscles:
        muscle_set = etree.SubElement(element, "RCNLMuscleSet")
        for muscle in model.muscles.values():
            m = etree.SubElement(muscle_set, "RCNLMuscle", name=muscle.name)
            for key in _MUSCLE_FIELDS:
                value = getattr(muscle, key)
                if value is not None:
                    _add(m, key, significant15(value))
            _add_extra(m, muscle.extra)
    if model.contact_surfaces:
        surface_set = etree.SubElement(element, "RCNLContactSurfaceSet")
        for surface in model.contact_surfaces:
            s = etree.SubElement(surface_set, "RCNLContactSurface")
            _add(s, "is_left_foot", _bool(surface.is_left_foot))
            _add(s, "belt_speed", significant15(surface.belt_speed))
            for key in _SURFACE_COLUMNS:
                _add(s, key, " ".join(getattr(surface, key)))
            for key in _SURFACE_TEXT:
                _add(s, key, getattr(surface, key))
            for key in _SURFACE_FLOATS:
                _add(s, key, significant15(getattr(surface, key)))
            parent = etree.SubElement(s, "GCPSpringSet") if surface.springs else None
            if parent is not None:
                s.insert(len(s) - 1, etree.Comment(_COMMENTS["GCPSpringSet"]))
            for i, spring in enumerate(surface.springs, start=1):
                sp = etree.SubElement(parent, "GCPSpring", name=spring.name or f"spring_marker_{i}")
                _add(sp, "parent_body", spring.parent_body)
                _add(sp, "location", " ".join(significant15(v) for v in spring.location))
                _add(sp, "spring_constant", significant15(spring.spring_constant))
                _add_extra(sp, spring.extra)
            _add_extra(s, surface.extra)
    if model.synergies:
        element.append(etree.Comment(_COMMENTS["RCNLSynergySet"]))
        synergy_set = etree.SubElement(element, "RCNLSynergySet")
        for synergy in model.synergies:
            y = etree.SubElement(synergy_set, "RCNLSynergy")
            _add(y, "muscle_group_name", synergy.muscle_group_name)
            _add(y, "num_synergies", str(synergy.num_synergies))
            _add_extra(y, synergy.extra)
    _add_extra(element, model.extra)
    return root


def format_osimx(model: OsimxModel) -> str:
    """The text of ``model`` as an ``.osimx`` file."""
    root = build_osimx_tree(model)
    etree.indent(root, space="   ")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + etree.tostring(root, encoding="unicode") + "\n"


def write_osimx(path: str | os.PathLike[str], model: OsimxModel) -> Path:
    """Write ``model`` to ``path``."""
    path = Path(path)
    path.write_text(format_osimx(model), encoding="utf-8")
    return path
