"""ForceSet group members of a model file (for ``nmsm vaf --group``)."""

from __future__ import annotations

import os

from nmsm.errors import InputError
from nmsm.io.names import close_matches


def group_members(model_file: str | os.PathLike[str], group: str) -> list[str]:
    """Members of ForceSet group ``group`` of the ``.osim`` model ``model_file`` (file order)."""
    from nmsm.model import load_model

    model = load_model(model_file)
    if group not in model.groups:
        close = close_matches(group, model.groups)
        raise InputError(
            f"'{group}' is not a ForceSet group of the model" + (f"; close matches: {', '.join(close)}" if close else ""),
            file=model_file,
            element="--group",
            expected="one of the model's groups: " + (", ".join(sorted(model.groups)) or "(none)"),
        )
    return model.group_members(group)
