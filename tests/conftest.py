"""Shared pytest set-up.

- The helper modules of tests/ (`robots`, `cbuild`) are importable from every test file.
- symdyn.compile builds its libraries without -march (SYMDYN_MARCH=none, symdyn.apps.compilation.build), the
  compiler's default target: the SIMD bodies of the batch wrappers are then left out by the
  preprocessor, so the many libraries the suite compiles cost what they cost before them (the
  vector bodies double a library's compile time). tests/test_batch.py compiles and checks the
  vector path, and symdyn.compile's default -march=native, itself. A SYMDYN_MARCH set by the
  caller is kept.
- symdyn.compile builds its libraries at -O0 (SYMDYN_OPT=0), as tests/cbuild.py builds the tests'
  own C: the values do not depend on the level (no -ffast-math, no contraction), and gcc -O2 took
  six times as long on the PUMA 560's C (1.9 s against 0.3 s of one core). tests/test_batch.py
  builds with symdyn.compile's default -O2 -march=native; a SYMDYN_OPT set by the caller is kept.
- Progress reports are off (SYMDYN_QUIET=1, symdyn.progress), in this process and the commands it
  starts.
- Under CI (the environment variable CI set to true, as .ci/run is run), a skipped test is a
  failure: CI installs every tool the tests use (a C compiler, pdflatex, the test extra), so a
  skip there would only hide a missing install step. Locally, tests of absent tools still skip.
  The one exception is hardware no install step provides: a test marked `accelerator` (it needs a
  GPU) skips without one, in CI too.
- The garbage collector runs less often (`warm_python.GC_THRESHOLDS`: it found little, at a sixth
  of the time).
- Each test file's garbage is collected and the rest frozen when the file ends
  (`pytest_runtest_teardown` below), so that full collections stop walking the heap of the files
  before; a pytest-xdist worker does the same before it reports its end (`pytest_sessionfinish`),
  so that it stops at once when asked to.
- The files run longest first, by the seconds tests/durations.py records in tests/durations.json.
- The tests' builds of generated C (tests/cbuild.py) are cached by content in a folder the
  workers share (`_temporary_symdyn_cache`): the same C with the same flags is compiled once.
- With SYMDYN_TEST_TIMES set to a folder, each process writes the cost of each test file there
  (tests/durations.py, which sets it).
"""

from __future__ import annotations

import gc
import os
import sys
from pathlib import Path

import pytest

HERE = str(Path(__file__).resolve().parent)
if HERE not in sys.path:
    sys.path.insert(0, HERE)

from cbuild import CACHE_ENV as CBUILD_CACHE  # noqa: E402  (tests/ is on the path only from here)
from durations import Recorder, order  # noqa: E402
from warm_python import GC_THRESHOLDS  # noqa: E402

IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")
# no progress reports (symdyn.progress): a command that runs for a second would add lines to the
# standard error the tests compare; tests/test_progress.py turns them on where it tests them, and
# the commands of the pages run (tests/test_docs.py) inherit the variable
os.environ["SYMDYN_QUIET"] = "1"
# the garbage collector's thresholds in the test processes (warm_python.GC_THRESHOLDS, also those
# of the documentation's commands; Python's are 700, 10, 10): SymPy makes millions of small
# objects, nearly none of them in cycles, and with the defaults a test file spent a sixth of its
# time in collections that found little. Measured with tests/durations.py -n 0 over
# test_c_target.py, test_newton_euler.py and test_lagrange.py (same load, one run each at once):
# 76.8 CPU-s with the defaults, 67.2 with these (time in collections 56 s to 19 s of wall time on
# the loaded machine), peak memory 187 MB and 177 MB.
gc.set_threshold(*GC_THRESHOLDS)


def pytest_collection_modifyitems(session, config, items):
    """The longest test files first, by the CPU seconds recorded in tests/durations.json
    (tests/durations.py writes it): pytest-xdist hands whole files to the workers in collection
    order (--dist loadfile with --no-loadscope-reorder, pyproject.toml: pytest-xdist 3.8 otherwise
    reorders the files by their number of tests), so a long file collected last would leave one
    worker running it alone while the other idles. A stable sort: the tests of one file keep
    their order."""
    rank = order([item.path.name for item in items])
    items.sort(key=lambda item: rank[item.path.name])


def pytest_configure(config):
    if os.environ.get("SYMDYN_TEST_TIMES"):  # tests/durations.py: the cost of each test file
        config.pluginmanager.register(Recorder(os.environ["SYMDYN_TEST_TIMES"]), "symdyn-durations")
    config.addinivalue_line("markers", "accelerator: needs a GPU; skips without one, under CI as well")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    hardware = item.get_closest_marker("accelerator") is not None
    if IN_CI and report.skipped and not hardware and not hasattr(report, "wasxfail"):
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
        report.outcome = "failed"
        report.longrepr = f"skipped under CI, where every tool the tests use is installed: {reason}"


@pytest.hookimpl(trylast=True)
def pytest_runtest_teardown(item, nextitem):
    """At the end of each test file (its module fixtures torn down: trylast, after pytest's
    runner), collect the garbage and freeze what is left (gc.freeze).

    What outlives a file is mostly the derivations the session caches (tests/robots.py) and
    SymPy's caches: hundreds of MB of objects that every full collection of the following files
    would walk again. Frozen, they are still freed by reference counting; a full collection walks
    only what was made since. Measured (tests/durations.py, test_configuration_space.py,
    test_tree.py and test_frame_functions.py in one process): 4 % less CPU, a fifth less time in
    full collections, the same peak memory.
    """
    if nextitem is None or nextitem.path != item.path:
        gc.collect()
        gc.freeze()


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session):
    """A worker's last full garbage collection, before it reports its end to the controller.

    Its heap (every example robot derived, SymPy's caches: about 1 GB) takes a full collection of
    1 to 12 s on a busy machine. pytest collects once more when it unconfigures, after the worker
    has reported its end (pytest-xdist sends `workerfinished` once the non-wrapper hooks here have
    run, session fixtures torn down), and execnet interrupts a worker still busy 5 s after the
    controller asked it to stop: a SIGINT, whose KeyboardInterrupt struck inside hypothesis' gc
    callback and ended a green suite with a PytestUnraisableExceptionWarning. So the worker
    collects here, while the controller still waits for it, and freezes what is left
    (gc.freeze): pytest's last collection then only looks at the objects made since.
    """
    if os.environ.get("PYTEST_XDIST_WORKER"):
        gc.collect()
        gc.freeze()


@pytest.fixture(autouse=True, scope="session")
def _temporary_symdyn_cache(tmp_path_factory):
    """Every test compiles into a temporary cache folder, never the user's (symdyn.apps.compilation.cache),
    and the tests' own builds of generated C (tests/cbuild.py) are cached in another.

    Under pytest-xdist the workers share each folder (in the run's common temporary root), so a
    library one worker compiled is a cache hit for the others: both caches' writes are atomic and
    safe under concurrent builds (tests of symdyn's cache itself use folders of their own).
    """
    old = {name: os.environ.get(name) for name in ("SYMDYN_CACHE_DIR", CBUILD_CACHE)}
    os.environ.setdefault("SYMDYN_MARCH", "none")
    os.environ.setdefault("SYMDYN_OPT", "0")
    for name, stem in (("SYMDYN_CACHE_DIR", "symdyn-cache"), (CBUILD_CACHE, "cbuild-cache")):
        if os.environ.get("PYTEST_XDIST_WORKER"):
            folder = tmp_path_factory.getbasetemp().parent / stem
            folder.mkdir(exist_ok=True)
        else:
            folder = tmp_path_factory.mktemp(stem)
        os.environ[name] = str(folder)
    yield
    for name, value in old.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value
