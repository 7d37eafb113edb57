"""Optional C code generation: same numbers as the CasADi virtual machine, cached."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from nmsm.model.codegen import compiled, compiler


@pytest.mark.skipif(compiler() is None, reason="no C compiler on this machine")
def test_compiled_inverse_dynamics_equals_virtual_machine(shared_data: Path, tmp_path: Path, monkeypatch) -> None:
    from nmsm.model import CasadiModel, load_model

    monkeypatch.setenv("NMSM_CACHE_DIR", str(tmp_path))
    cm = CasadiModel(load_model(shared_data / "jmp" / "toy_simple_arm" / "simple_arm.osim"))
    f = cm.inverse_dynamics_function()
    fast = compiled(f, strict=True)
    libraries = list((tmp_path / "codegen").glob("*.so"))
    assert len(libraries) == 1
    rng = np.random.default_rng(61)
    for _ in range(3):
        x = rng.normal(size=(3, cm.n))
        assert np.allclose(np.array(fast(*x)), np.array(f(*x)), rtol=1e-13, atol=1e-12)
    again = compiled(f, strict=True)  # loaded from the cache, not rebuilt
    assert list((tmp_path / "codegen").glob("*.so")) == libraries
    assert np.allclose(np.array(again(*x)), np.array(f(*x)), rtol=1e-13, atol=1e-12)
