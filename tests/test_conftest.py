"""tests/conftest.py: a pytest-xdist worker ends quietly (its heap collected and frozen before it
reports its end, so that pytest's last garbage collection is quick)."""

from __future__ import annotations

import gc
import os

import conftest


def test_the_last_collection_of_a_worker_runs_before_it_reports_its_end(request):
    """The hook runs inside pytest-xdist's hook wrapper (which sends `workerfinished` after it) and
    after the session's fixtures are torn down (trylast, after pytest's runner)."""
    caller = request.config.pluginmanager.hook.pytest_sessionfinish
    ours = next(impl for impl in caller.get_hookimpls() if impl.function is conftest.pytest_sessionfinish)
    assert not ours.hookwrapper and not ours.wrapper and ours.trylast


def test_after_it_a_collection_has_almost_nothing_to_look_at(monkeypatch, request):
    """After the hook, the objects gc.collect() walks are only those made since (not the heap of
    the derivations, which took 1-12 s to walk and outlived execnet's 5 s)."""
    monkeypatch.setenv("PYTEST_XDIST_WORKER", os.environ.get("PYTEST_XDIST_WORKER", "gw0"))
    heap = [[k] for k in range(300_000)]  # a heap of tracked objects, as a worker has
    assert len(gc.get_objects()) > len(heap)
    try:
        conftest.pytest_sessionfinish(request.session)
        assert gc.get_freeze_count() > len(heap)
        assert len(gc.get_objects()) < 10_000
    finally:
        gc.unfreeze()  # the other tests of this worker run as before
    del heap


def test_a_file_is_frozen_when_it_ends(request):
    """The end-of-file collection runs after pytest's runner has torn the file's fixtures down."""
    caller = request.config.pluginmanager.hook.pytest_runtest_teardown
    ours = next(impl for impl in caller.get_hookimpls() if impl.function is conftest.pytest_runtest_teardown)
    assert not ours.hookwrapper and not ours.wrapper and ours.trylast


def test_files_run_longest_first_and_unknown_ones_as_an_average_file(monkeypatch):
    import durations

    monkeypatch.setattr(durations, "table", lambda: {"a.py": 1.0, "b.py": 90.0, "c.py": 30.0})
    rank = durations.order(["a.py", "new.py", "c.py", "b.py", "a.py"])
    assert sorted(rank, key=rank.get) == ["b.py", "c.py", "new.py", "a.py"]
    assert durations.UNKNOWN_SECONDS == 5.0  # between c.py and a.py above
