"""Test configuration: headless matplotlib, numpy errors surface as failures, and a quiet end
of an xdist worker."""

import signal

import matplotlib
import pytest

matplotlib.use("Agg")


@pytest.hookimpl(tryfirst=True)
def pytest_sessionfinish(session):
    """An xdist worker whose tests are done ignores SIGINT. execnet sends its worker a SIGINT when
    the worker's teardown (pytest's final garbage collections of a large heap, on a loaded
    machine) outlasts 5 s; it lands in whatever Python code runs then, mostly hypothesis's
    ``gc_callback``, and is printed as a KeyboardInterrupt traceback after a green run. Ignored,
    the teardown ends (execnet still ends a worker that has not ended within 10 s more)."""
    if hasattr(session.config, "workerinput"):
        signal.signal(signal.SIGINT, signal.SIG_IGN)
