"""The OpenSim worker talks over its standard input and output, which works on Windows too.

``subprocess.Popen(pass_fds=...)`` is POSIX-only (on Windows it fails: "pass_fds not supported
on Windows"), and a descriptor number passed on the command line means nothing to a Windows
child, so the bridge must not depend on either.
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path


from nmsm.opensim_bridge import client
from nmsm.opensim_bridge.client import OpenSimBridge, receive_message, send_message

REPO = Path(__file__).resolve().parents[2]


def test_worker_starts_and_answers_where_pass_fds_is_unsupported(bridge, monkeypatch) -> None:
    real_popen = subprocess.Popen

    def windows_like_popen(*args, **kwargs):
        if kwargs.get("pass_fds"):
            raise AssertionError("pass_fds not supported on Windows.")  # CPython's Windows _execute_child
        return real_popen(*args, **kwargs)

    monkeypatch.setattr(client.subprocess, "Popen", windows_like_popen)
    worker = OpenSimBridge()
    try:
        assert "4." in worker.call("opensim_version")
    finally:
        worker.close()
    assert not worker.workdir.exists()


_CHILD = r"""
import os, sys
from nmsm.opensim_bridge._opensim_worker import protocol_streams
from nmsm.opensim_bridge.client import receive_message, send_message
requests, replies = protocol_streams()
print("console output of a print")
sys.stdout.flush()
os.write(1, b"console output written to descriptor 1 (as OpenSim's C++ code does)\n")
message = receive_message(requests)
send_message(replies, ("echo", message))
"""


def test_console_output_of_the_worker_never_reaches_the_replies(tmp_path: Path) -> None:
    log = tmp_path / "worker.log"
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    with log.open("wb") as err:
        proc = subprocess.Popen([sys.executable, "-c", _CHILD], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=err, env=env, cwd=tmp_path)
        send_message(proc.stdin, {"x": "Müller data/ü.osim"})
        proc.stdin.close()
        reply = receive_message(proc.stdout)
        rest = proc.stdout.read()
        proc.stdout.close()
        assert proc.wait(timeout=60) == 0
    assert reply == ("echo", {"x": "Müller data/ü.osim"}) and rest == b""
    text = log.read_text(encoding="utf-8")
    assert "console output of a print" in text and "written to descriptor 1" in text


#: every byte value, and the ones a text-mode (Windows) pipe would change: CR LF, lone CR and LF, Ctrl-Z (EOF)
_ALL_BYTES = bytes(range(256)) + b"\r\n\n\r\x1a\r\n\x1a"


def test_every_byte_crosses_the_worker_pipes_unchanged(tmp_path: Path) -> None:
    """The worker's request and reply streams are binary: a pipe in text mode (newline
    translation, Ctrl-Z as end of file on Windows) would change these bytes or cut the message."""
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    with (tmp_path / "worker.log").open("wb") as err:
        proc = subprocess.Popen([sys.executable, "-c", _CHILD], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=err, env=env, cwd=tmp_path)
        send_message(proc.stdin, {"raw": _ALL_BYTES, "text": "line 1\r\nline 2\n\x1a"})
        proc.stdin.close()
        reply = receive_message(proc.stdout)
        proc.stdout.close()
        assert proc.wait(timeout=60) == 0
    assert reply == ("echo", {"raw": _ALL_BYTES, "text": "line 1\r\nline 2\n\x1a"})


def test_messages_round_trip_through_a_pipe() -> None:
    read, write = os.pipe()
    with os.fdopen(write, "wb") as out:
        send_message(out, ("model_info", {"path": "C:/Users/Müller/model.osim"}))
    with os.fdopen(read, "rb") as inp:
        assert receive_message(inp) == ("model_info", {"path": "C:/Users/Müller/model.osim"})
    assert pickle.HIGHEST_PROTOCOL >= 5
