"""Load an HTML page in headless Chromium through the DevTools protocol (over a pipe).

:func:`load_page` starts ``chromium --headless --remote-debugging-pipe`` (DevTools messages
as NUL-terminated JSON on file descriptors 3 and 4, no websocket library needed), opens
the page at a given window size, waits for its load event, and returns the JavaScript
exceptions, console errors and failed loads seen, the value of a JavaScript expression
evaluated on the page, and a PNG screenshot of the first screen.
"""

from __future__ import annotations

import base64
import json
import os
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

import attrs

@attrs.frozen
class PageLoad:
    errors: list[str]
    value: Any
    screenshot: bytes


class _DevTools:
    def __init__(self, browser: str, profile: str) -> None:
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()

        def fds() -> None:  # in the child: the pipe ends on the descriptors Chromium expects
            reading, writing = os.dup(to_browser_r), os.dup(from_browser_w)
            os.dup2(reading, 3)
            os.dup2(writing, 4)

        self.process = subprocess.Popen(
            [browser, "--headless", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe", "--no-first-run",
             f"--user-data-dir={profile}", "about:blank"],
            preexec_fn=fds, pass_fds=(3, 4), stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._next_id = 0
        self._buffer = b""
        self.events: list[dict[str, Any]] = []

    def send(self, method: str, session: str | None = None, timeout: float = 30.0, **params: Any) -> dict[str, Any]:
        self._next_id += 1
        message: dict[str, Any] = {"id": self._next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            reply = self._receive(deadline)
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise RuntimeError(f"DevTools {method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method: str, timeout: float = 30.0) -> dict[str, Any]:
        deadline = time.monotonic() + timeout
        for event in self.events:
            if event.get("method") == method:
                return event
        while True:
            event = self._receive(deadline)
            self.events.append(event)
            if event.get("method") == method:
                return event

    def _receive(self, deadline: float) -> dict[str, Any]:
        import select

        while b"\0" not in self._buffer:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError("no answer from the browser")
            ready, _, _ = select.select([self._from_browser], [], [], remaining)
            if ready:
                chunk = os.read(self._from_browser, 1 << 20)
                if not chunk:
                    raise EOFError("the browser closed its DevTools pipe")
                self._buffer += chunk
        message, _, self._buffer = self._buffer.partition(b"\0")
        return json.loads(message)

    def close(self) -> None:
        try:
            self.send("Browser.close", timeout=5)
        except (OSError, EOFError, TimeoutError, RuntimeError):
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        os.close(self._to_browser)
        os.close(self._from_browser)


def load_page(browser: str, page: Path, expression: str, width: int = 1280, height: int = 900) -> PageLoad:
    """Open ``page`` at ``width`` x ``height`` CSS pixels; see the module docstring."""
    with tempfile.TemporaryDirectory(prefix="nmsm-chromium-") as profile:
        tools = _DevTools(browser, profile)
        try:
            target = tools.send("Target.createTarget", url="about:blank")["targetId"]
            session = tools.send("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
            for domain in ("Page", "Runtime", "Log", "Network"):
                tools.send(f"{domain}.enable", session)
            tools.send("Emulation.setDeviceMetricsOverride", session, width=width, height=height,
                       deviceScaleFactor=1, mobile=False)
            tools.send("Page.navigate", session, url=page.resolve().as_uri())
            tools.wait_for("Page.loadEventFired", timeout=60)
            value = tools.send("Runtime.evaluate", session, expression=expression, returnByValue=True)
            shot = tools.send("Page.captureScreenshot", session, format="png")
            errors = []
            for event in tools.events:
                params = event.get("params", {})
                if event.get("method") == "Runtime.exceptionThrown":
                    details = params["exceptionDetails"]
                    text = details.get("exception", {}).get("description") or details.get("text")
                    errors.append(f"exception: {text}")
                elif event.get("method") == "Log.entryAdded" and params["entry"]["level"] == "error":
                    errors.append(f"log: {params['entry'].get('text')}")
                elif event.get("method") == "Runtime.consoleAPICalled" and params.get("type") == "error":
                    errors.append(f"console: {params.get('args')}")
                elif event.get("method") == "Network.loadingFailed":
                    errors.append(f"load failed: {params.get('errorText')}")
            if "exceptionDetails" in value:
                errors.append(f"evaluate: {value['exceptionDetails'].get('text')}")
            return PageLoad(errors, value.get("result", {}).get("value"), base64.b64decode(shot["data"]))
        finally:
            tools.close()
