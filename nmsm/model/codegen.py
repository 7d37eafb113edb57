"""Optional C code generation of CasADi functions, cached by content hash.

:func:`compiled` generates C for a CasADi Function, compiles it into a shared library with
the system C compiler and returns the loaded ``casadi.external`` Function; the library is
kept in ``$NMSM_CACHE_DIR/codegen`` (or ``~/.cache/nmsm/codegen``) under the hash of the
function's serialized form, so a model's functions compile once. Nothing in nmsm requires
it: without a compiler, or on failure, :func:`compiled` returns the original function
(``strict=False``) or raises (``strict=True``).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import warnings
from pathlib import Path

import casadi as cs

from nmsm.errors import NmsmError


def codegen_dir() -> Path:
    env = os.environ.get("NMSM_CACHE_DIR")
    return (Path(env) if env else Path.home() / ".cache" / "nmsm") / "codegen"


def compiler() -> str | None:
    """The C compiler to use (``$CC``, ``cc`` or ``gcc``), or None."""
    for candidate in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if candidate and shutil.which(candidate):
            return candidate
    return None


def compiled(function: cs.Function, *, optimization: str = "-O1", strict: bool = False) -> cs.Function:
    """``function`` as compiled C (see module docstring)."""
    cc = compiler()
    if cc is None:
        if strict:
            raise NmsmError("no C compiler found for code generation (set CC)")
        warnings.warn("no C compiler found; using the CasADi virtual machine", stacklevel=2)
        return function
    key = hashlib.sha256(function.serialize().encode() + optimization.encode()).hexdigest()[:24]
    name = function.name()
    folder = codegen_dir()
    folder.mkdir(parents=True, exist_ok=True)
    library = folder / f"{name}_{key}.so"
    if not library.is_file():
        source = folder / f"{name}_{key}.c"
        generator = cs.CodeGenerator(source.name, {"with_header": False})
        generator.add(function)
        generator.generate(str(folder) + os.sep)
        tmp = library.with_suffix(".so.tmp")
        command = [cc, "-shared", "-fPIC", optimization, str(source), "-o", str(tmp), "-lm"]
        result = subprocess.run(command, capture_output=True, text=True)
        source.unlink(missing_ok=True)
        if result.returncode != 0:
            tmp.unlink(missing_ok=True)
            if strict:
                raise NmsmError(f"compiling {name} failed: {result.stderr[-2000:]}")
            warnings.warn(f"compiling {name} failed; using the CasADi virtual machine", stacklevel=2)
            return function
        os.replace(tmp, library)
    return cs.external(name, str(library))
