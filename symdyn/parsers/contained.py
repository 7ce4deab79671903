"""A contained child process: where symdyn runs the interpreters of untrusted files (xacro's
expressions, MuJoCo's compiler), which may compute and read files and do nothing else.

A xacro file is a program (its ${...} are Python expressions, and Python's object graph reaches
os.system from any of them), and MuJoCo's compiler is native code that allocates what a file asks.
So both run in a child process that `confine` shuts in, layer by layer, before it reads the file:

1. rlimits: address space MEMORY, CPU time, no file growth (RLIMIT_FSIZE 0: pipes are not
   files), no core dumps, no new processes (RLIMIT_NPROC 0, which root ignores: hence 2.);
2. the kernel (Linux, libseccomp through `pyseccomp`): a seccomp filter, which also sets
   no_new_privs, answers EPERM to creating a process (fork, vfork, clone without CLONE_THREAD,
   execve), opening a file for writing, creating, deleting or renaming a file or folder, changing
   its mode, owner or times, sockets, mapping executable memory (loading native code), signalling
   another process, ptrace and io_uring; it cannot be undone by anything the child runs;
3. a Python audit hook (sys.addaudithook), installed before the file's interpreter is imported,
   refuses the same acts at Python's level (os.system, subprocess, open for writing, os.remove,
   shutil, socket, ctypes, ...) and further imports, and remembers the first act it refused, so that
   the child can say in one line what the file tried (`refused`); it cannot be removed either.

The parent runs the child in a session of its own and kills the whole process group when it is
done or out of time (`run`, `Server`). Layer 2 needs Linux and libseccomp; elsewhere 1 and 3 hold.

This module imports the standard library only (pyseccomp when confining), so that the runners,
started as scripts, import it without symdyn on the path.
"""

from __future__ import annotations

import atexit
import contextlib
import json
import os
import select
import signal
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import Any, NamedTuple

__all__ = ["MEMORY", "TIMEOUT", "Outcome", "Server", "confine", "refused", "run", "serve"]

#: seconds a contained child may take
TIMEOUT = 60
#: bytes of address space a contained child may use
MEMORY = 2 * 2**30

#: what each refused act is called in the one-line message, by the audit events that do it
_ACTS = (
    ("run a process", ("os.system", "os.exec", "os.posix_spawn", "os.spawn", "os.fork", "os.forkpty",
                       "subprocess.", "pty.", "os.startfile", "os.kill", "os.killpg", "signal.pthread_kill")),
    ("write to the file system", ("os.remove", "os.rename", "os.rmdir", "os.mkdir", "os.link", "os.symlink",
                                  "os.truncate", "os.chmod", "os.chown", "os.chflags", "os.lchflags",
                                  "os.utime", "os.setxattr", "os.removexattr", "os.mkfifo", "os.mknod",
                                  "shutil.", "tempfile.", "os.chdir", "os.chroot")),
    ("open a network connection", ("socket.", "http.", "urllib.", "ftplib.", "smtplib.", "poplib.",
                                   "imaplib.", "nntplib.", "telnetlib.", "webbrowser.", "ensurepip.")),
    ("load native code", ("ctypes.", "mmap.", "cpython._PySys_ClearAuditHooks")),
    ("change the interpreter", ("sys.settrace", "sys.setprofile", "sys.addaudithook", "gc.", "code.__new__",
                                "function.__new__", "sys._current_frames", "sys.monitoring.")),
)  # fmt: skip
_WRITE_FLAGS = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND
#: the first act the audit hook refused in this process (None: none yet)
_refused: list[str] = []


def refused() -> str | None:
    """The first act the audit hook refused, as "to run a process (os.system)", or None."""
    return _refused[0] if _refused else None


def _act(event: str, args: tuple) -> str | None:
    """What refused act the audit event `event` is, or None when it is allowed."""
    if event == "open":
        mode, flags = args[1], args[2]
        writes = isinstance(flags, int) and flags & _WRITE_FLAGS
        if writes or (isinstance(mode, str) and set(mode) & set("wax+")):
            return "write to the file system"
        return None
    if event == "object.__setattr__" and args[1] in (
        "__code__",
        "__globals__",
        "__defaults__",
        "__kwdefaults__",
    ):
        return "change the interpreter"
    for what, prefixes in _ACTS:
        if event.startswith(prefixes):
            return what
    return None


def _install_hook(allow_import: Callable[[], bool]) -> None:
    """The audit hook of layer 3 (see the module documentation)."""

    def hook(event: str, args: tuple) -> None:
        if event == "import":
            name = str(args[0])
            if allow_import() or name.startswith("encodings."):
                return
            what = "load a module"
        else:
            what = _act(event, args)
            if what is None:
                return
        if not _refused:
            _refused.append(f"to {what} ({event}{' ' + str(args[0]) if event == 'import' else ''})")
        raise PermissionError(f"refused: {event}")

    sys.addaudithook(hook)


def _seccomp(threads: bool) -> bool:
    """Load layer 2's seccomp filter; False when this system has none (not Linux, no libseccomp)."""
    try:
        import pyseccomp as sc
    except (ImportError, RuntimeError, OSError):
        return False
    deny = sc.ERRNO(1)  # EPERM
    filt = sc.SyscallFilter(sc.ALLOW)
    names = [
        "fork", "vfork", "execve", "execveat", "creat", "unlink", "unlinkat", "rename", "renameat",
        "renameat2", "mkdir", "mkdirat", "rmdir", "link", "linkat", "symlink", "symlinkat", "mknod",
        "mknodat", "truncate", "ftruncate", "chmod", "fchmod", "fchmodat", "chown", "fchown", "fchownat",
        "lchown", "utime", "utimes", "utimensat", "futimesat", "setxattr", "lsetxattr", "fsetxattr",
        "removexattr", "lremovexattr", "fremovexattr", "mount", "umount2", "pivot_root", "chroot",
        "socket", "socketpair", "ptrace", "process_vm_writev", "process_vm_readv", "memfd_create",
        "io_uring_setup", "io_uring_enter", "io_uring_register", "bpf", "perf_event_open",
        "userfaultfd", "unshare", "setns", "tkill", "pidfd_open", "pidfd_send_signal", "pidfd_getfd",
        "kexec_load", "init_module", "finit_module", "delete_module", "keyctl", "add_key",
        "request_key", "name_to_handle_at", "open_by_handle_at", "fanotify_init", "inotify_init1",
        "swapon", "swapoff", "reboot", "acct", "sethostname", "setdomainname", "settimeofday",
        "clock_settime", "adjtimex", "quotactl",
    ]  # fmt: skip
    for name in names:
        _rule(sc, filt, deny, name)
    for name in ("clone3", "openat2"):  # their flags are in a struct: glibc falls back on ENOSYS
        _rule(sc, filt, sc.ERRNO(38), name)
    clone_thread = 0x00010000
    if threads:
        _rule(sc, filt, deny, "clone", sc.Arg(0, sc.MASKED_EQ, clone_thread, 0))
    else:
        _rule(sc, filt, deny, "clone")
    for name, index in (("open", 1), ("openat", 2)):
        for bit in (os.O_WRONLY, os.O_RDWR, os.O_CREAT, os.O_TRUNC, os.O_APPEND):
            _rule(sc, filt, deny, name, sc.Arg(index, sc.MASKED_EQ, bit, bit))
    prot_exec = 0x4
    for name in ("mmap", "mprotect", "pkey_mprotect"):
        _rule(sc, filt, deny, name, sc.Arg(2, sc.MASKED_EQ, prot_exec, prot_exec))
    me = os.getpid()
    for name in ("kill", "tgkill", "rt_sigqueueinfo", "rt_tgsigqueueinfo"):
        _rule(sc, filt, deny, name, sc.Arg(0, sc.NE, me))
    _rule(sc, filt, deny, "ioctl", sc.Arg(1, sc.EQ, 0x5412))  # TIOCSTI: typing into a terminal
    filt.load()
    return True


def _rule(sc: Any, filt: Any, action: int, name: str, *args: Any) -> None:
    """One rule, skipped when this architecture has no such system call."""
    with contextlib.suppress(OSError, ValueError, RuntimeError):
        filt.add_rule(action, name, *args)


def confine(memory: int, seconds: float, *, threads: bool = False) -> Callable[[], None]:
    """Shut this (child) process in (module documentation), and return a function that closes
    imports: call it once the file's interpreter (xacro) is imported. `threads`: the child may
    start threads (MuJoCo's compiler does), never processes."""
    try:
        import resource
    except ImportError:  # not POSIX: the parent's time bound is all there is
        resource = None
    if resource is not None:
        cpu = int(seconds) + 1
        for limit, value in (
            (resource.RLIMIT_AS, memory),
            (resource.RLIMIT_CPU, cpu),
            (resource.RLIMIT_FSIZE, 0),
            (resource.RLIMIT_CORE, 0),
        ) + (() if threads else ((resource.RLIMIT_NPROC, 0),)):
            with contextlib.suppress(ValueError, OSError):
                resource.setrlimit(limit, (value, value))
    if sys.platform.startswith("linux"):
        _seccomp(threads)
    state = {"open": True}
    _install_hook(lambda: state["open"])
    return lambda: state.update(open=False)


class Outcome(NamedTuple):
    """What a contained child left: its output, its exit status, whether it ran out of time."""

    stdout: bytes
    stderr: bytes
    status: int
    timed_out: bool


def _kill_group(pid: int) -> None:
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pid, signal.SIGKILL)


def run(argv: list[str], data: bytes, seconds: float, env: dict[str, str] | None = None) -> Outcome:
    """Run `argv` in a session of its own with `data` on its stdin, for at most `seconds`; its
    whole process group is killed as soon as it exits or runs out of time."""
    proc = subprocess.Popen(
        argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        start_new_session=True, env=env,
    )  # fmt: skip
    out: list[bytes] = []
    err: list[bytes] = []

    def feed() -> None:
        try:
            proc.stdin.write(data)
            proc.stdin.close()
        except OSError:  # the child stopped reading
            pass

    workers = [threading.Thread(target=feed, daemon=True)]
    workers += [
        threading.Thread(target=lambda s=stream, b=into: b.append(s.read()), daemon=True)
        for stream, into in ((proc.stdout, out), (proc.stderr, err))
    ]
    for worker in workers:
        worker.start()
    timed_out = False
    try:
        proc.wait(timeout=seconds)
    except subprocess.TimeoutExpired:
        timed_out = True
    finally:
        _kill_group(proc.pid)  # what the child left behind in its group, and the child itself
        proc.kill()
        proc.wait()
    for worker in workers:
        worker.join(timeout=5)
    for stream in (proc.stdout, proc.stderr):
        stream.close()
    return Outcome(b"".join(out), b"".join(err), proc.returncode, timed_out)


def _write_frame(fd: int, payload: bytes) -> None:
    view = memoryview(struct.pack(">Q", len(payload)) + payload)
    while view:
        view = view[os.write(fd, view) :]


def _read_exact(fd: int, count: int, deadline: float | None) -> bytes | None:
    """`count` bytes from `fd`, or None at end of file or past `deadline` (time.monotonic)."""
    chunks, got = [], 0
    while got < count:
        if deadline is not None:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([fd], [], [], left)[0]:
                return None
        chunk = os.read(fd, min(count - got, 1 << 20))
        if not chunk:
            return None
        chunks.append(chunk)
        got += len(chunk)
    return b"".join(chunks)


def _read_frame(fd: int, deadline: float | None, limit: int) -> bytes | None:
    head = _read_exact(fd, 8, deadline)
    if head is None or struct.unpack(">Q", head)[0] > limit:
        return None
    return _read_exact(fd, struct.unpack(">Q", head)[0], deadline)


def serve(handle: Callable[[dict], tuple[dict, bytes]], *, threads: bool) -> None:
    """The loop of a server child (a zygote, which has imported what `handle` needs): for each
    request frame on stdin it forks a child that confines itself (request "memory", "seconds"),
    answers with `handle(request)` -> (meta, blob) and exits; the server kills the child's group
    when it runs out of time and writes the frames meta (with "status", "timed_out") and blob."""
    with contextlib.suppress(ImportError, RuntimeError, OSError):  # once here, not in every child
        import pyseccomp  # noqa: F401
    while True:
        frame = _read_frame(0, None, 1 << 20)
        if frame is None:
            return
        request = json.loads(frame)
        seconds = float(request["seconds"])
        read_end, write_end = os.pipe()
        pid = os.fork()
        if pid == 0:  # the contained child
            os.close(read_end)
            code = 0
            try:
                os.setsid()
                quiet = os.open(os.devnull, os.O_RDWR)
                for fd in (0, 1, 2):  # the server's pipes are not the child's to write
                    os.dup2(quiet, fd)
                confine(int(request["memory"]), seconds, threads=threads)
                meta, blob = handle(request)
                _write_frame(write_end, json.dumps(meta).encode())
                _write_frame(write_end, blob)
            except BaseException:  # noqa: BLE001 - the status says it failed
                code = 1
            os._exit(code)
        os.close(write_end)
        deadline = time.monotonic() + seconds
        meta = _read_frame(read_end, deadline, 1 << 24)
        blob = _read_frame(read_end, deadline, 1 << 40) if meta is not None else None
        complete = meta is not None and blob is not None
        timed_out = not complete and time.monotonic() >= deadline
        _kill_group(pid)  # done or not, nothing of it goes on
        os.close(read_end)
        status = os.waitpid(pid, 0)[1]
        answer = json.loads(meta) if complete else {}
        answer.update(status=0 if complete else status, timed_out=timed_out)
        _write_frame(1, json.dumps(answer).encode())
        _write_frame(1, blob if complete else b"")


class Server:
    """A server child (`serve`) started by `argv` on first use and kept for later requests: a
    request costs a fork of an interpreter that has already imported its modules."""

    def __init__(self, argv: list[str], env: dict[str, str] | None = None) -> None:
        self._argv, self._env = argv, env
        self._proc: subprocess.Popen | None = None
        self._lock = threading.Lock()
        atexit.register(self.close)

    def request(self, request: dict, seconds: float, memory: int) -> tuple[dict, bytes]:
        """The answer (meta, blob) to `request`, from a child confined to `memory` bytes and
        `seconds`; meta holds "status" and "timed_out"."""
        with self._lock:
            for _attempt in (0, 1):
                proc = self._start()
                try:
                    message = json.dumps({**request, "seconds": seconds, "memory": memory}).encode()
                    _write_frame(proc.stdin.fileno(), message)
                    deadline = time.monotonic() + seconds + 30
                    meta = _read_frame(proc.stdout.fileno(), deadline, 1 << 24)
                    blob = _read_frame(proc.stdout.fileno(), deadline, 1 << 40) if meta else None
                except OSError:
                    meta = blob = None
                if meta is not None and blob is not None:
                    return json.loads(meta), blob
                self.close()
            return {"status": -1, "timed_out": True}, b""

    def _start(self) -> subprocess.Popen:
        if self._proc is None or self._proc.poll() is not None:
            self._proc = subprocess.Popen(
                self._argv,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                start_new_session=True,
                env=self._env,
            )
        return self._proc

    def close(self) -> None:
        """Stop the server child and whatever is left of its children."""
        if self._proc is not None:
            _kill_group(self._proc.pid)
            self._proc.kill()
            self._proc.wait()
            self._proc.stdin.close()
            self._proc.stdout.close()
            self._proc = None
