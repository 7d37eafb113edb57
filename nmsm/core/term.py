"""Cost and constraint terms: the normalized max-allowable-error formulation.

A term is a frozen attrs class whose fields are its settings-XML elements. A subclass
computes only its raw quantity; the base owns the normalization
``(value - error_center) / max_allowable_error`` and hands the normalized values to the
tool's reduction (``ctx.reduce_cost``), which applies the tool's scaling: means over
samples (MTP, NCP, GCP, JMP, MTLI), duration-normalized time integrals (TO, VO, DO),
term-type averaging, etc. The squared sum of the returned residuals is the term's
contribution to the objective.

Writing a term::

    @attrs.frozen(kw_only=True)
    class GeneralizedCoordinateTracking(ContinuousCost):  # nmsm.core.ocp.ContinuousCost
        \"\"\"Tracks one coordinate: q_exp - q (rad or m).\"\"\"
        type: ClassVar[str] = "generalized_coordinate_tracking"
        tools: ClassVar[frozenset[str]] = frozenset({"TO", "VO", "DO"})
        coordinate: str

        def bind(self, ctx):
            ctx.require_coordinate(self, self.coordinate)

        def quantity(self, ctx):
            return ctx.tracked_coordinate(self.coordinate) - ctx.coordinate(self.coordinate)
"""

from __future__ import annotations

import functools
import itertools
import math
import types
import typing
import warnings
from collections.abc import Callable, Mapping
from typing import Any, ClassVar, Protocol

import attrs

from nmsm.core.origins import origin_of
from nmsm.io.term_spec import SourceRef, TermSpec
from nmsm.errors import InputError, NmsmError, RegistryError, TermValueError


class TermContext(Protocol):
    """What a tool hands to its terms. Tools add their own quantities (model outputs)."""

    tool: str

    def reduce_cost(self, term: CostTerm, normalized: Any) -> Any:
        """Residual vector whose squared sum is the term's objective contribution."""

    def reduce_constraint(self, term: ConstraintTerm, value: Any) -> tuple[Any, Any, Any]:
        """``(expression, lower, upper)`` for the problem's constraint vector."""


#: ``*_list`` settings elements split into one term per item (as the original).
LIST_TO_SINGULAR: dict[str, str] = {
    "coordinate_list": "coordinate",
    "load_list": "load",
    "muscle_list": "muscle",
    "force_list": "force",
    "moment_list": "moment",
    "marker_list": "marker",
    "controller_list": "controller",
    "body_list": "body",
    "hindfoot_body_list": "hindfoot_body",
    "synergy_list": "synergy",
    "synergy_group_list": "synergy_group",
    "axes": "axis",
}

_TRUE = {"true"}
_FALSE = {"false"}


def parse_bool(text: str, *, where: str = "value") -> bool:
    low = text.strip().lower()
    if low in _TRUE:
        return True
    if low in _FALSE or low == "":
        return False
    raise ValueError(f"{where} must be 'true' or 'false', got '{text}'")


def _convert(text: str, annotation: Any) -> Any:
    """Convert element text to the field's annotated type."""
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        inner = [a for a in args if a is not type(None)]
        if text.strip() == "" and type(None) in args:
            return None
        return _convert(text, inner[0])
    if annotation is bool:
        return parse_bool(text)
    if annotation is int:
        return _integer(text)
    if annotation is float:
        return float(text)
    if annotation is str:
        return text.strip()
    if origin in (tuple, list):
        items = text.split()
        item_type = args[0] if args else str
        values = [_convert(i, item_type) for i in items]
        return tuple(values) if origin is tuple else values
    return text.strip()


def _integer(text: str) -> int:
    """``"3"`` or ``"3.0"`` -> 3; ``"2.7"`` is refused rather than truncated."""
    stripped = text.strip()
    try:
        return int(stripped)
    except ValueError:
        pass
    value = float(stripped)  # ValueError for text that is no number at all
    if not value.is_integer():
        raise ValueError(f"'{stripped}' is not an integer")
    return int(value)


#: Scalar field types the settings reader converts (see :func:`_convert`).
_SCALARS: tuple[type, ...] = (str, int, float, bool)

#: The field annotations :func:`_convert` reads, for messages.
SUPPORTED_FIELD_TYPES = "str, int, float, bool, X | None, tuple[X, ...] and list[X] with X one of str, int, float, bool"

#: Fields whose value must be a finite number (a NaN or an infinity makes the term meaningless).
_FINITE_FIELDS = ("max_allowable_error", "error_center", "min_error", "max_error")


def readable_annotation(annotation: Any) -> bool:
    """True if :func:`_convert` turns element text into a value of type ``annotation``
    (:data:`SUPPORTED_FIELD_TYPES`); anything else would reach the term as raw text."""
    if annotation in _SCALARS:
        return True
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin in (typing.Union, types.UnionType):
        inner = [a for a in args if a is not type(None)]
        return len(inner) == 1 and type(None) in args and readable_annotation(inner[0])
    if origin in (tuple, list):
        items = {a for a in args if a is not Ellipsis}
        return len(items) == 1 and next(iter(items)) in _SCALARS
    return False


def _type_name(annotation: Any) -> str:
    if isinstance(annotation, type) and not typing.get_args(annotation):
        return annotation.__qualname__ if annotation.__module__ == "builtins" else \
            f"{annotation.__module__}.{annotation.__qualname__}"
    return repr(annotation).replace("typing.", "")


def _qualified(cls: type) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"


def _is_classvar(annotation: Any) -> bool:
    if isinstance(annotation, str):  # ``from __future__ import annotations``
        return annotation.strip().startswith(("ClassVar", "typing.ClassVar", "t.ClassVar"))
    return annotation is ClassVar or typing.get_origin(annotation) is ClassVar


def term_class_problems(cls: type[Term]) -> list[str]:
    """What makes ``cls`` (a :class:`Term` subclass) unusable from settings XML, checked when
    the plugin registry is built (:mod:`nmsm.core.registry`); empty if nothing.

    A term must be decorated with ``@attrs.frozen(kw_only=True)`` (its fields are its settings
    elements), keep ``type`` and ``tools`` as ``ClassVar`` s, and annotate every field with a
    type the settings reader converts (:data:`SUPPORTED_FIELD_TYPES`) unless the field has a
    ``converter`` that takes the element's text.
    """
    out: list[str] = []
    for klass in cls.__mro__:
        if not issubclass(klass, Term) or "__attrs_attrs__" in klass.__dict__:
            continue
        own = [name for name, annotation in klass.__dict__.get("__annotations__", {}).items()
               if not _is_classvar(annotation)]
        if klass is cls or own:
            text = "is not decorated" if klass is cls else f"has a base {_qualified(klass)} not decorated"
            text += " with @attrs.frozen(kw_only=True)"
            if len(own) == 1:
                text += f": '{own[0]}' would not be a field, so its settings element <{own[0]}> would be refused"
            elif own:
                text += (f": {', '.join(repr(n) for n in own)} would not be fields, so their settings elements "
                         f"would be refused")
            out.append(text)
    if out:
        return out
    fields = attrs.fields_dict(cls)
    for name, kind in (("type", "str"), ("tools", "frozenset[str]"), ("kind", "str"), ("aliases", "dict[str, str]")):
        if name in fields:
            default = fields[name].default
            example = "..." if default is attrs.NOTHING or isinstance(default, attrs.Factory) else repr(default)
            out.append(f"sets '{name}' as an attrs field, but '{name}' must be a ClassVar[{kind}], not an attrs "
                       f"field (write {name}: ClassVar[{kind}] = {example})")
    if out:
        return out
    try:
        hints = cls.xml_fields()
    except Exception as exc:  # get_type_hints: a name in an annotation that cannot be resolved
        return [f"has field annotations that cannot be resolved ({type(exc).__name__}: {exc})"]
    for name, annotation in hints.items():
        if fields[name].converter is None and not readable_annotation(annotation):
            out.append(f"has field '{name}' annotated {_type_name(annotation)}, which the settings reader cannot "
                       f"read (supported: {SUPPORTED_FIELD_TYPES}; or give the field a converter taking the "
                       f"element's text)")
    return out


class TermCodeError(RegistryError):
    """A term's own code (``bind``, ``quantity``, ``value``, ...) raised an exception that is not
    an nmsm error: a bug in the term (often a plugin's). The message names the settings file
    and line, the term type, its class and the class's distribution; the original exception
    is chained (``--traceback`` shows where it was raised)."""

    def __init__(self, term: Term, method: str, exc: BaseException) -> None:
        self.term = term
        self.method = method
        self.original = exc
        cls = type(term)
        where = ""
        if term.source.file:
            where = term.source.file + (f":{term.source.line}" if term.source.line is not None else "") + ": "
        owner = _qualified(cls)
        origin = origin_of(cls)
        if origin is not None and origin[0] != "nmsm":
            owner += f" from distribution '{origin[0]}' {origin[1]}"
        detail = str(exc)
        error = type(exc).__name__ + (f" {detail}" if detail else "")
        label = f"term '{term.type}'" + (f" ({term.name})" if term.name else "")
        super().__init__(f"{where}{label} ({owner}) failed while building its expression, in {method}(): "
                         f"{error} (run with --traceback for details)")


#: Term methods whose exceptions are reported by :class:`TermCodeError`.
_GUARDED_METHODS = ("bind", "quantity", "normalized", "residuals", "value", "bounded")


class _GuardedMethod:
    """A term method that turns an exception other than an nmsm error into a
    :class:`TermCodeError` naming the term (``raise ... from`` the original).

    Installed by :meth:`Term.__init_subclass__` on every method of :data:`_GUARDED_METHODS` a
    term class defines, so every caller (problem builders, scoring, comparisons) gets the
    message. ``__closure__`` exposes the function's cells so attrs re-points the ``__class__``
    cell of ``super()`` calls when it rebuilds a slotted class.
    """

    def __init__(self, func: Callable[..., Any]) -> None:
        self.__func__ = func

        @functools.wraps(func)
        def guarded(term: Term, *args: Any, **kwargs: Any) -> Any:
            try:
                return func(term, *args, **kwargs)
            except NmsmError:
                raise  # raised on purpose (term.error(...), ctx.require_...): already says what is wrong
            except Exception as exc:
                raise TermCodeError(term, func.__name__, exc) from exc

        self._guarded = guarded
        functools.update_wrapper(self, func)

    @property
    def __closure__(self) -> Any:
        return self.__func__.__closure__

    def __get__(self, instance: Any, owner: type | None = None) -> Any:
        if instance is None:
            return self._guarded
        return types.MethodType(self._guarded, instance)


@attrs.frozen(kw_only=True)
class Term:
    """Base of cost and constraint terms.

    Class attributes a subclass sets:
      ``type``  the settings name (``<type>`` element);
      ``tools`` the tool codes that accept it (see :data:`nmsm.core.registry.TOOL_NAMES`).
    """

    type: ClassVar[str] = ""
    tools: ClassVar[frozenset[str]] = frozenset()
    kind: ClassVar[str] = ""
    #: settings element aliases: alias -> field name
    aliases: ClassVar[dict[str, str]] = {}
    #: settings elements -> text of a valid term, for :func:`nmsm.testing.check_term` (names of
    #: its synthetic problem where the term names model parts)
    check_example: ClassVar[Mapping[str, str]] = {}

    is_enabled: bool = True
    name: str | None = None
    source: SourceRef = attrs.field(factory=SourceRef, eq=False, repr=False)
    #: the term's settings elements as written in its file -> line (messages name what the file says)
    element_lines: Mapping[str, int | None] = attrs.field(factory=dict, eq=False, repr=False)

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        for method in _GUARDED_METHODS:
            func = cls.__dict__.get(method)
            if isinstance(func, types.FunctionType):
                setattr(cls, method, _GuardedMethod(func))

    # ----- construction from settings -------------------------------------------------
    @classmethod
    def xml_fields(cls) -> dict[str, Any]:
        """Settings element name -> annotated type, for every settable field."""
        hints = typing.get_type_hints(cls)
        return {f.name: hints[f.name] for f in attrs.fields(cls) if f.name not in _NOT_XML}

    @classmethod
    def element_spellings(cls, name: str) -> tuple[str, ...]:
        """Every settings element that sets field ``name`` (or its ``*_list`` form): the field,
        its list form (one term per item) and its aliases, e.g. ``coordinate``, ``coordinate_list``."""
        singular = LIST_TO_SINGULAR.get(name, name)
        out = [singular] + [plural for plural, single in LIST_TO_SINGULAR.items() if single == singular]
        out += [alias for alias, target in cls.aliases.items() if target in (name, singular)]
        if name not in out:
            out.insert(0, name)
        return tuple(out)

    @classmethod
    def _missing_required(cls, given: set[str]) -> list[str]:
        """Required fields (no default) that none of ``given`` (field names) sets."""
        return [f.name for f in attrs.fields(cls)
                if f.default is attrs.NOTHING and f.init and f.name not in _NOT_XML and f.name not in given]

    @classmethod
    def from_spec(cls, spec: TermSpec) -> list[Term]:
        """Instantiate from settings; a ``*_list`` element gives one term per item.

        Unknown elements are errors naming the element and listing the valid ones.
        """
        fields = cls.xml_fields()
        raw: dict[str, str] = {}
        # several lists (e.g. <marker_list> and <axes>) give one term per combination
        splits: dict[str, list[str]] = {}
        for element, text in spec.fields.items():
            if element in ("type",):
                continue
            target = cls.aliases.get(element, element)
            singular = LIST_TO_SINGULAR.get(target)
            if target not in fields and singular in fields:
                split_values = text.split()
                if singular == "axis":  # "xyz", "x z" or "x,y": one term per named axis
                    split_values = [c for c in text.lower() if c in "xyz"]
                repeated = sorted({v for v in split_values if split_values.count(v) > 1}, key=split_values.index)
                if repeated:  # one term per name: a name listed twice would be weighted twice
                    raise InputError(
                        f"{', '.join(repr(v) for v in repeated)} listed more than once in term '{cls.type}'",
                        file=spec.source.file,
                        line=spec.field_lines.get(element, spec.source.line),
                        element=f"<{element}>",
                        expected=f"each name once in <{element}>",
                    )
                splits[singular] = split_values
                continue
            if target not in fields:
                raise InputError(
                    f"element <{element}> is not a field of term type '{cls.type}'",
                    file=spec.source.file,
                    line=spec.field_lines.get(element, spec.source.line),
                    element=f"<{spec.kind == 'cost' and 'RCNLCostTerm' or 'RCNLConstraintTerm'}>",
                    expected="one of " + ", ".join(sorted(set(fields) - {"name"})),
                )
            raw[target] = text
        values: dict[str, Any] = {}
        attributes = attrs.fields_dict(cls)
        for key, text in raw.items():
            if text.strip() == "" and key in ("max_allowable_error", "error_center", "max_error", "min_error"):
                default = attributes[key].default
                warnings.warn(
                    f"{spec.source.file}:{spec.field_lines.get(key, spec.source.line)}: empty <{key}> in "
                    f"term '{cls.type}' treated as absent (default {_number(default)} used)",
                    stacklevel=2,
                )
                continue
            element, line = _as_written(cls, spec.field_lines, key, spec.source.line)
            try:
                values[key] = _convert(text, fields[key])
            except (TypeError, ValueError) as exc:
                raise InputError(
                    f"cannot read {element} = '{text}' of term '{cls.type}': {exc}",
                    file=spec.source.file,
                    line=line,
                    expected=f"{getattr(fields[key], '__name__', fields[key])}",
                ) from exc
            if key in _FINITE_FIELDS and isinstance(values[key], float) and not math.isfinite(values[key]):
                raise InputError(f"term '{cls.type}': '{text.strip()}' is not a finite number", file=spec.source.file,
                                 line=line, element=element, expected="a finite number")
        term_element = f"<{'RCNLCostTerm' if spec.kind == 'cost' else 'RCNLConstraintTerm'}>"
        missing = cls._missing_required(set(values) | set(splits))
        if missing:
            raise InputError(
                f"term '{cls.type}' has no " + " and no ".join(f"<{name}>" for name in missing),
                file=spec.source.file,
                line=spec.source.line,
                element=term_element,
                expected="; ".join(" or ".join(f"<{e}>" for e in cls.element_spellings(name)) for name in missing),
            )
        element_lines = {element: spec.field_lines.get(element) for element in spec.fields}
        keys = list(splits)
        out: list[Term] = []
        for combination in itertools.product(*(splits[k] for k in keys)):
            kw = dict(values)
            kw.update(zip(keys, combination))
            try:
                out.append(cls(source=spec.source, element_lines=element_lines, **kw))
            except TermValueError as exc:
                element, line = _as_written(cls, element_lines, exc.field, spec.source.line)
                raise InputError(f"term '{cls.type}': {exc}", file=spec.source.file, line=line, element=element,
                                 expected=exc.expected) from exc
            except (TypeError, ValueError) as exc:
                raise InputError(f"term '{cls.type}': {exc}", file=spec.source.file, line=spec.source.line,
                                 element=term_element) from exc
        return out

    # ----- binding and errors ------------------------------------------------------------
    def bind(self, ctx: TermContext) -> None:
        """Check names against the model and data once, before any solve. Override."""

    def error(self, message: str, *, element: str | None = None, expected: str | None = None) -> InputError:
        """An :class:`InputError` pointing at this term's declaration.

        ``element`` (e.g. ``"<coordinate_list>"``) is named as the settings file spells it
        (``<coordinate>`` when the term gives a single ``<coordinate>``), at its line.
        """
        label = f"term '{self.type}'" + (f" ({self.name})" if self.name else "")
        line = self.source.line
        if element and element.count("<") == 1 and element.startswith("<") and element.endswith(">"):
            element, line = _as_written(type(self), self.element_lines, element[1:-1], line)
        return InputError(
            f"{label}: {message}",
            file=self.source.file,
            line=line,
            element=element,
            expected=expected,
        )

    @property
    def label(self) -> str:
        """Short unique-ish label used in reports: type plus the selected component."""
        parts = [self.type]
        for key in ("coordinate", "load", "muscle", "force", "moment", "marker", "controller", "body",
                    "hindfoot_body", "synergy", "synergy_group", "axis"):
            value = getattr(self, key, None)
            if value not in (None, ""):
                parts.append(str(value))
        return ":".join(parts)


def _location(file: str | None, line: int | None) -> str:
    """``"FILE:LINE: "`` (or what is known of it) for warnings."""
    if not file:
        return "" if line is None else f"line {line}: "
    return f"{file}:{line}: " if line is not None else f"{file}: "


def _number(value: Any) -> str:
    return f"{value:g}" if isinstance(value, (int, float)) else repr(value)


#: Term fields that are not settings elements
_NOT_XML = ("source", "element_lines")


def _as_written(cls: type[Term], element_lines: Mapping[str, int | None], name: str,
                line: int | None) -> tuple[str, int | None]:
    """``<name>`` as the term's settings spell it (``<coordinate>`` for ``coordinate_list``,
    ``<max_value>`` for ``max_error``, ...) and its line; ``<name>`` at ``line`` if not written."""
    for spelling in cls.element_spellings(name):
        if spelling in element_lines:
            return f"<{spelling}>", element_lines[spelling] or line
    return f"<{name}>", line


def _positive(instance: Any, attribute: attrs.Attribute, value: float) -> None:
    if not value > 0:
        raise TermValueError(f"'{attribute.name}' must be > 0 (got {value})", field=attribute.name,
                             expected="a number > 0")


@attrs.frozen(kw_only=True)
class CostTerm(Term):
    """A cost term: raw quantity -> ((value - error_center) / max_allowable_error)^2, reduced by the tool."""

    kind: ClassVar[str] = "cost"

    max_allowable_error: float = attrs.field(default=1.0, validator=_positive)
    error_center: float = 0.0

    def quantity(self, ctx: Any) -> Any:
        """The raw quantity (CasADi expression or array). Override."""
        raise NotImplementedError(f"{type(self).__name__}.quantity")

    def normalized(self, ctx: Any) -> Any:
        """``(quantity - error_center) / max_allowable_error``; a quantity given as a tuple of
        blocks (reduced one by one by the tool, e.g. one per foot) gives the tuple of normalized
        blocks. Override only for non-standard forms."""
        quantity = self.quantity(ctx)
        if isinstance(quantity, tuple):
            return tuple((block - self.error_center) / self.max_allowable_error for block in quantity)
        return (quantity - self.error_center) / self.max_allowable_error

    def residuals(self, ctx: TermContext) -> Any:
        """Residuals whose squared sum is this term's objective contribution."""
        return ctx.reduce_cost(self, self.normalized(ctx))


@attrs.frozen(kw_only=True)
class ConstraintTerm(Term):
    """A constraint term: ``min_error <= value <= max_error`` after the tool's scaling."""

    kind: ClassVar[str] = "constraint"
    aliases: ClassVar[dict[str, str]] = {"max_value": "max_error", "min_value": "min_error"}

    max_error: float = 1.0
    min_error: float = -1.0

    def __attrs_post_init__(self) -> None:
        if self.min_error > self.max_error:
            raise TermValueError(f"min_error {self.min_error} > max_error {self.max_error}", field="min_error",
                                 expected="<min_error> <= <max_error>")

    def value(self, ctx: Any) -> Any:
        """The constrained quantity (CasADi expression). Override."""
        raise NotImplementedError(f"{type(self).__name__}.value")

    def bounded(self, ctx: TermContext) -> tuple[Any, Any, Any]:
        """``(expression, lower, upper)`` after the tool's scaling."""
        return ctx.reduce_constraint(self, self.value(ctx))
