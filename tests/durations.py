"""What each test file of the suite costs, and the order the suite runs its files in.

Run as a script, from the repository root, it runs the suite as the README does (pytest-xdist,
`--dist loadfile`) with the recorder below switched on, and writes `tests/durations.json`: the CPU
seconds of each test file (its process's user and system time plus that of the commands it ran:
compilers, the documentation's commands), set-up and tear-down of its fixtures included::

    python tests/durations.py --write    # the whole suite; rewrites tests/durations.json
    python tests/durations.py tests/test_tree.py -n 0   # any pytest arguments; prints, writes nothing

`tests/conftest.py` sorts the collected files by these seconds, longest first: pytest-xdist hands
whole files to its workers in collection order, so a long file collected last would leave one
worker running it alone while the other idles. A file the table does not know yet (a new one)
runs after the files that took longer than `UNKNOWN_SECONDS`, as an average file would.

The recorder (`Recorder`, on when the environment variable SYMDYN_TEST_TIMES names a folder)
writes one JSON file per process into that folder: per test file its CPU seconds, wall seconds,
seconds spent in garbage collection and number of tests, and the process's peak resident memory.
"""

from __future__ import annotations

import gc
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
TABLE = HERE / "durations.json"
#: the CPU seconds assumed for a test file missing from the table
UNKNOWN_SECONDS = 5.0


def _cpu() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


class Recorder:
    """A pytest plugin: the cost of each test file in this process (see the module's docstring)."""

    def __init__(self, folder: str) -> None:
        self.folder = Path(folder)
        self.files: dict[str, dict[str, float]] = {}
        self._gc_start = 0.0
        self._gc_seconds = [0.0, 0.0, 0.0]
        gc.callbacks.append(self._gc)

    def _gc(self, phase: str, info: dict) -> None:
        if phase == "start":
            self._gc_start = time.perf_counter()
        else:
            self._gc_seconds[info["generation"]] += time.perf_counter() - self._gc_start

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(self, item, nextitem):
        cpu, wall, collected = _cpu(), time.perf_counter(), sum(self._gc_seconds)
        yield
        entry = self.files.setdefault(item.path.name, {"cpu": 0.0, "wall": 0.0, "gc": 0.0, "tests": 0})
        entry["cpu"] += _cpu() - cpu
        entry["wall"] += time.perf_counter() - wall
        entry["gc"] += sum(self._gc_seconds) - collected
        entry["tests"] += 1

    def pytest_sessionfinish(self, session):
        if not self.files:  # pytest-xdist's controller: its workers ran the tests
            return
        name = os.environ.get("PYTEST_XDIST_WORKER", "main")
        record = {
            "files": self.files,
            "gc_by_generation": self._gc_seconds,
            "cpu": _cpu(),
            "max_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        }
        self.folder.mkdir(parents=True, exist_ok=True)
        (self.folder / f"{name}.json").write_text(json.dumps(record, indent=1))


def table() -> dict[str, float]:
    """tests/durations.json: test file name -> CPU seconds ({} if absent or unreadable)."""
    try:
        data = json.loads(TABLE.read_text())
    except (OSError, ValueError):
        return {}
    return {str(k): float(v) for k, v in data.items()} if isinstance(data, dict) else {}


def order(names: list[str]) -> dict[str, int]:
    """Rank of each test file name: the longest (by the table) first, unknown files as an average
    one (`UNKNOWN_SECONDS`), ties by name."""
    seconds = table()
    ranked = sorted(set(names), key=lambda n: (-seconds.get(n, UNKNOWN_SECONDS), n))
    return {name: k for k, name in enumerate(ranked)}


def gather(folder: Path) -> tuple[dict[str, dict[str, float]], list[dict]]:
    """The per-file records of every process of a run, summed by file."""
    files: dict[str, dict[str, float]] = {}
    processes = []
    for path in sorted(folder.glob("*.json")):
        record = json.loads(path.read_text())
        processes.append({"name": path.stem, **{k: v for k, v in record.items() if k != "files"}})
        for name, entry in record["files"].items():
            total = files.setdefault(name, {"cpu": 0.0, "wall": 0.0, "gc": 0.0, "tests": 0})
            for key, value in entry.items():
                total[key] += value
    return files, processes


def report(files: dict[str, dict[str, float]], processes: list[dict], top: int = 40) -> str:
    lines = [f"{'file':40s} {'cpu s':>8s} {'wall s':>8s} {'gc s':>7s} {'tests':>6s}"]
    for name, e in sorted(files.items(), key=lambda kv: -kv[1]["cpu"])[:top]:
        lines.append(f"{name:40s} {e['cpu']:8.1f} {e['wall']:8.1f} {e['gc']:7.1f} {int(e['tests']):6d}")
    cpu = sum(e["cpu"] for e in files.values())
    lines.append(f"{'all ' + str(len(files)) + ' files':40s} {cpu:8.1f}")
    for p in processes:
        gcs = ", ".join(f"{s:.1f}" for s in p["gc_by_generation"])
        rss = p["max_rss_mb"]
        lines.append(
            f"process {p['name']}: cpu {p['cpu']:.1f} s, gc by generation {gcs} s, peak RSS {rss:.0f} MB"
        )
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    write = argv[:1] == ["--write"]
    argv = argv[1:] if write else argv
    with tempfile.TemporaryDirectory() as folder:
        env = {**os.environ, "SYMDYN_TEST_TIMES": folder}
        started = time.perf_counter()
        status = subprocess.call(
            [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *argv], env=env
        )
        wall = time.perf_counter() - started
        files, processes = gather(Path(folder))
    print(report(files, processes))
    print(f"wall {wall:.0f} s, exit status {status}")
    if write:  # a test that failed still took its time (a time bound missed on a busy machine)
        TABLE.write_text(
            json.dumps({n: round(e["cpu"], 1) for n, e in sorted(files.items())}, indent=1) + "\n"
        )
        print(f"wrote {TABLE.relative_to(HERE.parent)}")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
