"""Deprecated location of the treatment term bases: import them from :mod:`nmsm.core.ocp`.

Kept so plugins written against earlier documentation still load; nothing in nmsm imports it.
"""

from nmsm.core.ocp import (  # noqa: F401  (re-exported names)
    TREATMENT_TOOLS,
    ContinuousCost,
    DiscreteCost,
    PathConstraint,
    TerminalConstraint,
    require_axis,
)
