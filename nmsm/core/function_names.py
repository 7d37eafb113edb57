"""Valid CasADi function names from user-given names.

CasADi accepts a function (or ``nlpsol``) name only if it starts with an ASCII letter and
continues with letters, digits and single underscores (``Function::check_name``). Names
built from a trial file name (``gait.1``, ``Gang ü1``), a model's body, joint or marker name
(``R.ASIS``) or a contact surface name would otherwise stop a run with CasADi's
``Function name is not valid`` traceback. The name is only a label (logs, generated code),
so the other characters are simply replaced.
"""

from __future__ import annotations

import re

_NOT_NAME = re.compile(r"[^A-Za-z0-9]+")
_KEYWORDS = frozenset({"null", "jac", "hess"})


def function_name(*parts: object) -> str:
    """``parts`` joined by ``_`` as a valid CasADi name: ``("mtp_activation", "gait.1")`` ->
    ``mtp_activation_gait_1``; runs of other characters become one ``_``."""
    text = _NOT_NAME.sub("_", "_".join(str(part) for part in parts)).strip("_")
    text = re.sub(r"_+", "_", text)
    if not text or not ("a" <= text[0].lower() <= "z"):
        text = "f_" + text if text else "f"
    return text + "_f" if text in _KEYWORDS else text
