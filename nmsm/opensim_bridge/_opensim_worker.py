"""The OpenSim worker process (``python -m nmsm.opensim_bridge._opensim_worker``).

Reads pickled ``(command, kwargs)`` requests from its standard input and writes
``(ok, payload)`` to its standard output (:func:`protocol_streams`: the same on every
system, see :mod:`nmsm.opensim_bridge.client`), after a start-up token
(:data:`~nmsm.opensim_bridge.client.SYNC_TOKEN`) that tells the client where its replies begin.
Never imports CasADi. OpenSim's log file is pinned to the worker's private folder
(``NMSM_BRIDGE_WORKDIR``) before any model is loaded, because OpenSim opens
``opensim.log`` lazily in whatever folder is current, and loading a model can change it.
"""

from __future__ import annotations

import os
import sys
import traceback
from typing import BinaryIO


def _pin_opensim_log(workdir: str) -> None:
    import opensim as osim

    try:
        osim.Logger.removeFileSink()
    except Exception:  # older builds
        pass
    osim.Logger.addFileSink(os.path.join(workdir, "opensim.log"))


#: whether this is Windows (a constant, so tests can pretend)
_WINDOWS = os.name == "nt"


def _binary(fd: int) -> int:
    """``fd``, in binary mode on Windows (no newline translation; Python starts its standard
    streams binary, this makes sure for the duplicates)."""
    if _WINDOWS:
        import msvcrt

        msvcrt.setmode(fd, os.O_BINARY)
    return fd


def protocol_streams() -> tuple[BinaryIO, BinaryIO]:
    """The request and reply streams: this process's standard input and output, moved to
    private descriptors. Descriptor 1 then writes to the log (descriptor 2) and descriptor 0
    reads nothing, so neither OpenSim's console output nor a ``print`` can reach the replies."""
    requests = os.fdopen(_binary(os.dup(0)), "rb")
    replies = os.fdopen(_binary(os.dup(1)), "wb")
    sys.stdout.flush()
    os.dup2(2, 1)
    devnull = os.open(os.devnull, os.O_RDONLY)
    try:
        os.dup2(devnull, 0)
    finally:
        os.close(devnull)
    return requests, replies


def main(argv: list[str]) -> int:
    requests, replies = protocol_streams()  # first: nothing may write to the reply pipe but replies
    from nmsm.opensim_bridge.client import SYNC_TOKEN, receive_message, send_message

    replies.write(SYNC_TOKEN)  # the client skips whatever start-up code printed before this
    replies.flush()
    from nmsm.opensim_bridge.commands import COMMANDS, load_all

    workdir = os.environ.get("NMSM_BRIDGE_WORKDIR") or os.getcwd()
    os.chdir(workdir)
    try:
        _pin_opensim_log(workdir)
        load_all()
        import_error = None
    except Exception as exc:  # report at first request
        import_error = f"{type(exc).__name__}: {exc}"
    while True:
        try:
            command, kwargs = receive_message(requests)
        except EOFError:
            return 0
        if command == "shutdown":
            return 0
        if command == "ping":
            send_message(replies, (import_error is None, import_error or "pong"))
            continue
        try:
            if import_error:
                raise RuntimeError(import_error)
            handler = COMMANDS.get(command)
            if handler is None:
                raise KeyError(f"unknown bridge command '{command}' (known: {', '.join(sorted(COMMANDS))})")
            result = handler(**kwargs)
            reply = (True, result)
        except Exception as exc:
            detail = f"{type(exc).__name__}: {exc}"
            print(traceback.format_exc(), file=sys.stderr, flush=True)
            reply = (False, detail)
        finally:
            os.chdir(workdir)  # OpenSim may have moved us to a model's folder
        send_message(replies, reply)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
