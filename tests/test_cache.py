"""The cache's leftovers and errors (symdyn.apps.compilation.cache, symdyn.leftovers).

A build killed before its rename leaves a `.build-PID-XXXXXXXX` folder; the next build
removes it once stale (its process gone, or older than an hour) and `symdyn cache` counts it.
A cache that cannot be written gives SymdynError, not PermissionError. Builds here write a
small file instead of compiling, so that many can run at once in a second.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from robots import dead_pid

from symdyn import cli
from symdyn.apps.compilation import cache
from symdyn.errors import SymdynError
from symdyn.leftovers import STALE_SECONDS

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def temporary_cache(tmp_path, monkeypatch):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


def _write(folder: Path) -> dict:
    (folder / "data.txt").write_text("payload", encoding="utf-8")
    return {"kind": "test"}


def test_stale_staging_folders_are_removed_and_counted(temporary_cache, capsys):
    layout = temporary_cache / "v1"
    dead = layout / f".build-{dead_pid()}-abcdefgh"  # killed: its process is gone
    live = layout / f".build-{os.getpid()}-ijklmnop"  # a build under way in a live process
    old = layout / ".build-qrstuvwx"  # an earlier version's, without a pid: stale by age
    young = layout / ".build-yz012345"  # the same, recent: kept
    for folder in (dead, live, old, young):
        folder.mkdir(parents=True)
        (folder / "lib.so").write_bytes(b"x" * 1000)
    past = time.time() - STALE_SECONDS - 60
    os.utime(old, (past, past))
    assert cache.leftovers() == (4, 4000)
    assert cli.main(["cache"]) == 0
    out = capsys.readouterr().out
    assert "0 entries" in out and "4 unfinished build folders (.build-*), 4.0 kB" in out
    cache.get_or_build(cache.entry_key(test="sweep"), _write)
    assert not dead.exists() and not old.exists()
    assert live.is_dir() and young.is_dir()
    root, count, size = cache.usage()
    assert (count, size) == (
        1,
        len("payload")
        + (root / "v1").joinpath(cache.entry_key(test="sweep"), "manifest.json").stat().st_size,
    )
    assert cache.leftovers() == (2, 2000)
    assert cache.clear() == 1 and cache.leftovers() == (0, 0)


def test_eight_concurrent_builds_survive(temporary_cache):
    """Eight processes build the same entry and four others their own at once, each sweeping."""
    code = (
        "import sys, time\n"
        "from pathlib import Path\n"
        "from symdyn.apps.compilation import cache\n"
        "def build(folder):\n"
        "    time.sleep(0.3)\n"
        "    (folder / 'data.txt').write_text(sys.argv[1])\n"
        "    return {'who': sys.argv[1]}\n"
        "e = cache.get_or_build(cache.entry_key(test=sys.argv[1]), build)\n"
        "print(e.file('data.txt').read_text())\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    names = ["same"] * 8 + ["a", "b", "c", "d"]
    procs = [
        subprocess.Popen([sys.executable, "-c", code, name], stdout=subprocess.PIPE, text=True, env=env)
        for name in names
    ]
    outs = [p.communicate(timeout=120)[0].strip() for p in procs]
    assert outs == names and all(p.returncode == 0 for p in procs)
    assert cache.usage()[1] == 5 and cache.leftovers() == (0, 0)
    for name in set(names):
        assert cache.lookup(cache.entry_key(test=name)).file("data.txt").read_text() == name


def test_a_cache_that_cannot_be_written_is_a_symdyn_error(tmp_path, monkeypatch):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(cache.CACHE_ENV, str(blocker / "cache"))
    with pytest.raises(
        SymdynError, match=r"the symdyn cache at .*a-file/cache cannot be written .*SYMDYN_CACHE_DIR"
    ):
        cache.get_or_build(cache.entry_key(test="blocked"), _write)


def test_a_read_only_cache_is_a_symdyn_error(tmp_path, monkeypatch):
    """A folder without write permission (as root, which writes anyway, the refusal is staged)."""
    import tempfile

    root = tmp_path / "ro"
    (root / "v1").mkdir(parents=True)
    monkeypatch.setenv(cache.CACHE_ENV, str(root))
    os.chmod(root / "v1", 0o500)
    if os.name != "posix" or os.geteuid() == 0:

        def refuse(*args, dir=None, **kwargs):
            raise PermissionError(13, "Permission denied", str(dir))

        monkeypatch.setattr(tempfile, "mkdtemp", refuse)
    try:
        with pytest.raises(SymdynError, match=r"cannot be written \(Permission denied: .*ro/v1"):
            cache.get_or_build(cache.entry_key(test="ro"), _write)
    finally:
        os.chmod(root / "v1", 0o700)


# Issue 34, item 9: a build killed by SIGKILL left $TMPDIR/symdyn-build-* that no later run removed.
# Issue 34, item 8: a relative SYMDYN_CACHE_DIR broke every compile (the compiler runs in another
# folder, where the library's relative path pointed elsewhere).

DOUBLE = {"double.c": "double twice(double x) { return 2.0 * x; }\n"}


def _compiler():
    from symdyn.apps.compilation.build import find_compiler

    compiler = find_compiler()
    if compiler is None:
        pytest.skip("no C compiler")
    return compiler


def _twice(library: Path) -> float:
    import ctypes

    lib = ctypes.CDLL(str(library))
    lib.twice.restype, lib.twice.argtypes = ctypes.c_double, [ctypes.c_double]
    return lib.twice(1.25)


def test_a_killed_compilers_folder_is_removed_by_the_next_build(tmp_path, monkeypatch):
    import signal
    import tempfile

    from symdyn.apps.compilation.build import BUILD_PREFIX, compile_library

    compiler = _compiler()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    code = (
        "import os, sys, tempfile\n"
        "from symdyn.apps.compilation import build\n"
        "def stop(*args, **kwargs):\n"  # the compiler started: die as by kill -9, mid-build
        "    os.kill(os.getpid(), 9)\n"
        "build._compile_objects = stop\n"
        "build.compile_library(sys.argv[1:], {'a.c': 'int x;'}, 'lib.so')\n"
    )
    env = {**os.environ, "TMPDIR": str(tmp_path / "tmp"), "PYTHONPATH": str(ROOT)}
    killed = subprocess.run([sys.executable, "-c", code, *compiler], env=env, timeout=60)
    assert killed.returncode == -signal.SIGKILL
    left = list((tmp_path / "tmp").iterdir())
    assert len(left) == 1 and left[0].name.startswith(BUILD_PREFIX) and (left[0] / "a.c").is_file()
    live = tmp_path / "tmp" / f"{BUILD_PREFIX}{os.getpid()}-livebild"  # a build under way: kept
    old = tmp_path / "tmp" / f"{BUILD_PREFIX}oldstyle"  # an earlier version's, an hour old: removed
    young = tmp_path / "tmp" / f"{BUILD_PREFIX}youngone"  # the same, recent: kept
    for folder in (live, old, young):
        folder.mkdir()
    past = time.time() - STALE_SECONDS - 60
    os.utime(old, (past, past))
    library = compile_library(compiler, DOUBLE, tmp_path / "double.so")
    assert _twice(library) == 2.5
    assert sorted((tmp_path / "tmp").iterdir()) == sorted([live, young])


def test_a_relative_cache_folder_is_taken_from_the_current_folder(tmp_path, monkeypatch):
    from symdyn.apps.compilation.build import compile_library

    compiler = _compiler()
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(cache.CACHE_ENV, "relative/cache")
    assert cache.cache_dir() == tmp_path / "relative" / "cache"

    def build(folder: Path) -> dict:
        compile_library(compiler, DOUBLE, folder / "double.so")
        return {}

    entry = cache.get_or_build(cache.entry_key(test="relative"), build)
    assert entry.path.is_absolute() and entry.path.parent == tmp_path / "relative" / "cache" / "v1"
    assert _twice(entry.file("double.so")) == 2.5


def test_a_manifest_of_deeply_nested_brackets_is_a_stale_entry(temporary_cache):
    """json's reader raised RecursionError on 100,000 nested brackets; the entry is removed and rebuilt."""
    key = cache.entry_key(test="nested")
    folder = cache.cache_dir() / "v1" / key
    folder.mkdir(parents=True)
    (folder / "manifest.json").write_text("[" * 100_000 + "]" * 100_000)
    assert cache.lookup(key) is None and not folder.exists()
