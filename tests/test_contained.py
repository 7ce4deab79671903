"""The contained child process (symdyn.parsers.contained), layer by layer, as root (as CI runs).

Each layer is tested alone in a child that tries every escape: the kernel's seccomp filter with
no audit hook (as if an expression had found a route the hook does not see), then the audit hook
with no seccomp filter; each escape must fail, and no file it tried to make may exist after.
The parent's side: `run` kills the child's process group, `Server` answers, and stops a child
that runs out of time.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from symdyn.parsers import contained
from tests.timebound import within

HERE = Path(contained.__file__).parent

#: a child that tries each escape in turn and prints what happened to each
ESCAPES = r"""
import json, os, socket, subprocess, sys, threading
import _posixsubprocess, ctypes
sys.path.insert(0, sys.argv[1])
import contained
maps = open("/proc/self/maps").read()
native = next(n for n in ("libsqlite3.so.0", "libbz2.so.1.0", "libuuid.so.1", "libffi.so.8") if n not in maps)
tmp = sys.argv[2]
if sys.argv[3] == "kernel":
    assert contained._seccomp(False)
else:
    contained._install_hook(lambda: False)
def attempt(name, act):
    try:
        got = act()
    except BaseException as exc:
        return name, f"refused: {type(exc).__name__}"
    return name, f"done: {got!r}"
def fork_exec():
    r, w = os.pipe()
    exe = b"/bin/sh"
    return _posixsubprocess.fork_exec([exe, b"-c", f"touch {tmp}/fork_exec".encode()], (exe,), True, (w,),
        None, None, -1, -1, -1, -1, -1, -1, r, w, True, True, -1, None, None, None, -1, None, True)
results = dict([
    attempt("os.system", lambda: os.system(f"touch {tmp}/system") or "status 0"),
    attempt("detached", lambda: os.system(f'setsid sh -c "sleep 1; touch {tmp}/detached" &') or "status 0"),
    attempt("subprocess", lambda: subprocess.run(["touch", f"{tmp}/subprocess"])),
    attempt("fork_exec", fork_exec if sys.argv[3] == "kernel" else lambda: 1 / 0),
    attempt("fork", lambda: os.fork() or os._exit(0)),
    attempt("thread", lambda: threading.Thread(target=lambda: None).start()),
    attempt("os.open", lambda: os.open(f"{tmp}/created", os.O_CREAT | os.O_WRONLY)),
    attempt("open w", lambda: open(f"{tmp}/keep", "w")),
    attempt("open a", lambda: open(f"{tmp}/keep", "a")),
    attempt("remove", lambda: os.remove(f"{tmp}/keep")),
    attempt("rename", lambda: os.rename(f"{tmp}/keep", f"{tmp}/renamed")),
    attempt("mkdir", lambda: os.mkdir(f"{tmp}/folder")),
    attempt("chmod", lambda: os.chmod(f"{tmp}/keep", 0o777)),
    attempt("socket", lambda: socket.socket()),
    attempt("ctypes", lambda: ctypes.CDLL(native)),
    attempt("kill parent", lambda: os.kill(os.getppid(), 0)),
])
results["read"] = open(f"{tmp}/keep").read()
print(json.dumps(results))
"""


def _escapes(tmp_path: Path, layer: str) -> dict[str, str]:
    (tmp_path / "keep").write_text("kept")
    done = subprocess.run(
        [sys.executable, "-B", "-c", ESCAPES, str(HERE), str(tmp_path), layer],
        capture_output=True,
        text=True,
        timeout=60,
        start_new_session=True,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _seccomp_available() -> bool:
    try:
        import pyseccomp  # noqa: F401
    except (ImportError, RuntimeError, OSError):
        return False
    return sys.platform.startswith("linux")


@pytest.mark.parametrize("layer", ["kernel", "hook"])
def test_each_layer_alone_refuses_every_escape(tmp_path, layer):
    if layer == "kernel" and not _seccomp_available():
        pytest.skip("seccomp needs Linux and libseccomp")
    results = _escapes(tmp_path, layer)
    assert results.pop("read") == "kept"  # reading stays allowed
    if layer == "hook":  # signals, threads and _posixsubprocess (no audit event) are the kernel's
        results.pop("kill parent"), results.pop("thread"), results.pop("fork_exec")
    for name, what in results.items():
        if name in ("os.system", "detached") and what.startswith("done"):
            assert what != "done: 'status 0'", (name, what)  # the shell could not be started
        else:
            assert what.startswith("refused"), (name, what)
    time.sleep(1.5)  # the detached child would have touched its file by now
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep"]
    assert (tmp_path / "keep").stat().st_mode & 0o777 != 0o777


def test_the_hook_names_the_first_act_it_refused():
    assert contained._act("os.system", ("ls",)) == "run a process"
    assert contained._act("open", ("f", "r", os.O_RDONLY)) is None
    assert contained._act("open", ("f", None, os.O_WRONLY | os.O_CREAT)) == "write to the file system"
    assert contained._act("open", ("f", "rb+", os.O_RDWR)) == "write to the file system"
    assert contained._act("socket.__new__", (None, 2, 1, 0)) == "open a network connection"
    assert contained._act("ctypes.dlopen", ("libc.so.6",)) == "load native code"
    assert contained._act("object.__setattr__", (len, "__code__", None)) == "change the interpreter"
    assert contained._act("compile", (b"1 + 1", "<string>")) is None


def test_run_kills_the_process_group_when_the_child_ends(tmp_path):
    marker = tmp_path / "late"
    script = f"import os; os.system('(sleep 1; touch {marker}) &'); print('started')"
    with within(20):
        done = contained.run([sys.executable, "-c", script], b"", 10)
    assert (done.stdout, done.status, done.timed_out) == (b"started\n", 0, False)
    time.sleep(1.5)
    assert not marker.exists()


def test_run_stops_a_child_out_of_time():
    with within(20):
        done = contained.run([sys.executable, "-c", "import time; time.sleep(30)"], b"", 1)
    assert done.timed_out


def test_the_server_answers_and_stops_a_child_out_of_time(tmp_path):
    script = tmp_path / "server.py"
    script.write_text(
        f"import sys, time; sys.path.insert(0, {str(HERE)!r}); import contained\n"
        "def handle(request):\n"
        "    time.sleep(request['sleep'])\n"
        "    return {'echo': request['word']}, request['word'].encode() * 3\n"
        "contained.serve(handle, threads=False)\n"
    )
    server = contained.Server([sys.executable, "-B", str(script)])
    try:
        with within(60):
            assert server.request({"word": "ab", "sleep": 0}, 10, 2**31) == (
                {"echo": "ab", "status": 0, "timed_out": False},
                b"ababab",
            )
            meta, blob = server.request({"word": "cd", "sleep": 30}, 1, 2**31)
            assert meta["timed_out"] and blob == b""
            assert server.request({"word": "ef", "sleep": 0}, 10, 2**31)[1] == b"efefef"
    finally:
        server.close()
