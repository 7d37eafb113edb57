"""Reading a settings file: parse with line numbers, upgrade an older schema in memory (with a
warning), check the root, version and tool element."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

from nmsm.errors import InputError
from nmsm.io.settings.document import (
    OPENSIM_TOOL_FILES,
    PIPELINE_VERSION_TEXT,
    ROOT,
    SettingsDocument,
    check_version,
    elements,
    parse_settings_xml,
    tool_element_of,
)
from nmsm.io.settings import upgrade_released
from nmsm.io.settings.upgrade import detect_schema, upgrade_tree


def read_settings_document(
    path: str | os.PathLike[str], *, check_paths: bool = True, upgrade: bool = True
) -> SettingsDocument:
    """Parse a settings file; older schemas are upgraded in memory with a warning.

    ``check_paths=False`` resolves paths without requiring them to exist (templates,
    upgrade previews).
    """
    path = Path(path)
    root = parse_settings_xml(path)
    upgraded_from = None
    schema = detect_schema(root)
    if schema != "current":
        if not upgrade:
            raise InputError(
                f"old settings schema ({schema})",
                file=path,
                line=root.sourceline,
                element=f"<{root.tag}>",
                expected=f"<{ROOT} Version=\"{PIPELINE_VERSION_TEXT}\"> (run 'nmsm upgrade-settings')",
            )
        result = upgrade_tree(root, path)
        warnings.warn(
            f"{path}: old settings schema ({schema}) upgraded in memory; save the current form with "
            f"'nmsm upgrade-settings {path.name} -o NEW.xml'",
            stacklevel=2,
        )
        for note in result.notes:
            warnings.warn(f"{path}: {note}", stacklevel=2)
        root = result.root
        upgraded_from = schema
    elif upgrade and root.tag == ROOT and upgrade_released.needed(root):
        result = upgrade_tree(root, path)
        for note in result.notes:
            warnings.warn(f"{path}: {note}", stacklevel=2)
        root = result.root
    if root.tag != ROOT:
        inner = next(iter(elements(root)), None)
        use = OPENSIM_TOOL_FILES.get(str(inner.tag)) if root.tag == "OpenSimDocument" and inner is not None else None
        if use is not None:
            raise InputError(
                f"root element is <{root.tag}> holding <{inner.tag}>: an OpenSim file, "
                "not the settings of an NMSM tool that 'nmsm run' runs",
                file=path,
                line=inner.sourceline,
                element=f"<{inner.tag}>",
                expected=f"<{ROOT}> (an NMSM settings file); {use}",
            )
        raise InputError(
            f"root element is <{root.tag}>",
            file=path,
            line=root.sourceline,
            element=f"<{root.tag}>",
            expected=f"<{ROOT}> (an NMSM settings file)",
        )
    version = check_version(root, path)
    tool = tool_element_of(root, path)
    return SettingsDocument(
        path=path, root=root, tool_element=tool, version=version, upgraded_from=upgraded_from, check_paths=check_paths
    )
