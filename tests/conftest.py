"""Shared fixtures.

``shared_data``  path of ``../shared/data`` (or ``$NMSM_SHARED_DATA``). Tests that use it
                 skip when it is absent, and fail instead when ``NMSM_REQUIRE_SHARED_DATA=1``
                 (set by ``.ci/run``).
``bridge``       the OpenSim worker; skips when ``opensim`` is not installed, fails instead
                 when ``NMSM_REQUIRE_OPENSIM=1``.
``chromium``     the path of a headless Chromium (``chromium``, ``chromium-browser`` or
                 ``google-chrome``); skips when there is none, fails instead when
                 ``NMSM_REQUIRE_BROWSER=1`` (set by ``.ci/run``).
``default_sigint`` Python's own SIGINT handler for the test (restored after): a pytest started
                 in the background of a non-interactive shell (``nohup pytest ... &``) inherits
                 SIGINT ignored, and tests of Ctrl-C need the handler an interactive run has.

Never import opensim here or in any test module: OpenSim runs only in the bridge's worker.
"""

from __future__ import annotations

import os
import signal
import threading
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _shared_data_dir() -> Path:
    env = os.environ.get("NMSM_SHARED_DATA")
    return Path(env) if env else REPO.parent / "shared" / "data"


def _require(flag: str) -> bool:
    return os.environ.get(flag, "") not in ("", "0", "false", "no")


@pytest.fixture
def default_sigint():
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signal handlers can only be set in the main thread")
    previous = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        # None: a handler not installed from Python, which cannot be put back; leave Python's
        signal.signal(signal.SIGINT, previous if previous is not None else signal.default_int_handler)


@pytest.fixture(scope="session")
def shared_data() -> Path:
    path = _shared_data_dir()
    if not (path / "README.md").is_file():
        message = f"shared data not found at {path} (set NMSM_SHARED_DATA)"
        if _require("NMSM_REQUIRE_SHARED_DATA"):
            pytest.fail(message + "; NMSM_REQUIRE_SHARED_DATA is set, so this is an error")
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def chromium() -> str:
    import shutil

    found = next((path for path in map(shutil.which, ("chromium", "chromium-browser", "google-chrome")) if path), None)
    if found is None:
        message = "no headless Chromium on PATH (Debian: apt-get install chromium)"
        if _require("NMSM_REQUIRE_BROWSER"):
            pytest.fail(message + "; NMSM_REQUIRE_BROWSER is set, so this is an error")
        pytest.skip(message)
    return found


@pytest.fixture(scope="session")
def bridge():
    from nmsm.opensim_bridge import get_bridge, opensim_available

    if not opensim_available():
        message = "the 'opensim' package is not installed for the bridge (pip install opensim)"
        if _require("NMSM_REQUIRE_OPENSIM"):
            pytest.fail(message + "; NMSM_REQUIRE_OPENSIM is set, so this is an error")
        pytest.skip(message)
    return get_bridge()
