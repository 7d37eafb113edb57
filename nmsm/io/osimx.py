"""``.osimx`` files: NMSM's personalized quantities next to an ``.osim`` model.

Structure (docs/pipeline.md, 'Reading .osimx files')::

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
  ``*_scale_factor`` children are not current fields and are kept as unknown elements
  (NCP applies them to the model's lengths). The same children in an ``<RCNLMuscleSet>``
  get one warning per file.
* Unknown elements are **kept**: each object stores them (``extra``, serialized XML) and the
  writer puts them back at the end of the same element, so nothing a newer or older tool
  wrote is lost. Each one is reported by a ``UserWarning`` naming the file, the line, the
  element, its parent and the closest known child of that parent ("did you mean
  <tendon_slack_length>?"), since a misspelled field or set is otherwise silently unused.
  Unknown children of a *set* (``RCNLContactSurfaceSet``, ``GCPSpringSet``,
  ``RCNLSynergySet``) and of the root have no object to live in: they are dropped, with the
  same warning. Comments are descriptive and are not kept.
* The old ground-contact layout (``<RCNLGroundContact>``, ``<toes_coordinate>``) is an
  error: GCP must be re-run to name the ``hindfoot_body``.
* Every number is finite (``nan``, ``inf``, ``1e400`` are errors: ``nmsm export`` wrote
  them into the ``.osim``), and lengths, time constants, the EMG scale and the latching
  velocity are > 0, the maximum isometric force and GCP's spring, damping and friction
  coefficients >= 0 (``_SIGN_LIMITS``), each an ``InputError`` at the element's line.

Applying the muscles to a model (MTP, NCP, treatment muscle and synergy controllers):
:func:`check_muscles_in_model` makes an ``RCNLMuscle`` that names no muscle of the model an
``InputError`` (the original ignored it and copied it into its output ``.osimx``).
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Iterable, Mapping
from pathlib import Path

import attrs
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.names import close_matches
from nmsm.io.numbers import significant15
from nmsm.io.xml_input import element_text, parse_xml_file, refuse_entities, xml_input_error, xml_parser

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
    #: line of the ``<RCNLMuscle>`` in the file it was read from (None when built in code)
    line: int | None = attrs.field(default=None, eq=False, repr=False)


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
    #: line of the ``<RCNLContactSurface>`` in the file it was read from (None when built in code)
    line: int | None = attrs.field(default=None, eq=False, repr=False)


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
    #: the file it was read from (None when built in code or parsed from text)
    source: Path | None = attrs.field(default=None, eq=False, repr=False)

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
_SURFACE_FIELDS = ("is_left_foot", "belt_speed", *_SURFACE_COLUMNS, *_SURFACE_TEXT, *_SURFACE_FLOATS)
_SPRING_FIELDS = ("parent_body", "location", "spring_constant")
#: fields whose sign is physical, and why: a zero or negative length, force or time constant
#: has no meaning (the tools divide by them), GCP bounds its coefficients to >= 0. Resting
#: spring length (GCP leaves it free: the tutorial's is -0.43 mm), belt speed (direction),
#: activation nonlinearity and spring locations may take any finite value; the
#: electromechanical delay is >= 0 up to round-off (``_ROUND_OFF``: the original's Patient 3
#: MTP file holds -2.7e-40 at MTP's bound 0; NCP copied a -1 into its output .osimx).
_SIGN_REASONS = {
    "optimal_fiber_length": "a length in m",
    "tendon_slack_length": "a length in m",
    "max_isometric_force": "a force in N; 0 is kept: the original's own test files hold it",
    "activation_time_constant": "a time constant in 0.01 s",
    "emg_scale_factor": "the scale of the EMG",
    "electromechanical_delay": "a delay in 0.1 s",
    "spring_constant": "GCP bounds spring constants to >= 0",
    "damping_factor": "GCP bounds the damping factor to >= 0",
    "dynamic_friction_coefficient": "GCP bounds friction coefficients to >= 0",
    "viscous_friction_coefficient": "GCP bounds friction coefficients to >= 0",
    "latching_velocity": "a velocity scale in m/s",
}
_ROUND_OFF = {"electromechanical_delay": 1e-9}
_SIGN_LIMITS = {
    **dict.fromkeys(("optimal_fiber_length", "tendon_slack_length",
                     "activation_time_constant", "emg_scale_factor", "latching_velocity"), "positive"),
    **dict.fromkeys(("electromechanical_delay", "max_isometric_force", "spring_constant", "damping_factor",
                     "dynamic_friction_coefficient", "viscous_friction_coefficient"), "non-negative"),
}
_SYNERGY_FIELDS = ("muscle_group_name", "num_synergies")

#: the children the reader uses, per (current) parent element: anything else is "unknown"
_KNOWN_CHILDREN: dict[str, tuple[str, ...]] = {
    "NMSMPipelineDocument": ("OsimxModel",),
    "OsimxModel": ("associated_osim_model", "RCNLMuscleSet", "RCNLContactSurfaceSet", "RCNLSynergySet"),
    "RCNLMuscle": _MUSCLE_FIELDS,
    "RCNLContactSurfaceSet": ("RCNLContactSurface",),
    "RCNLContactSurface": (*_SURFACE_FIELDS, "GCPSpringSet"),
    "GCPSpringSet": ("GCPSpring",),
    "GCPSpring": _SPRING_FIELDS,
    "RCNLSynergySet": ("RCNLSynergy",),
    "RCNLSynergy": _SYNERGY_FIELDS,
}
#: 2023 root read as the current one (reported by its own warning)
_OLD_NAMES = {"OpenSimDocument": "NMSMPipelineDocument"}
#: 2023 ``RCNLMuscle`` children (MTP's length scale factors): kept, applied by NCP, not "unknown"
_OLD_SCALE_FACTORS = (
    "optimal_fiber_length_scale_factor",
    "slack_tendon_length_scale_factor",
    "tendon_slack_length_scale_factor",
)


# ----- reading ----------------------------------------------------------------------------
def _owner(element: etree._Element) -> str:
    """``<RCNLMuscle> 'soleus_r': `` for a value inside a named element (muscle, spring,
    surface), else ``''``: the start of a message about the value."""
    for parent in element.iterancestors():
        name = parent.get("name")
        if name:
            return f"<{parent.tag}> '{name}': "
    return ""


class _Reader:
    """One read of one file; ``messages`` collects its warnings (emitted by the caller)."""

    def __init__(self, path: Path | None) -> None:
        self.path = path
        self.messages: list[str] = []
        self.old_scale_factors: list[etree._Element] = []

    def where(self, element: etree._Element) -> str:
        return f"{self.path if self.path is not None else '(.osimx text)'}:{element.sourceline}"

    def unknown(self, child: etree._Element, parent: etree._Element, *, kept: bool = True) -> None:
        """Record a warning for ``child``, an element the reader does not use inside ``parent``."""
        known = _KNOWN_CHILDREN[_OLD_NAMES.get(parent.tag, parent.tag)]
        close = close_matches(str(child.tag), known, n=1, cutoff=0.75)
        hint = f"did you mean <{close[0]}>?" if close else "known here: " + ", ".join(f"<{k}>" for k in known)
        fate = "kept and written back, but not used" if kept else "ignored and not written back"
        self.messages.append(
            f"{self.where(child)}: unknown element <{child.tag}> in {_describe(parent)}: {fate} ({hint})"
        )

    def old_scale_factor_message(self) -> None:
        """One warning for 2023 length scale factors outside an ``<MTPMuscleSet>``."""
        if not self.old_scale_factors:
            return
        first = self.old_scale_factors[0]
        self.messages.append(
            f"{self.where(first)}: {len(self.old_scale_factors)} 2023 length scale factor(s) (first <{first.tag}> in "
            f"{_describe(first.getparent())}) are not current fields: kept and written back; NCP applies them to "
            "the model's lengths, MTP and treatment tools do not (current files hold absolute "
            "<optimal_fiber_length>/<tendon_slack_length>)"
        )

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
        return element_text(element)  # comments inside a value left out (lxml's .text stops at the first)

    def number(self, element: etree._Element) -> float:
        """A finite number, within the field's sign limit (``_SIGN_LIMITS``) if it has one."""
        text = self.text(element)
        try:
            value = float(text)
        except ValueError:
            raise self.error(element, f"'{text}' is not a number", "a number") from None
        if not math.isfinite(value):  # no field means anything by nan or inf (float() reads both)
            raise self.error(element, f"{_owner(element)}'{text}' is not a finite number", "a finite number")
        limit = _SIGN_LIMITS.get(str(element.tag))
        if limit is not None and not (value > 0 if limit == "positive" else value >= -_ROUND_OFF.get(element.tag, 0.0)):
            expected = "a number > 0" if limit == "positive" else "a number >= 0"
            sign = "positive" if limit == "positive" else "non-negative"
            raise self.error(element, f"{_owner(element)}{text} is not {sign}",
                             f"{expected} ({_SIGN_REASONS[str(element.tag)]})")
        return value

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
            values = tuple(kind(p) for p in parts)
        except ValueError:
            raise self.error(element, f"'{self.text(element)}' are not numbers", "three numbers") from None
        if kind is float and not all(math.isfinite(v) for v in values):
            raise self.error(element, f"'{self.text(element)}' are not finite numbers", "three finite numbers")
        return values

    def muscle(self, element: etree._Element, *, old_set: bool = False) -> OsimxMuscle:
        """One ``RCNLMuscle``; ``old_set``: inside a 2023 ``<MTPMuscleSet>`` (its scale factors already reported)."""
        name = element.get("name")
        if not name:
            raise self.error(element, "muscle without a name attribute", '<RCNLMuscle name="...">')
        values: dict[str, float] = {}
        extra: list[str] = []
        for child in self.children(element):
            if child.tag in _MUSCLE_FIELDS:
                values[child.tag] = self.number(child)
                continue
            extra.append(_serialize(child))
            if child.tag not in _OLD_SCALE_FACTORS:
                self.unknown(child, element)
            elif not old_set:
                self.old_scale_factors.append(child)
        return OsimxMuscle(name=name, extra=tuple(extra), line=element.sourceline, **values)

    def extras(self, element: etree._Element, known: tuple[str, ...]) -> list[str]:
        """Serialized children of ``element`` not in ``known`` (each one warned about)."""
        out = []
        for child in self.children(element):
            if child.tag not in known:
                self.unknown(child, element)
                out.append(_serialize(child))
        return out

    def members(self, element: etree._Element, tag: str) -> list[etree._Element]:
        """The ``tag`` children of a set; any other child is warned about and dropped (no object holds it)."""
        out = []
        for child in self.children(element):
            if child.tag == tag:
                out.append(child)
            else:
                self.unknown(child, element, kept=False)
        return out

    def spring(self, element: etree._Element) -> GcpSpring:
        found = {c.tag: c for c in self.children(element)}
        missing = [k for k in _SPRING_FIELDS if k not in found]
        if missing:
            raise self.error(element, f"spring lacks <{missing[0]}>", "parent_body, location, spring_constant")
        extra = self.extras(element, _SPRING_FIELDS)
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
                    "<hindfoot_body>",
                )
            if child.tag == "GCPSpringSet":
                for member in self.members(child, "GCPSpring"):
                    spring = self.spring(member)
                    if spring.name and any(spring.name == other.name for other in springs):
                        raise self.error(member, f"spring '{spring.name}' appears twice in this contact surface",
                                         "one <GCPSpring> per name")
                    springs.append(spring)
            elif child.tag in _SURFACE_FIELDS:
                found[child.tag] = child
            else:
                self.unknown(child, element)
                extra.append(_serialize(child))
        for key in _SURFACE_FIELDS:
            if key not in found:
                raise self.error(element, f"contact surface lacks <{key}>", "every contact-surface field")
        return OsimxContactSurface(
            is_left_foot=self.boolean(found["is_left_foot"]),
            belt_speed=self.number(found["belt_speed"]),
            springs=tuple(springs),
            extra=tuple(extra),
            line=element.sourceline,
            **{k: self.triple(found[k], str) for k in _SURFACE_COLUMNS},
            **{k: self.text(found[k]) for k in _SURFACE_TEXT},
            **{k: self.number(found[k]) for k in _SURFACE_FLOATS},
        )

    def synergy(self, element: etree._Element) -> OsimxSynergy:
        found = {c.tag: c for c in self.children(element)}
        for key in _SYNERGY_FIELDS:
            if key not in found:
                raise self.error(element, f"synergy lacks <{key}>", "muscle_group_name and num_synergies")
        count = self.number(found["num_synergies"])
        if not count.is_integer() or count < 1:
            raise self.error(
                found["num_synergies"], f"num_synergies must be a positive integer, got {count}", "an integer >= 1"
            )
        extra = self.extras(element, _SYNERGY_FIELDS)
        return OsimxSynergy(self.text(found["muscle_group_name"]), int(count), tuple(extra))

    def model(self, root: etree._Element) -> OsimxModel:
        if root.tag == "OpenSimDocument":
            self.messages.append(f"{self.path}: old .osimx root <OpenSimDocument>; read as <NMSMPipelineDocument>")
        elif root.tag != "NMSMPipelineDocument":
            raise self.error(root, f"root element is <{root.tag}>", "<NMSMPipelineDocument> (an .osimx file)")
        models = [c for c in self.children(root) if c.tag == "OsimxModel"]
        if len(models) == 1:
            for child in self.children(root):
                if child.tag != "OsimxModel":
                    self.unknown(child, root, kept=False)
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
                    self.messages.append(
                        f"{self.path}:{child.sourceline}: old <MTPMuscleSet> read as <RCNLMuscleSet>; its scale "
                        "factors are not current fields and are kept as unknown elements (NCP applies them to the "
                        "model's lengths)"
                    )
                for m in self.children(child):
                    if m.tag != "RCNLMuscle":
                        raise self.error(m, f"unexpected <{m.tag}> in the muscle set", "<RCNLMuscle> elements")
                    muscle = self.muscle(m, old_set=child.tag == "MTPMuscleSet")
                    if muscle.name in muscles:
                        raise self.error(m, f"muscle '{muscle.name}' appears twice", "one entry per muscle")
                    muscles[muscle.name] = muscle
            elif child.tag == "RCNLContactSurfaceSet":
                surfaces.extend(self.surface(s) for s in self.members(child, "RCNLContactSurface"))
            elif child.tag == "RCNLGroundContact":
                raise self.error(
                    child,
                    "old ground-contact layout <RCNLGroundContact> (toe coordinate instead of hindfoot body); "
                    "re-run GCP to write a current .osimx",
                    "<RCNLContactSurfaceSet>",
                )
            elif child.tag == "RCNLSynergySet":
                for member in self.members(child, "RCNLSynergy"):
                    synergy = self.synergy(member)
                    if any(synergy.muscle_group_name == other.muscle_group_name for other in synergies):
                        raise self.error(member, f"muscle group '{synergy.muscle_group_name}' has two <RCNLSynergy>",
                                         "one <RCNLSynergy> per muscle group")
                    synergies.append(synergy)
            else:
                self.unknown(child, element)
                extra.append(_serialize(child))
        if associated is None:
            raise self.error(element, "missing <associated_osim_model>", "the path of the .osim model")
        self.old_scale_factor_message()
        return OsimxModel(
            name=element.get("name", ""),
            associated_osim_model=associated,
            muscles=muscles,
            contact_surfaces=tuple(surfaces),
            synergies=tuple(synergies),
            version=root.get("Version", OSIMX_VERSION),
            extra=tuple(extra),
            source=self.path,
        )

    def read(self, root: etree._Element) -> OsimxModel:
        """The model of ``root``; the warnings of the read are emitted (to the caller's caller) at the end."""
        model = self.model(root)
        for message in self.messages:
            warnings.warn(message, stacklevel=3)
        return model


def _describe(element: etree._Element) -> str:
    """``<tag>``, or ``<tag name="...">`` when the element has a name."""
    name = element.get("name")
    return f'<{element.tag} name="{name}">' if name else f"<{element.tag}>"


def _serialize(element: etree._Element) -> str:
    copy = etree.fromstring(etree.tostring(element), xml_parser())
    copy.tail = None
    return etree.tostring(copy, encoding="unicode")


def read_osimx(path: str | os.PathLike[str]) -> OsimxModel:
    """Read an ``.osimx`` file (see module docstring for compatibility rules)."""
    path = Path(path)
    root = parse_xml_file(path, what=".osimx file", remove_blank_text=True)  # an "ANSI" file: its line, the fix
    return _Reader(path).read(root)


def parse_osimx(text: str | bytes, *, source: Path | None = None) -> OsimxModel:
    """Parse ``.osimx`` text (see :func:`read_osimx`)."""
    try:
        root = etree.fromstring(text.encode() if isinstance(text, str) else text, xml_parser(remove_blank_text=True))
    except etree.XMLSyntaxError as exc:
        raise xml_input_error(exc, source) from exc
    refuse_entities(root, source, ".osimx file")
    return _Reader(source).read(root)


# ----- applying to a model ----------------------------------------------------------------
def check_muscles_in_model(
    osimx: OsimxModel,
    model_muscles: Iterable[str],
    *,
    model_file: str | os.PathLike[str] | None = None,
    osimx_file: str | os.PathLike[str] | None = None,
) -> None:
    """Raise :class:`InputError` if an ``RCNLMuscle`` of ``osimx`` names no muscle of the model.

    Called where an ``.osimx``'s muscles are applied to a model by name (MTP, NCP, treatment
    controllers): such an entry is a typo or an ``.osimx`` of another model, and would
    otherwise be silently unused (and copied into the tool's output ``.osimx``). The error
    names the ``.osimx`` (``osimx_file``, default the file it was read from), the line of the
    first such muscle, close matches among ``model_muscles`` and the other unknown names.
    An ``.osimx`` holding a *subset* of the model's muscles is fine (the others keep the
    model's values).
    """
    known = list(model_muscles)
    present = set(known)
    unknown = [m for m in osimx.muscles.values() if m.name not in present]
    if not unknown:
        return
    first = unknown[0]
    close = close_matches(first.name, known, n=3)
    hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
    others = f"; also not in the model: {', '.join(m.name for m in unknown[1:])}" if len(unknown) > 1 else ""
    model = f"the model {model_file}" if model_file is not None else "the model"
    shown = ", ".join(known[:12]) + (f", ... ({len(known)} muscles)" if len(known) > 12 else "")
    raise InputError(
        f"muscle '{first.name}' is not in {model}{hint}{others}",
        file=osimx_file if osimx_file is not None else osimx.source,
        line=first.line,
        element=f'<RCNLMuscle name="{first.name}">',
        expected=f"RCNLMuscle names that are muscles of the model: {shown}",
    )


def check_contact_surfaces(osimx: OsimxModel, *, osimx_file: str | os.PathLike[str] | None = None) -> None:
    """Raise :class:`InputError` unless each contact surface has springs and its own hindfoot body.

    Called where the surfaces are applied as foot contact (treatment tools, ``nmsm export``):
    a surface without springs was a CasADi "Slice ... out of bounds" while a term was built,
    and two surfaces on one hindfoot body (an ``RCNLContactSurface`` copied, or the original's
    GCP appending a re-run's surface to the input's) pushed that foot twice, silently. GCP
    itself reads such a file: it replaces the surfaces of the feet it personalizes.
    """
    file = osimx_file if osimx_file is not None else osimx.source
    seen: dict[str, OsimxContactSurface] = {}
    for surface in osimx.contact_surfaces:
        if not surface.springs:
            raise InputError(f"the contact surface on '{surface.hindfoot_body}' has no springs", file=file,
                             line=surface.line, element="<RCNLContactSurface>",
                             expected="a <GCPSpringSet> holding GCP's springs (re-run GCP for this foot)")
        first = seen.get(surface.hindfoot_body)
        if first is not None:
            at = f" (also at line {first.line})" if first.line is not None else ""
            raise InputError(f"two contact surfaces on '{surface.hindfoot_body}'{at}: that foot would touch the "
                             "ground twice", file=file, line=surface.line, element="<RCNLContactSurface>",
                             expected="one <RCNLContactSurface> per hindfoot body")
        seen[surface.hindfoot_body] = surface


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
        parent.append(etree.fromstring(item, xml_parser()))


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
