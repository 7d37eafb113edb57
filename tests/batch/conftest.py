"""Fixtures of the batch tests: a synthetic JMP case (a few seconds a run), a time limit."""

from __future__ import annotations

import signal
import threading

import pytest

from nmsm.examples.synthetic_jmp import make_synthetic_jmp_case


@pytest.fixture(scope="module")
def jmp_case(tmp_path_factory):
    """A synthetic JMP case (``settings_file``, markers, models) and a copy of its settings with
    a value JMP cannot read (``broken.xml``)."""
    case = make_synthetic_jmp_case(tmp_path_factory.mktemp("jmp_case"), duration=1.0)
    text = case.settings_file.read_text(encoding="utf-8")
    broken = text.replace("<max_function_evaluations>500", "<max_function_evaluations>lots")
    assert broken != text
    (case.folder / "broken.xml").write_text(broken, encoding="utf-8")
    return case


@pytest.fixture(scope="module")
def long_jmp_case(tmp_path_factory):
    """A synthetic JMP case whose solve takes a few seconds: long enough for a test to kill
    its worker before the run ends, however late the "started" event arrives."""
    return make_synthetic_jmp_case(tmp_path_factory.mktemp("long_jmp_case"), duration=6.0)


class BatchTimeout(Exception):
    pass


@pytest.fixture
def time_limit():
    """``time_limit(seconds)``: raise :class:`BatchTimeout` in the test after ``seconds`` (the
    batch then stops and shuts its cluster down)."""
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("needs the main thread for SIGALRM")

    def expire(signum, frame):
        raise BatchTimeout("the batch test ran out of time")

    previous = signal.signal(signal.SIGALRM, expire)
    yield lambda seconds: signal.alarm(int(seconds))
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)
