"""A warm Python for the documentation's commands (tests/test_docs.py).

Each page of docs/ runs its blocks in a Python process of its own, and each `symdyn ...` or
`python ...` line of its shell blocks started one more: about a hundred interpreters per suite,
each importing SymPy, NumPy and symdyn again (0.7 to 1.7 CPU-s apiece, most of test_docs.py's
time). Here one server process (`serve`) imports them once; a request forks it, and the child
runs the command as a fresh interpreter would (`python -m MODULE ...`, `python -c CODE ...`,
`python SCRIPT ...`: `sys.argv`, `sys.path[0]`, `__main__`, the exit status), in the caller's
working folder and environment, on the caller's own standard streams (their file descriptors
are passed over the socket, SCM_RIGHTS), unbuffered as under PYTHONUNBUFFERED.

`client` is the other end: run as `python -S warm_python.py client ARGS...` (no site
packages: it starts in milliseconds), it hands ARGS to the server named by $SYMDYN_WARM_PYTHON
and exits with the command's status, or, when no server answers or ARGS are of another form,
replaces itself by the real interpreter (`os.execve`), so a command never depends on the server.
The server waits for its children and is waited for (SIGTERM, then `wait`), so their CPU time
counts in the test process's children's time (tests/durations.py measures that).
"""

from __future__ import annotations

import contextlib
import gc
import json
import os
import socket
import struct
import sys

#: the environment variable naming the server's socket
ADDRESS_ENV = "SYMDYN_WARM_PYTHON"
#: what the server imports before it forks (what the pages' commands import)
WARM_MODULES = (
    "numpy",
    "sympy",
    "yaml",
    "symdyn",
    "symdyn.cli.main",
    "symdyn.dynamics",
    "symdyn.codegen",
    "symdyn.parsers",
    "symdyn.rnea",
)
_HEADER = struct.Struct("!I")
#: the garbage collector's thresholds of the test processes (tests/conftest.py says why) and of
#: the server's children
GC_THRESHOLDS = (100_000, 50, 100)


def _runnable(args: list[str]) -> bool:
    """Whether a child of the server runs `python ARGS` as the interpreter would: `-m MODULE`,
    `-c CODE` or a script, with no interpreter options before them."""
    if not args:
        return False
    if args[0] in ("-m", "-c"):
        return len(args) >= 2
    return not args[0].startswith("-")


def client(args: list[str], python: str) -> None:
    """`python ARGS` through the server, or the real interpreter `python` when none answers."""
    address = os.environ.get(ADDRESS_ENV, "")
    if address and _runnable(args):
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            s.connect(address)
        except OSError:  # no server: the real interpreter below
            s.close()
        else:
            request = json.dumps({"args": args, "cwd": os.getcwd(), "env": dict(os.environ)}).encode()
            socket.send_fds(s, [_HEADER.pack(len(request)) + request], [0, 1, 2])
            answer = b""
            while chunk := s.recv(64):
                answer += chunk
            os._exit(int(answer) if answer.isdigit() else 1)  # no answer: the child was killed
    env = {k: v for k, v in os.environ.items() if k != ADDRESS_ENV}
    os.execve(python, [python, *args], env)


def _receive(conn: socket.socket) -> tuple[dict, list[int]]:
    data, fds, _, _ = socket.recv_fds(conn, 1 << 16, 3)
    while len(data) < _HEADER.size:
        data += conn.recv(1 << 16)
    (size,) = _HEADER.unpack_from(data)
    while len(data) < _HEADER.size + size:
        chunk = conn.recv(1 << 16)
        if not chunk:
            raise EOFError("the request ended early")
        data += chunk
    return json.loads(data[_HEADER.size : _HEADER.size + size]), fds


def _exit_status(code) -> int:
    """The exit status of `SystemExit(code)`, as the interpreter computes it."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code & 0xFF
    print(code, file=sys.stderr)
    return 1


def _run(request: dict, fds: list[int]) -> int:
    """In a forked child: the command of `request` as `python ARGS` runs it; its exit status."""
    import io
    import runpy
    import traceback

    for target, fd in zip((0, 1, 2), fds, strict=True):
        os.dup2(fd, target)
        os.close(fd)
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    encoding = sys.stdout.encoding
    sys.stdin = io.TextIOWrapper(io.FileIO(0, "r", closefd=False), encoding=encoding)
    sys.stdout = io.TextIOWrapper(io.FileIO(1, "w", closefd=False), encoding=encoding, write_through=True)
    sys.stderr = io.TextIOWrapper(
        io.FileIO(2, "w", closefd=False), encoding=encoding, errors="backslashreplace", write_through=True
    )
    args = request["args"]
    try:
        if args[0] == "-m":
            sys.argv = [args[1], *args[2:]]
            sys.path[0] = os.getcwd()
            runpy.run_module(args[1], run_name="__main__", alter_sys=True)
        elif args[0] == "-c":
            sys.argv = ["-c", *args[2:]]
            sys.path[0] = ""
            main = type(sys)("__main__")
            sys.modules["__main__"] = main
            exec(compile(args[1], "<string>", "exec"), main.__dict__)
        else:
            sys.argv = list(args)
            sys.path[0] = os.path.dirname(os.path.abspath(args[0]))
            runpy.run_path(args[0], run_name="__main__")
        status = 0
    except SystemExit as exc:
        status = _exit_status(exc.code)
    except BaseException:
        traceback.print_exc()
        status = 1
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):
            stream.flush()
    return status


def _reap(block: bool) -> None:
    """Wait for the ended children (all of them when `block`): reaped, their CPU time counts in
    this process's children's time, and so in that of the test process that waits for it."""
    while True:
        try:
            pid, _ = os.waitpid(-1, 0 if block else os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return


def serve(address: str) -> None:
    """Import WARM_MODULES, then serve requests on the Unix socket `address` until SIGTERM: each
    one runs in a forked child, which sends the command's exit status back when it ends. On
    SIGTERM, or when its parent (the test process) is gone, the server waits for its children
    and exits."""
    import importlib
    import signal

    for name in WARM_MODULES:
        importlib.import_module(name)
    # what the imports made is never garbage: frozen, the children's full collections skip it
    # (and leave its pages shared); they collect as the test processes do (tests/conftest.py)
    gc.collect()
    gc.freeze()
    gc.set_threshold(*GC_THRESHOLDS)

    def stop(signum, frame):
        _reap(block=True)
        os._exit(0)

    signal.signal(signal.SIGTERM, stop)
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(address)
    listener.listen(16)
    listener.settimeout(5.0)
    parent = os.getppid()
    print("ready", flush=True)
    while True:
        try:
            conn, _ = listener.accept()
        except TimeoutError:
            _reap(block=False)
            if os.getppid() != parent:  # the test process is gone (killed): so is the server
                stop(signal.SIGTERM, None)
            continue
        conn.settimeout(None)
        _reap(block=False)
        try:
            request, fds = _receive(conn)
        except (OSError, EOFError, ValueError):
            conn.close()
            continue
        sys.stdout.flush()
        sys.stderr.flush()
        if os.fork() == 0:
            listener.close()
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            status = 1
            try:
                status = _run(request, fds)
            finally:
                try:
                    conn.sendall(str(status).encode())
                finally:
                    os._exit(status)
        conn.close()
        for fd in fds:
            os.close(fd)


if __name__ == "__main__":
    if sys.argv[1:2] == ["serve"]:
        serve(sys.argv[2])
    elif sys.argv[1:2] == ["client"]:
        client(sys.argv[3:], sys.argv[2])
    else:
        sys.exit("usage: warm_python.py serve ADDRESS | client PYTHON ARGS...")
