"""Pointing a stage's input elements at the artifacts earlier stages produced.

For every :class:`~nmsm.tools.pipeline.kinds.Wire` of the stage's kind whose artifact is
available (from an earlier stage, or the pipeline file's starting inputs), the settings
element is rewritten to the artifact's path, unless the ``<Stage>`` keeps that element
(``keep_settings_inputs``). Kinds with settings-dependent wiring add a hook (below).
"""

from __future__ import annotations

from nmsm.tools.pipeline.artifacts import Artifacts
from nmsm.tools.pipeline.kinds import StageKind
from nmsm.tools.pipeline.stage_settings import StageSettings


def is_kept(key: str, keep: tuple[str, ...]) -> bool:
    """Whether element ``key`` (``a/b/element``) is named in ``keep`` (by key or last name)."""
    return key in keep or key.rsplit("/", 1)[-1] in keep


def wire_stage(kind: StageKind, settings: StageSettings, artifacts: Artifacts,
               keep: tuple[str, ...] = ()) -> dict[str, str]:
    """Rewrite the inputs of ``settings``; returns ``{element key: "artifact from source"}``."""
    wired: dict[str, str] = {}
    for wire in kind.wires:
        artifact = artifacts.get(wire.artifact)
        if artifact is None or is_kept(wire.key, keep):
            continue
        if wire.only_if_present and not settings.has_field(wire.key):
            continue
        settings.set_path(wire.key, artifact.path)
        wired[wire.key] = f"{wire.artifact} from {artifact.source}"
    hook = kind.load_hook()
    if hook is not None:
        wired.update(hook(settings, artifacts, keep))
    return wired


def tracking_initial_guess(settings: StageSettings, artifacts: Artifacts, keep: tuple[str, ...]) -> dict[str, str]:
    """Tracking Optimization's initial guess: NCP's results (synergy weights and commands)
    for a synergy-driven problem when NCP ran, else the tracked data folder."""
    key = "initial_guess_directory"
    if is_kept(key, keep):
        return {}
    synergy = settings.tool.find("RCNLSynergyController") is not None
    for name in (("ncp_results", "data_directory") if synergy else ("data_directory",)):
        artifact = artifacts.get(name)
        if artifact is not None:
            settings.set_path(key, artifact.path)
            return {key: f"{name} from {artifact.source}"}
    return {}
