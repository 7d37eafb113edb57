"""Client side of the OpenSim bridge: a persistent worker process running OpenSim.

OpenSim's Python wheel bundles its own CasADi, which clashes with ours in one process,
so OpenSim runs only in a worker started as a fresh interpreter (never forked). The
worker's current folder and ``opensim.log`` live in a private temporary folder, never in
the user's or the shared data folders.

Messages are pickled ``(command, kwargs)`` requests and ``(ok, result_or_error)`` replies
over the worker's standard input and output, the only pipes a child inherits the same way
on Linux, macOS and Windows (``subprocess``'s ``pass_fds`` is POSIX-only, and a file
descriptor number means nothing to a Windows child). The worker moves its standard output
to a private descriptor at once and points descriptor 1 at its log, so OpenSim's console
output (and any ``print``) goes to the worker's log file, never into the reply pipe.

Whatever reaches standard output before the worker can move it (a ``sitecustomize.py``, a
``.pth`` file, a wrapper set as ``NMSM_OPENSIM_PYTHON`` that prints before starting Python)
still lands in the reply pipe, so the worker first writes :data:`SYNC_TOKEN`; the client
skips everything before it (at most :data:`MAX_PREAMBLE` bytes, copied to the worker log).

Environment:
``NMSM_OPENSIM_PYTHON``  interpreter with ``opensim`` installed (default: this one).
"""

from __future__ import annotations

import atexit
import os
import pickle
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
from pathlib import Path
from typing import Any, BinaryIO

from nmsm.errors import BridgeError

_HEADER = struct.Struct("<Q")

#: written by the worker as soon as its standard output is private: what comes before it is not ours
SYNC_TOKEN = b"\x00\x01NMSM-OPENSIM-BRIDGE-SYNC-1\x01\x00"
#: the most start-up output (bytes) the client skips while looking for :data:`SYNC_TOKEN`
MAX_PREAMBLE = 1 << 20
#: the largest message (bytes) a header may declare; more means the pipe carries something else
MAX_MESSAGE = 1 << 32
_CHUNK = 1 << 24


class BridgeProtocolError(ValueError):
    """What arrived in a bridge pipe is not a bridge message (garbage length or pickle)."""


def send_message(stream: BinaryIO, obj: Any) -> None:
    data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(_HEADER.pack(len(data)))
    stream.write(data)
    stream.flush()


def receive_message(stream: BinaryIO) -> Any:
    header = stream.read(_HEADER.size)
    if len(header) < _HEADER.size:
        raise EOFError("bridge pipe closed")
    (size,) = _HEADER.unpack(header)
    if size > MAX_MESSAGE:
        raise BridgeProtocolError(
            f"a bridge message declares {size} bytes, more than the limit of {MAX_MESSAGE}: the header "
            f"{header!r} is not a bridge message header (something else wrote to the pipe)")
    chunks = []
    remaining = size
    while remaining:  # in bounded chunks: memory grows only with what really arrives
        chunk = stream.read(min(remaining, _CHUNK))
        if not chunk:
            raise EOFError(f"bridge pipe closed mid-message ({size - remaining} of {size} bytes received)")
        chunks.append(chunk)
        remaining -= len(chunk)
    data = b"".join(chunks)
    try:
        return pickle.loads(data)
    except Exception as exc:  # UnpicklingError, but garbage can raise almost anything
        raise BridgeProtocolError(
            f"a bridge message of {size} bytes is not a valid pickle ({type(exc).__name__}: {exc}); "
            f"it starts with {data[:60]!r}") from exc


def await_sync(stream: BinaryIO, limit: int | None = None) -> bytes:
    """Read ``stream`` up to and including :data:`SYNC_TOKEN`; return the bytes before it.

    Raises EOFError (with the bytes read in ``.preamble``) if the stream ends first and
    :class:`BridgeProtocolError` if more than ``limit`` bytes come before the token.
    """
    limit = MAX_PREAMBLE if limit is None else limit
    seen = bytearray()
    n = len(SYNC_TOKEN)
    while True:
        byte = stream.read(1)  # one at a time (buffered): not a byte past the token is consumed
        if not byte:
            error = EOFError(f"bridge pipe closed before the worker's start-up token ({len(seen)} bytes before)")
            error.preamble = bytes(seen)  # type: ignore[attr-defined]
            raise error
        seen += byte
        if seen[-n:] == SYNC_TOKEN:
            return bytes(seen[:-n])
        if len(seen) > limit + n:
            raise BridgeProtocolError(
                f"more than {limit} bytes arrived on the worker's standard output before its start-up "
                f"token; they start with {bytes(seen[:200])!r}")


def opensim_python() -> str:
    return os.environ.get("NMSM_OPENSIM_PYTHON") or sys.executable


def opensim_available() -> bool:
    """True when the bridge's interpreter can import ``opensim`` (checked in a subprocess)."""
    global _AVAILABLE
    if _AVAILABLE is None:
        try:
            with subprocess.Popen([opensim_python(), "-c", "import opensim"], stdin=subprocess.DEVNULL,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                  cwd=tempfile.gettempdir()) as proc:
                try:
                    proc.wait(timeout=120)
                except BaseException:  # timed out or stopped (Ctrl-C): killed and reaped, none left running
                    proc.kill()
                    proc.wait()
                    raise
            _AVAILABLE = proc.returncode == 0
        except (OSError, subprocess.TimeoutExpired):
            _AVAILABLE = False
    return _AVAILABLE


_AVAILABLE: bool | None = None


class OpenSimBridge:
    """A running OpenSim worker. Use :func:`get_bridge` for the shared one.

    >>> bridge = get_bridge()
    >>> info = bridge.call("model_info", path="model.osim")
    """

    def __init__(self, python: str | None = None) -> None:
        self.python = python or opensim_python()
        self.workdir = Path(tempfile.mkdtemp(prefix="nmsm-opensim-"))
        self.log_path = self.workdir / "worker.log"
        self._lock = threading.Lock()
        self._proc: subprocess.Popen[bytes] | None = None
        try:
            self._start()
        except BaseException:  # a failed or interrupted start leaves no worker, pipe or folder
            self.close()
            raise

    def _start(self) -> None:
        env = dict(os.environ)
        package_root = str(Path(__file__).resolve().parents[2])
        env["PYTHONPATH"] = package_root + os.pathsep + env.get("PYTHONPATH", "")
        env["NMSM_BRIDGE_WORKDIR"] = str(self.workdir)
        log = open(self.log_path, "ab")
        try:
            self._proc = subprocess.Popen(
                [self.python, "-m", "nmsm.opensim_bridge._opensim_worker"],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=log, cwd=self.workdir, env=env,
                close_fds=True,
            )
        finally:
            log.close()
        self._requests = self._proc.stdin
        self._replies = self._proc.stdout
        try:
            self._await_sync()
            ok, payload = self._exchange(("ping", {}))
        except BaseException:  # no half-started worker left running
            self._kill()
            raise
        if not ok:
            raise BridgeError(f"OpenSim worker failed to start: {payload}")

    def _log_tail(self, n: int = 30) -> str:
        try:
            lines = self.log_path.read_text(errors="replace", encoding="utf-8").splitlines()
        except OSError:
            return ""
        return "\n".join(lines[-n:])

    def _kill(self) -> None:
        if self._proc is not None and self._proc.poll() is None:
            self._proc.kill()
            try:
                self._proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
        self._close_streams()

    def _close_streams(self) -> None:
        """Close the request and reply pipes (errors of an already broken pipe ignored)."""
        for stream in (getattr(self, "_requests", None), getattr(self, "_replies", None)):
            try:
                if stream:
                    stream.close()
            except OSError:
                pass

    def _note_preamble(self, preamble: bytes) -> None:
        """Copy start-up output found before the sync token into the worker log."""
        if not preamble:
            return
        try:
            with open(self.log_path, "ab") as log:
                log.write(b"[nmsm] the worker's standard output before the bridge started (%d bytes, "
                          b"from sitecustomize, a .pth file or a wrapper interpreter; skipped):\n" % len(preamble))
                log.write(preamble if preamble.endswith(b"\n") else preamble + b"\n")
        except OSError:
            pass

    def _await_sync(self) -> None:
        """Skip whatever the interpreter printed before the worker's start-up token."""
        try:
            preamble = await_sync(self._replies)
        except EOFError as exc:
            self._note_preamble(getattr(exc, "preamble", b""))
            try:
                code = self._proc.wait(timeout=10) if self._proc else None
            except subprocess.TimeoutExpired:
                code = None
            raise BridgeError(
                f"OpenSim worker ({self.python}) stopped (exit code {code}) before it started the bridge: {exc}. "
                f"Is NMSM_OPENSIM_PYTHON a Python interpreter with nmsm's dependencies? "
                f"Worker log tail:\n{self._log_tail()}") from exc
        except BridgeProtocolError as exc:
            raise BridgeError(
                f"OpenSim worker ({self.python}) did not start the bridge: {exc}. Something in that interpreter's "
                f"start-up (sitecustomize, a .pth file, a wrapper) prints too much to standard output. "
                f"Worker log tail:\n{self._log_tail()}") from exc
        except OSError as exc:
            raise BridgeError(
                f"OpenSim worker ({self.python}): reading its start-up token failed: {exc}. "
                f"Worker log tail:\n{self._log_tail()}") from exc
        self._note_preamble(preamble)

    def _exchange(self, message: tuple[str, dict[str, Any]]) -> tuple[bool, Any]:
        try:
            send_message(self._requests, message)
            return receive_message(self._replies)
        except (EOFError, BrokenPipeError, OSError) as exc:
            code = self._proc.poll() if self._proc else None
            raise BridgeError(
                f"OpenSim worker ({self.python}) stopped (exit code {code}) during '{message[0]}': {exc}. "
                f"Is the 'opensim' package installed (pip install opensim)? Worker log tail:\n{self._log_tail()}"
            ) from exc
        except (BridgeProtocolError, pickle.UnpicklingError, MemoryError, struct.error) as exc:
            self._kill()  # the pipe is out of step: the next call starts a fresh worker
            raise BridgeError(
                f"OpenSim worker ({self.python}) sent a reply to '{message[0]}' that is not a bridge message "
                f"({type(exc).__name__}: {exc}); the worker is stopped. Worker log tail:\n{self._log_tail()}"
            ) from exc

    def call(self, command: str, **kwargs: Any) -> Any:
        """Run a worker command (see :mod:`nmsm.opensim_bridge.commands`); OpenSim errors raise BridgeError."""
        with self._lock:
            if self._proc is None or self._proc.poll() is not None:
                self._start()
            ok, payload = self._exchange((command, kwargs))
        if not ok:
            raise BridgeError(f"OpenSim ({command}): {payload}")
        return payload

    def close(self) -> None:
        """Stop the worker (asked to shut down, killed if it does not within 10 s or if this
        wait is interrupted), close the pipes and remove the working folder."""
        with self._lock:
            try:
                if self._proc is not None and self._proc.poll() is None:
                    try:
                        send_message(self._requests, ("shutdown", {}))
                        self._proc.wait(timeout=10)
                    except (OSError, AttributeError, subprocess.TimeoutExpired):
                        self._proc.kill()
                    except KeyboardInterrupt:
                        self._proc.kill()
                        raise
            finally:
                if self._proc is not None and self._proc.poll() is None:
                    self._proc.kill()
                    try:
                        self._proc.wait(timeout=10)  # reap the killed worker
                    except BaseException:  # noqa: BLE001 - already stopping; cleanup goes on
                        pass
                self._close_streams()
                self._proc = None
                shutil.rmtree(self.workdir, ignore_errors=True)

    def _close_at_exit(self) -> None:
        """:meth:`close` at interpreter exit, where a Ctrl-C during the worker's shutdown
        only hurries it (killed) instead of printing a traceback."""
        try:
            self.close()
        except KeyboardInterrupt:
            pass

    def __enter__(self) -> OpenSimBridge:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


_BRIDGE: OpenSimBridge | None = None


def get_bridge() -> OpenSimBridge:
    """The process-wide worker (started on first use, closed at exit)."""
    global _BRIDGE
    if _BRIDGE is None:
        _BRIDGE = OpenSimBridge()
        atexit.register(_BRIDGE._close_at_exit)
    return _BRIDGE
