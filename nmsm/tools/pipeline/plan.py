"""Checks of a pipeline before anything runs: stage order and every stage's inputs.

* Order: enabled stages must follow the kinds' order (:mod:`nmsm.tools.pipeline.kinds`);
  a stage after one of a later kind is an error naming both.
* Inputs: each required artifact must come from an earlier enabled stage, from the
  pipeline file's starting inputs, or from the stage's own settings (the element names an
  existing file or folder and is not rewired). Otherwise the error names the stage, the
  missing piece, and the three ways to provide it.
"""

from __future__ import annotations

from nmsm.tools.pipeline.artifacts import ARTIFACTS, INPUT_ELEMENTS
from nmsm.tools.pipeline.kinds import order_text, stage_kinds
from nmsm.tools.pipeline.pipeline_file import PipelineSpec, StageSpec
from nmsm.tools.pipeline.stage_settings import StageSettings
from nmsm.tools.pipeline.wiring import is_kept


def check_order(spec: PipelineSpec) -> None:
    """:class:`InputError` when an enabled stage comes after a stage of a later kind."""
    latest: StageSpec | None = None
    for stage in spec.stages:
        if not stage.enabled:
            continue
        if latest is not None and stage.kind.order < latest.kind.order:
            raise stage.error(
                f"cannot run after stage '{latest.name}' ({latest.kind.code}): {stage.kind.label} comes before "
                f"{latest.kind.label} in the pipeline",
                element="<StageList>",
                expected=f"stages in the order {order_text()}",
            )
        latest = stage


def _producers(artifact: str) -> list[str]:
    return [k.code for k in stage_kinds().values() if artifact in k.produces]


def _own_input(stage: StageSpec, settings: StageSettings, artifact: str) -> tuple[bool, str]:
    """Whether the stage's settings provide ``artifact`` themselves, and what they name."""
    described: list[str] = []
    for wire in stage.kind.wires_for(artifact):
        if not settings.has_field(wire.key):
            continue
        field = settings.field(wire.key)
        value = settings.resolve(field)
        if value is None:
            described.append(f"<{field.spec.element}> is empty")
            continue
        if value.exists():
            return True, str(value)
        described.append(f"<{field.spec.element}> names '{value}', which does not exist")
    return False, "; ".join(described) or "its settings have no such element"


def check_inputs(spec: PipelineSpec, settings: dict[str, StageSettings]) -> None:
    """:class:`InputError` for the first enabled stage lacking a required input."""
    available = set(spec.inputs)
    producer: dict[str, str] = {a: "the pipeline inputs" for a in spec.inputs}
    for stage in spec.stages:
        if not stage.enabled:
            continue
        stage_settings = settings[stage.name]
        for artifact in stage.kind.requires:
            wired = [w for w in stage.kind.wires_for(artifact) if not is_kept(w.key, stage.keep)]
            if artifact in available and wired:
                continue
            ok, described = _own_input(stage, stage_settings, artifact)
            if ok:
                continue
            ways = []
            makers = _producers(artifact)
            if makers and wired:
                ways.append("an earlier " + " or ".join(makers) + " stage")
            if artifact in INPUT_ELEMENTS and wired:
                ways.append(f"<{INPUT_ELEMENTS[artifact]}> in the pipeline's <PipelineTool>")
            elements = sorted({w.key for w in stage.kind.wires_for(artifact)})
            if elements:
                ways.append("an existing path in the stage settings' " + ", ".join(f"<{e}>" for e in elements))
            reason = f"{ARTIFACTS[artifact][1]} is missing: no earlier stage produces it"
            if artifact in available and not wired:
                reason = (f"{ARTIFACTS[artifact][1]} from {producer[artifact]} is not used "
                          f"(keep_settings_inputs) and the settings give none")
            raise stage.error(f"{reason} ({described})", element=f"<{stage.kind.tool_element}>",
                              expected=" or ".join(ways))
        for artifact in stage.kind.produces:
            available.add(artifact)
            producer[artifact] = f"stage '{stage.name}'"
