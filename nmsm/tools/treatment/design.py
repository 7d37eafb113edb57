"""Design Optimization extras (docs/treatment.md): static parameters and model functions.

``<RCNLParameterTermSet>``: each ``<RCNLParameterTerm>`` declares a static design variable
block named by its ``type`` (``initial_values``, ``lower_bounds``, ``upper_bounds``; one
value per entry), available to terms as ``ctx.parameter(type)`` (MX column) and to model
modifiers. ``<model_functions>``: names of registered model modifiers
(:class:`~nmsm.core.plugin_bases.ModelModifier`) applied in order before the terms are
built. The solution's parameters are written to ``<trial>_parameterSolution.xml``
(``NMSMPipelineDocument/RCNLParameters/RCNLParameterSet{type, values}``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from lxml import etree

from nmsm.core.registry import get_registry
from nmsm.errors import InputError, RegistryError

PARAMETER_PREFIX = "parameter:"


def design_extras(settings: Any) -> Callable[[Any, Any], None]:
    """``declare_extra(problem, data)`` for :func:`~nmsm.tools.treatment.formulation.build_problem`."""

    def declare(problem: Any, data: Any) -> None:
        seen: set[str] = set()
        for term in getattr(settings, "parameter_terms", ()):
            if term.type in seen:
                raise InputError(f"parameter type '{term.type}' is declared twice", file=term.source.file,
                                 line=term.source.line, element="<RCNLParameterTerm>", expected="one term per type")
            seen.add(term.type)
            data.parameters[term.type] = problem.variable(
                PARAMETER_PREFIX + term.type, np.asarray(term.initial_values, dtype=float),
                np.asarray(term.lower_bounds, dtype=float), np.asarray(term.upper_bounds, dtype=float),
            )
        modifiers = model_modifiers(settings)
        if modifiers:
            from nmsm.tools.treatment.modifiers import ModificationTarget

            target = ModificationTarget(data, settings)
            for modifier in modifiers:
                modifier.apply(target, data.parameters)

    return declare


def model_modifiers(settings: Any) -> list[Any]:
    """Instances of the modifiers named in ``<model_functions>`` (registry, tool DO)."""
    registry = get_registry()
    out = []
    for name in getattr(settings, "model_functions", ()):
        try:
            cls = registry.get("modifier", name, "DO")
        except RegistryError as exc:
            raise InputError(str(exc), file=settings.settings_file, element="<model_functions>",
                             expected="names of installed model modifiers (nmsm plugins)") from exc
        out.append(cls(name, str(settings.settings_file)))
    return out


def parameter_values(prepared: Any, tsol: Any) -> dict[str, np.ndarray]:
    """Solved value of every static parameter (type -> (n,) array)."""
    values = tsol.solution.values
    return {name: np.asarray(values[PARAMETER_PREFIX + name]).ravel()
            for name in prepared.data.parameters if PARAMETER_PREFIX + name in values}


def parameter_tables(prepared: Any, tsol: Any) -> dict[str, Any]:
    """Extra tables to write for DO (none: parameters go to the XML file)."""
    return {}


def write_parameter_solution(stage: Path, prepared: Any, tsol: Any) -> list[Path]:
    """``<trial>_parameterSolution.xml`` when the problem has static parameters."""
    values = parameter_values(prepared, tsol)
    if not values:
        return []
    root = etree.Element("NMSMPipelineDocument", Version="1.5.0")
    parameters = etree.SubElement(root, "RCNLParameters")
    for name, v in values.items():
        entry = etree.SubElement(parameters, "RCNLParameterSet")
        etree.SubElement(entry, "type").text = name
        etree.SubElement(entry, "values").text = " ".join(repr(float(x)) for x in v)
    path = stage / f"{tsol.trial_name}_parameterSolution.xml"
    path.write_bytes(etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8"))
    return [path, *write_design_model(stage, prepared, tsol)]


def write_design_model(stage: Path, prepared: Any, tsol: Any) -> list[Path]:
    """``<model>DesignOpt.osim``: the input model with the solution's joint-frame
    parameters written in place (the rest of the file untouched), when model functions made
    the model parametric (:mod:`nmsm.modifiers.joint_frame`)."""
    from nmsm.model.osim_writer import OsimWriter

    data = prepared.data
    model = data.model
    if not getattr(model, "parameter_count", 0):
        return []
    values = np.asarray(tsol.value(data.model_parameter_values), dtype=float).ravel()
    source = Path(model.file)
    writer = OsimWriter(source)
    writer.apply_parameters(model.parameters, values)
    return [writer.write(stage / f"{source.stem}DesignOpt.osim")]
