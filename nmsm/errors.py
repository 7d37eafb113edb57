"""Exceptions raised by nmsm.

Every error about user input names the file, the element or column, and what was
expected, so a user can fix the input without reading nmsm's source.
"""

from __future__ import annotations

import errno
from os import PathLike


class NmsmError(Exception):
    """Base class of every error nmsm raises on purpose."""


class InputError(NmsmError, ValueError):
    """Bad user input: a settings file, a data table, a model or a name in them.

    The message is assembled as ``FILE:LINE: <element>: message (expected ...)``
    from the parts that are known.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | PathLike[str] | None = None,
        line: int | None = None,
        element: str | None = None,
        expected: str | None = None,
    ) -> None:
        self.file = None if file is None else str(file)
        self.line = line
        self.element = element
        self.expected = expected
        self.detail = message
        super().__init__(self._compose())

    def _compose(self) -> str:
        where = ""
        if self.file:
            where = self.file if self.line is None else f"{self.file}:{self.line}"
            where += ": "
        if self.element:
            where += f"{self.element}: "
        text = where + self.detail
        if self.expected:
            text += f" (expected {self.expected})"
        return text


class ModelError(InputError):
    """An OpenSim model that nmsm cannot represent or that is inconsistent."""


class TermValueError(ValueError):
    """A term field's value is out of its range (raised by a term's field validators).

    ``field`` is the field (settings element) at fault and ``expected`` what it accepts, so
    the settings reader can name the element, its line and the accepted values in the
    :class:`InputError` it raises.
    """

    def __init__(self, message: str, *, field: str, expected: str | None = None) -> None:
        super().__init__(message)
        self.field = field
        self.expected = expected


class RegistryError(NmsmError):
    """A plugin problem: duplicate names, unknown names, bad registrations."""


class SolverError(NmsmError):
    """An optimization that failed; carries the path of the saved last iterate."""

    def __init__(self, message: str, *, last_iterate_path: str | None = None) -> None:
        self.last_iterate_path = last_iterate_path
        if last_iterate_path:
            message += f" (last iterate and diagnosis saved in {last_iterate_path})"
        super().__init__(message)


class BridgeError(NmsmError):
    """An error reported by OpenSim running in the bridge's worker process."""


#: what to do about an operating-system error, by ``errno``
_OS_ADVICE = {
    errno.ENAMETOOLONG: "names of at most 255 bytes per file or folder name (and a shorter path): rename or move it",
    errno.ENOSPC: "free space on that disk, or results written to another disk (nmsm run -o RESULTS_DIR); "
                  "nothing half-written was left",
    errno.EDQUOT: "disk quota left, or results written elsewhere (nmsm run -o RESULTS_DIR)",
    errno.EROFS: "a writable file system (nmsm run -o RESULTS_DIR writes elsewhere)",
    errno.EACCES: "permission to read or write that path",
    errno.EPERM: "permission to read or write that path",
}


def os_error(exc: OSError) -> InputError | None:
    """The :class:`InputError` naming the path and what to do for an operating-system error
    that input or the machine causes (a name too long, a full disk, no permission, a
    read-only file system); None for other errors."""
    advice = _OS_ADVICE.get(exc.errno) if exc.errno is not None else None
    if advice is None:
        return None
    return InputError(exc.strerror or str(exc), file=exc.filename, expected=advice)
