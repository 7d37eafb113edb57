"""``nmsm vaf``: activations must be non-negative (NMF). Values down to -0.01 are a solver's
bound tolerance (the shared NCP result ``synergy_kick_tutorial/ncpResults`` reaches -0.0036)
and are set to 0; lower ones are refused, naming the file, line, row, time and column."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import table_from_columns, write_storage
from nmsm.tools.ncp.vaf import read_activation_trials, vaf_curve


def _activations(folder: Path, value: float, *, row: int = 14) -> Path:
    """A 30-row activation file of three muscles with ``value`` at ``row`` of 'soleus_r'."""
    time = np.linspace(0.0, 0.29, 30)
    columns = {m: 0.2 + 0.1 * np.sin(time * k) for k, m in enumerate(("tibant_r", "soleus_r", "vasmed_r"), 1)}
    columns["soleus_r"][row] = value
    return write_storage(folder / "trial_1.sto", table_from_columns(time, columns, name="muscleActivations"))


def test_clearly_negative_activation_is_refused(tmp_path: Path) -> None:
    path = _activations(tmp_path, -0.5)
    lines = path.read_text().splitlines()
    line = next(k for k, text in enumerate(lines, 1) if "-0.5" in text.split())
    with pytest.raises(InputError) as caught:
        read_activation_trials([tmp_path])
    message = str(caught.value)
    assert message.startswith(f"{path}:{line}: column 'soleus_r': negative activation -0.5 in data row 15 "
                              "(time 0.14 s)")
    assert "activations >= 0" in message
    with pytest.raises(InputError, match="is negative"):
        vaf_curve(np.array([[0.1, -0.5], [0.2, 0.3]]))


def test_slightly_negative_activations_are_set_to_zero(tmp_path: Path) -> None:
    _activations(tmp_path, -0.003)
    with pytest.warns(UserWarning, match=r"1 slightly negative activation\(s\), the lowest -0.003 \('soleus_r', "
                                         r"time 0.14 s\), set to 0"):
        data, names = read_activation_trials([tmp_path])
    assert data.min() == 0.0 and data[14, names.index("soleus_r")] == 0.0


def test_round_off_negatives_pass_silently(tmp_path: Path) -> None:
    _activations(tmp_path, -1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        data, _ = read_activation_trials([tmp_path])
    assert data.min() == 0.0
