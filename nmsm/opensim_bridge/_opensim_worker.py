"""The OpenSim worker process (``python -m nmsm.opensim_bridge._opensim_worker R W``).

Reads pickled ``(command, kwargs)`` requests from fd R and writes ``(ok, payload)`` to
fd W. Never imports CasADi. OpenSim's log file is pinned to the worker's private folder
(``NMSM_BRIDGE_WORKDIR``) before any model is loaded, because OpenSim opens
``opensim.log`` lazily in whatever folder is current, and loading a model can change it.
"""

from __future__ import annotations

import os
import sys
import traceback


def _pin_opensim_log(workdir: str) -> None:
    import opensim as osim

    try:
        osim.Logger.removeFileSink()
    except Exception:  # older builds
        pass
    osim.Logger.addFileSink(os.path.join(workdir, "opensim.log"))


def main(argv: list[str]) -> int:
    from nmsm.opensim_bridge.client import receive_message, send_message
    from nmsm.opensim_bridge.commands import COMMANDS, load_all

    requests = os.fdopen(int(argv[1]), "rb")
    replies = os.fdopen(int(argv[2]), "wb")
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
