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


def test_pytest_xdist_keeps_the_files_in_collection_order(request):
    """--no-loadscope-reorder (pyproject.toml): without it pytest-xdist 3.8 hands the files out
    by their number of tests, not longest first as pytest_collection_modifyitems orders them."""
    assert request.config.getoption("loadscopereorder") is False


def _c_files(folder, header_value: int):
    folder.mkdir()
    (folder / "value.h").write_text(f"#define VALUE {header_value}\n")
    (folder / "main.c").write_text('#include "value.h"\nint main(void)\n{\n    return VALUE;\n}\n')
    return folder / "main.c"


def test_a_build_is_compiled_once_and_copied_for_the_same_files_elsewhere(tmp_path, monkeypatch):
    """tests/cbuild.py's cache: the same source and header in another folder is a hit (the
    compiler is not run); a changed header, or other flags, is another build."""
    import subprocess

    import cbuild

    if not cbuild.compilers():
        return
    monkeypatch.setenv(cbuild.CACHE_ENV, str(tmp_path / "cache"))
    runs = []
    real = cbuild._run
    monkeypatch.setattr(cbuild, "_run", lambda cmd: runs.append(cmd) or real(cmd))

    def exit_status(exe):
        return subprocess.run([str(exe)]).returncode

    first = cbuild.compile_program([_c_files(tmp_path / "a", 3)], tmp_path / "a" / "prog")
    same = cbuild.compile_program([_c_files(tmp_path / "b", 3)], tmp_path / "b" / "prog")
    assert len(runs) == 1 and exit_status(first) == exit_status(same) == 3
    changed = cbuild.compile_program([_c_files(tmp_path / "c", 5)], tmp_path / "c" / "prog")
    assert len(runs) == 2 and exit_status(changed) == 5
    other = cbuild.compile_program([tmp_path / "a" / "main.c"], tmp_path / "a" / "prog1", opt="-O1")
    assert len(runs) == 3 and exit_status(other) == 3
    cbuild.compile_program([tmp_path / "a" / "main.c"], tmp_path / "a" / "main.s", extra=("-S",))
    cbuild.compile_program([tmp_path / "a" / "main.c"], tmp_path / "a" / "main.s", extra=("-S",))
    assert len(runs) == 5  # a build with another output than its program is never cached


def test_a_failed_build_is_not_cached(tmp_path, monkeypatch):
    import cbuild

    if not cbuild.compilers():
        return
    monkeypatch.setenv(cbuild.CACHE_ENV, str(tmp_path / "cache"))
    source = tmp_path / "warns.c"
    source.write_text("int main(void)\n{\n    int unused;\n    return 0;\n}\n")
    for _ in range(2):
        try:
            cbuild.compile_program([source], tmp_path / "warns")
        except cbuild.CompileError as error:
            assert "unused" in str(error)
        else:
            raise AssertionError("a warning under -Werror must fail the build each time")
    assert not (tmp_path / "cache").exists() or not list((tmp_path / "cache").iterdir())
