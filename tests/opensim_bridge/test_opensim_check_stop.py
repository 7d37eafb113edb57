"""Ctrl-C while nmsm checks that OpenSim can be imported: the check's process is killed and
reaped, so the stop prints no "subprocess ... is still running" warning after its message."""

from __future__ import annotations

import gc
import os
import signal
import threading
import time
import warnings
from pathlib import Path

import pytest

from nmsm.opensim_bridge import client

pytestmark = pytest.mark.usefixtures("default_sigint")  # also when pytest runs in the background (SIGINT ignored)


def test_a_stop_during_the_opensim_check_leaves_no_running_process(tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    slow = tmp_path / "slow_python"
    slow.write_text("#!/bin/sh\nexec sleep 30\n", encoding="utf-8")
    slow.chmod(0o755)
    monkeypatch.setenv("NMSM_OPENSIM_PYTHON", str(slow))
    monkeypatch.setattr(client, "_AVAILABLE", None)
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    started = time.monotonic()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        timer.start()
        try:
            client.opensim_available()
        except KeyboardInterrupt:
            stopped = True
        else:
            stopped = False
        finally:
            timer.cancel()
        gc.collect()
    assert stopped and time.monotonic() - started < 10
    assert client._AVAILABLE is None  # a stopped check decides nothing
    assert not [w for w in caught if issubclass(w.category, ResourceWarning)], [str(w.message) for w in caught]
