"""Closing the OpenSim worker: a Ctrl-C while it shuts down kills it and still cleans up."""

from __future__ import annotations

import pytest


@pytest.fixture
def own_bridge(bridge):  # the session fixture checks that opensim is installed
    from nmsm.opensim_bridge.client import OpenSimBridge

    worker = OpenSimBridge()
    yield worker
    worker.close()


def _interrupted_wait(*args, **kwargs):
    raise KeyboardInterrupt


def test_ctrl_c_while_the_worker_shuts_down_kills_it_and_cleans_up(own_bridge, monkeypatch) -> None:
    process, folder = own_bridge._proc, own_bridge.workdir
    monkeypatch.setattr(process, "wait", _interrupted_wait)
    with pytest.raises(KeyboardInterrupt):
        own_bridge.close()
    monkeypatch.undo()
    assert process.wait(timeout=10) is not None  # killed, not left running
    assert own_bridge._proc is None and not folder.exists()
    assert own_bridge._requests.closed and own_bridge._replies.closed


def test_at_exit_the_interrupted_shutdown_is_quiet(own_bridge, monkeypatch) -> None:
    process = own_bridge._proc
    monkeypatch.setattr(process, "wait", _interrupted_wait)
    own_bridge._close_at_exit()  # no KeyboardInterrupt escapes (no traceback at interpreter exit)
    monkeypatch.undo()
    assert process.wait(timeout=10) is not None and own_bridge._proc is None
