"""Subprocesses that tests only wait for, started when the session starts and run next to the test process.

On two cores the test process keeps one busy most of the time (numba compiles on one thread), so a long
subprocess whose output a test merely checks (a fresh install, runs under other CPU dispatch settings, a
rebuild) runs on the other core while the tests before it run, instead of after them. tests/conftest.py
starts, through :func:`submit`, those that a selected test uses; the test takes the future's result. One
worker thread runs them in the order submitted, so at most one such subprocess runs at a time.
"""

from __future__ import annotations

import subprocess
from concurrent.futures import Future, ThreadPoolExecutor

import pytest

_WORKER = ThreadPoolExecutor(max_workers=1, thread_name_prefix="tests-background")
_RUNNING: set = set()


def submit(function, *args, **kwargs) -> Future:
    """Run ``function(*args, **kwargs)`` on the worker thread; its result or exception comes from the future."""
    return _WORKER.submit(function, *args, **kwargs)


def run(command, timeout=None, **kwargs) -> subprocess.CompletedProcess:
    """``subprocess.run(command, capture_output=True, text=True, ...)`` that :func:`stop` can kill."""
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs) as process:
        _RUNNING.add(process)
        try:
            stdout, stderr = process.communicate(timeout=timeout)
        finally:
            _RUNNING.discard(process)
            if process.poll() is None:
                process.kill()
    return subprocess.CompletedProcess(command, process.returncode, stdout, stderr)


def succeeded(process: subprocess.CompletedProcess) -> subprocess.CompletedProcess:
    """``process`` if it exited with 0; otherwise the calling test fails with the command and its output's end."""
    if process.returncode != 0:
        pytest.fail(f"{' '.join(map(str, process.args))} failed ({process.returncode}):\n{process.stdout[-4000:]}\n"
                    f"{process.stderr[-4000:]}")
    return process


def stop() -> None:
    """At the session's end: drop what has not started and kill what runs (a test that needed it has failed)."""
    _WORKER.shutdown(wait=False, cancel_futures=True)
    for process in list(_RUNNING):
        process.kill()
