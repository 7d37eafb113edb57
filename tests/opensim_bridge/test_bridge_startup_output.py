"""Output printed to the worker's standard output before it can move it away (a
``sitecustomize.py``, a ``.pth`` file, a wrapper set as ``NMSM_OPENSIM_PYTHON``) lands in the
reply pipe: the client skips it up to the worker's start-up token, and garbage in the pipe is
a BridgeError naming the interpreter, never a MemoryError or an UnpicklingError."""

from __future__ import annotations

import io
import pickle
import struct
import sys
from pathlib import Path

import pytest

from nmsm.errors import BridgeError
from nmsm.opensim_bridge import client
from nmsm.opensim_bridge.client import BridgeProtocolError, OpenSimBridge, await_sync, receive_message


def _script(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    path.chmod(0o755)
    return path


def test_a_printing_sitecustomize_does_not_break_the_bridge(bridge, tmp_path: Path, monkeypatch) -> None:
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text('print("hello from sitecustomize")\n', encoding="utf-8")
    monkeypatch.setenv("PYTHONPATH", str(site))
    worker = OpenSimBridge()
    try:
        assert "4." in worker.call("opensim_version")
        assert "hello from sitecustomize" in worker.log_path.read_text(encoding="utf-8")
    finally:
        worker.close()


@pytest.mark.skipif(sys.platform == "win32", reason="a shell-script wrapper")
def test_a_wrapper_that_prints_before_starting_python(bridge, tmp_path: Path) -> None:
    wrapper = _script(tmp_path / "wrapped_python",
                      f'#!/bin/sh\necho "activating environment..."\nprintf "no newline"\nexec "{client.opensim_python()}" "$@"\n')
    worker = OpenSimBridge(python=str(wrapper))
    try:
        assert "4." in worker.call("opensim_version")
        assert "activating environment...\nno newline" in worker.log_path.read_text(encoding="utf-8")
    finally:
        worker.close()


@pytest.mark.skipif(sys.platform == "win32", reason="a shell-script wrapper")
def test_an_interpreter_that_prints_and_exits_is_a_bridge_error(tmp_path: Path) -> None:
    wrapper = _script(tmp_path / "broken_python", "#!/bin/sh\necho 'conda: environment nmsm not found'\nexit 3\n")
    with pytest.raises(BridgeError) as caught:
        OpenSimBridge(python=str(wrapper))
    message = str(caught.value)
    assert str(wrapper) in message and "exit code 3" in message
    assert "conda: environment nmsm not found" in message  # the log tail


@pytest.mark.skipif(sys.platform == "win32", reason="a shell-script wrapper")
def test_endless_start_up_output_is_a_bridge_error(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(client, "MAX_PREAMBLE", 10_000)
    wrapper = _script(tmp_path / "chatty_python", "#!/bin/sh\nyes 'chatter' | head -c 50000\nexec sleep 60\n")
    with pytest.raises(BridgeError) as caught:
        OpenSimBridge(python=str(wrapper))
    message = str(caught.value)
    assert str(wrapper) in message and "more than 10000 bytes" in message and "chatter" in message


_GARBAGE_REPLY = f"""#!{sys.executable}
import os, sys, time
from nmsm.opensim_bridge.client import SYNC_TOKEN
os.write(1, SYNC_TOKEN + b"garbage!\\n" * 4)  # token, then text instead of a reply
time.sleep(60)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="a script as interpreter")
def test_garbage_after_the_token_is_a_bridge_error_and_stops_the_worker(tmp_path: Path) -> None:
    fake = _script(tmp_path / "fake_python", _GARBAGE_REPLY)  # the client puts nmsm on its PYTHONPATH
    with pytest.raises(BridgeError) as caught:
        OpenSimBridge(python=str(fake))
    message = str(caught.value)
    assert str(fake) in message and "'ping'" in message and "not a bridge message" in message


def test_await_sync_returns_what_came_before_and_leaves_what_follows() -> None:
    stream = io.BufferedReader(io.BytesIO(b"printed\n" + client.SYNC_TOKEN + b"reply"))
    assert await_sync(stream) == b"printed\n"
    assert stream.read() == b"reply"


def test_await_sync_at_end_of_stream_keeps_the_output() -> None:
    with pytest.raises(EOFError) as caught:
        await_sync(io.BytesIO(b"only this"))
    assert caught.value.preamble == b"only this"


def test_a_garbage_length_header_is_refused_before_allocating() -> None:
    with pytest.raises(BridgeProtocolError, match="declares .* more than the limit"):
        receive_message(io.BytesIO(b"hello from sitecustomize\n"))


def test_a_garbage_payload_is_a_protocol_error() -> None:
    with pytest.raises(BridgeProtocolError, match="not a valid pickle"):
        receive_message(io.BytesIO(struct.pack("<Q", 8) + b"garbage!"))
    data = pickle.dumps(("ok", 1))
    assert receive_message(io.BytesIO(struct.pack("<Q", len(data)) + data)) == ("ok", 1)
