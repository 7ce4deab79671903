"""The batch library of symdyn.compile, built when a batch call first needs it (batch_library).

One-state calls and a simulation build the scalar library alone; the first batch call builds the
batch library once, whichever threads call at once, and its results equal the one-state calls bit
for bit; a later compile of the robot finds both in the cache. A compiler that fails on the batch
files leaves the scalar library working and raises one line, again at the next batch call; a
scalar object file changed in the cache is found before the batch library links it.
"""

from __future__ import annotations

import os
import shutil
import threading
from pathlib import Path

import numpy as np
import pytest
from cbuild import compilers
from robots import example
from timebound import within

import symdyn
from symdyn.apps.compilation import batch_library, build, cache
from symdyn.apps.simulation.simulate import simulate
from symdyn.errors import SymdynError

pytestmark = pytest.mark.skipif(not compilers(), reason="needs a C compiler")


@pytest.fixture
def built(tmp_path, monkeypatch) -> list[str]:
    """An empty cache of its own; the names of the libraries compile_library builds from now on."""
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path / "cache"))
    monkeypatch.delenv("CC", raising=False)
    names: list[str] = []
    real = build.compile_library

    def counting(compiler, sources, target, *args, **kwargs):
        names.append(Path(target).name)
        return real(compiler, sources, target, *args, **kwargs)

    monkeypatch.setattr(build, "compile_library", counting)
    return names


def _states(n: int, count: int) -> list[np.ndarray]:
    rng = np.random.default_rng(42)
    return [rng.uniform(-2, 2, (count, n)) for _ in range(3)]


def test_one_state_calls_build_the_scalar_library_and_a_batch_the_batch_library_once(built, monkeypatch):
    robot = example("planar_3r")
    fast = symdyn.compile(robot)
    q, qd, qdd = _states(robot.n, 37)
    one = np.array([fast.inverse_dynamics(*s) for s in zip(q, qd, qdd, strict=True)])
    simulate(fast, q[0], duration=0.02, dt=1e-3)
    assert fast.cdll.symdyn_simulate and fast.pointer("forward_dynamics")
    assert built == ["libplanar_3r.so"] and cache.usage()[1] == 1
    assert not hasattr(fast.cdll, "planar_3r_inverse_dynamics_batch")  # the scalar library has none
    results, start = [None] * 4, threading.Barrier(4)

    def first_batch(k: int) -> None:
        start.wait()
        results[k] = fast.inverse_dynamics(q, qd, qdd)

    threads = [threading.Thread(target=first_batch, args=(k,)) for k in range(4)]
    with within(60):
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    assert built == ["libplanar_3r.so", "libplanar_3r_batch.so"] and cache.usage()[1] == 2
    for tau in results:
        assert tau.tobytes() == one.tobytes()  # the same bits as the one-state calls
    M = fast.mass_matrix(q)
    assert M.tobytes() == np.array([fast.mass_matrix(s) for s in q]).tobytes()
    np.testing.assert_allclose(one, symdyn.rnea(robot, q, qd, qdd), rtol=1e-10, atol=1e-10)
    assert fast.batch_width >= 1 and len(built) == 2
    monkeypatch.setattr(batch_library, "_ENTRIES", {})  # as a new process: from the cache alone
    again = symdyn.compile(robot)
    assert again.inverse_dynamics(q, qd, qdd).tobytes() == one.tobytes() and len(built) == 2
    with pytest.raises(SymdynError, match='batch must be "lazy" or "eager", not \'sometimes\''):
        symdyn.compile(robot, batch="sometimes")


def test_a_failed_batch_build_leaves_the_one_state_calls(built, tmp_path, monkeypatch):
    """A compiler that fails on the batch files only: the scalar library builds and works, every
    batch call (and batch="eager") raises one line naming the batch library."""
    cc = tmp_path / "cc"
    cc.write_text(
        '#!/bin/sh\nfor a in "$@"; do case "$a" in *_batch*.c) echo "$a:1: error: no batch here" >&2; '
        f'exit 1;; esac; done\nexec {shutil.which(compilers()[0])} "$@"\n'
    )
    os.chmod(cc, 0o755)
    monkeypatch.setenv("CC", str(cc))
    robot = example("planar_3r")
    q, qd, qdd = _states(robot.n, 5)
    message = (
        r"^symdyn.compile: the batch library libplanar_3r_batch.so of robot 'planar_3r' was not built "
        r"\(one-state calls still work\): the C compiler failed \(.* planar_3r_batch\.c .*\): "
        r"planar_3r_batch\.c:1: error: no batch here$"
    )
    with within(60):
        with pytest.raises(SymdynError, match=message) as failed:
            symdyn.compile(robot, batch="eager")
        assert "\n" not in str(failed.value)
        fast = symdyn.compile(robot)
        tau = fast.inverse_dynamics(q[0], qd[0], qdd[0])
        np.testing.assert_allclose(tau, symdyn.rnea(robot, q[0], qd[0], qdd[0]), rtol=1e-10, atol=1e-10)
        for call in (lambda: fast.inverse_dynamics(q, qd, qdd), lambda: fast.batch_width):
            with pytest.raises(SymdynError, match=message):
                call()
        after = fast.inverse_dynamics(q[1], qd[1], qdd[1])  # still working after the failures
        np.testing.assert_allclose(after, symdyn.rnea(robot, q[1], qd[1], qdd[1]), rtol=1e-10, atol=1e-10)
    assert built == ["libplanar_3r.so", *["libplanar_3r_batch.so"] * 3] and cache.usage()[1] == 1


def test_a_changed_object_file_is_rebuilt_before_the_batch_links_it(built):
    """The scalar objects the batch library links are verified against the entry's manifest when a
    later compile (a cache hit, which verifies the library alone) first needs them: one changed since
    the build removes the entry, which is built again, then the batch library."""
    robot = example("planar_3r")
    first = symdyn.compile(robot)
    (first._entry.path / first._entry.meta["batch"]["objects"][0]).write_bytes(b"not an object file")
    fast = symdyn.compile(robot)  # as a later process: the scalar library verified and loaded
    q, qd, qdd = _states(robot.n, 5)
    with within(60):
        tau = fast.inverse_dynamics(q, qd, qdd)
    assert built == ["libplanar_3r.so", "libplanar_3r.so", "libplanar_3r_batch.so"]
    one = np.array([fast.inverse_dynamics(*s) for s in zip(q, qd, qdd, strict=True)])
    assert tau.tobytes() == one.tobytes()
