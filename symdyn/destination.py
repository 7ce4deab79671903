"""Where an output goes: what a path names, and how symdyn writes there without replacing the wrong thing.

One set of rules for every file symdyn writes (`generate --out`, `simulate --out`, `excite --out`,
`--plot`), decided here once by `destination(path)`:

- a missing file, in a folder that exists, is created with the mode `open` gives a new file (0666
  less the umask);
- an existing regular file is replaced atomically (a temporary `.NAME.PID.XXXXXXXX.tmp` beside it,
  then one rename) and keeps its permission bits and, where the system allows, its owner and group;
- a symbolic link is followed: its target is written by those rules and the link is kept (as editors
  do); a dangling link, or a loop of links, is refused;
- a character device (/dev/null, /dev/full, a terminal) and a FIFO are written in place, streamed:
  opened for writing without O_CREAT or O_TRUNC, never replaced; a FIFO that no process reads
  within FIFO_WAIT seconds is refused, and a full device (/dev/full) is "no space left on device";
- /dev/stdout, /dev/stderr, /dev/fd/N and /proc/self/fd/N are written to that open descriptor;
- a folder, a block device (a disk), a socket, an empty path, a path through a file and a name
  longer than the file system allows (255 bytes) are refused in one line.

`check_folder` refuses an output folder early and `make_folder` creates its missing folders, but
never one that a path only passes through ("a/../out" when "a" does not exist is refused, not
created); `folder_lock` holds an exclusive lock (flock) on a folder while a run writes into it, so
concurrent runs write one after the other. A path symdyn refuses is a SymdynError; a write that
fails (no space, no permission, a reader that went away) an OSError naming the output path (not a
temporary) and saying why; either way the temporary is removed and the old file is left as it was.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import stat
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

from .errors import SymdynError
from .leftovers import is_stale, remove

__all__ = [
    "FIFO_WAIT",
    "LOCK_WAIT",
    "Destination",
    "destination",
    "write_to",
    "stage",
    "commit",
    "sweep",
    "check_folder",
    "make_folder",
    "remove_folders",
    "folder_lock",
]

#: Seconds a FIFO may stay without a reader before the write is refused.
FIFO_WAIT = 10.0
#: Seconds a run waits for another run writing into the same folder.
LOCK_WAIT = 60.0
_STREAMS = re.compile(r"/dev/std(out|err)|/dev/fd/([0-9]+)|/proc/self/fd/([0-9]+)")
_NAME_MAX = 255
_TEMP_EXTRA = 32  # ".", ".PID" (up to 10 digits), ".XXXXXXXX", ".tmp" around NAME in a temporary's name


@dataclass(frozen=True)
class Destination:
    """What an output path names: `kind` is "new", "file", "device", "fifo" or "stream";
    `real` the file written (a link's target), `like` the existing file's status (None when new),
    `fd` the descriptor of a stream."""

    path: str
    kind: str
    real: Path
    like: os.stat_result | None = None
    fd: int | None = None


def _fail(path: str, what: str) -> SymdynError:
    return SymdynError(f"{path}: {what}")


def _io_error(path: str, exc: OSError, reason: str | None = None) -> OSError:
    """The OSError of a write that failed (the environment's fault, not the input's), naming the
    output path the user gave (not a temporary) and saying why in words."""
    return OSError(exc.errno, reason or _reason(exc), path)


def _reason(exc: OSError) -> str:
    return {
        errno.ENAMETOOLONG: "a name in the path is longer than the file system allows",
        errno.ENOTDIR: "the path goes through a file, not a folder",
        errno.ELOOP: "a loop of symbolic links",
    }.get(exc.errno, (exc.strerror or str(exc)).lower())


def destination(path: str | os.PathLike) -> Destination:
    """What writing to `path` means (the rules of the module); SymdynError when symdyn refuses it."""
    text = os.fspath(path)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    if text == "":
        raise SymdynError("'': the output path is empty")
    if "\0" in text:
        raise _fail(repr(text), "an output path cannot hold a NUL character")
    stream = _STREAMS.fullmatch(text)
    if stream:
        fd = {"out": 1, "err": 2}.get(stream[1]) if stream[1] else int(stream[2] or stream[3])
        return Destination(text, "stream", Path(text), fd=fd)
    try:
        st = os.lstat(text)
    except FileNotFoundError:
        if text.endswith(("/", os.sep)):
            raise _fail(text, "names a folder (it ends with a slash), which does not exist") from None
        return _new(text, Path(text))
    except OSError as exc:
        raise _fail(text, _reason(exc)) from None
    real = Path(text)
    if stat.S_ISLNK(st.st_mode):
        real = Path(os.path.realpath(text))
        try:
            st = os.stat(text)
        except FileNotFoundError:
            raise _fail(text, f"a dangling symbolic link (to {os.readlink(text)})") from None
        except OSError as exc:
            raise _fail(text, _reason(exc)) from None
    kind = _kind(text, st.st_mode)
    return Destination(text, kind, real, like=st)


def _kind(text: str, mode: int) -> str:
    if stat.S_ISREG(mode):
        return "file"
    if stat.S_ISCHR(mode):
        return "device"
    if stat.S_ISFIFO(mode):
        return "fifo"
    if stat.S_ISDIR(mode):
        raise _fail(text, "is a folder")
    if stat.S_ISBLK(mode):
        raise _fail(text, "is a block device (a disk): symdyn does not write onto disks")
    raise _fail(text, "is a socket or another special file symdyn does not write")


def _new(text: str, target: Path) -> Destination:
    folder = target.parent
    if not folder.is_dir():
        what = "is not a folder" if os.path.lexists(folder) else "does not exist"
        raise _fail(text, f"folder {folder} {what}")
    limit = _name_max(folder)
    if len(os.fsencode(target.name)) > limit:
        raise _fail(text, f"the file name is longer than the file system allows ({limit} bytes)")
    return Destination(text, "new", target)


def _name_max(folder: Path) -> int:
    try:
        return int(os.pathconf(folder, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):
        return _NAME_MAX


def _short(name: str) -> str:
    """`name` as a temporary's name holds it: cut to leave room for the rest of that name."""
    raw = os.fsencode(name)
    return os.fsdecode(raw[: _NAME_MAX - _TEMP_EXTRA]) if len(raw) > _NAME_MAX - _TEMP_EXTRA else name


def stage(dest: Destination, content: bytes) -> Path:
    """Write `content` to a new temporary beside `dest.real` (a "new" or "file" destination), with the
    mode (and owner) the file will have; the caller renames it over `dest.real` or removes it."""
    folder, prefix = dest.real.parent, f".{_short(dest.real.name)}.{os.getpid()}."
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    for _ in range(100):
        tmp = folder / f"{prefix}{secrets.token_hex(4)}.tmp"
        try:
            fd = os.open(tmp, flags, 0o666 if dest.like is None else 0o600)  # 0666: the umask applies
            break
        except FileExistsError:
            continue
        except OSError as exc:
            raise _io_error(dest.path, exc, f"cannot write in folder {folder} ({_reason(exc)})") from None
    else:  # pragma: no cover - 100 clashes of 32 random bits
        raise _fail(dest.path, f"cannot make a temporary file in {folder}")
    try:
        try:
            _write_all(fd, content)
            if dest.like is not None and hasattr(os, "fchmod"):  # POSIX (Windows has no modes to keep)
                with contextlib.suppress(OSError):  # another user's file: the owner cannot be kept
                    os.fchown(fd, dest.like.st_uid, dest.like.st_gid)
                os.fchmod(fd, stat.S_IMODE(dest.like.st_mode) & 0o777)
        finally:
            os.close(fd)
    except OSError as exc:
        _unlink(tmp)
        raise _io_error(dest.path, exc) from None
    except BaseException:
        _unlink(tmp)
        raise
    return tmp


def commit(tmp: Path, dest: Destination) -> None:
    """Rename the temporary `tmp` (from stage) over `dest.real`; removed when that fails."""
    try:
        os.replace(tmp, dest.real)
    except OSError as exc:
        _unlink(tmp)
        raise _io_error(dest.path, exc) from None


def _unlink(path: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)


def _write_all(fd: int, content: bytes) -> None:
    view = memoryview(content)
    while view:
        view = view[os.write(fd, view) :]


def write_to(dest: Destination, content: str | bytes) -> None:
    """Write `content` to `dest` by the module's rules: in place (device, FIFO, stream) or atomically."""
    data = content.encode() if isinstance(content, str) else content
    if dest.kind in ("new", "file"):
        commit(stage(dest, data), dest)
        return
    try:
        if dest.kind == "stream":
            import sys

            for stream in (sys.stdout, sys.stderr):
                with contextlib.suppress(Exception):
                    stream.flush()
            _write_all(dest.fd, data)
            return
        fd = _open_fifo(dest) if dest.kind == "fifo" else os.open(dest.real, os.O_WRONLY | os.O_NOCTTY)
        try:
            _write_all(fd, data)
        finally:
            os.close(fd)
    except OSError as exc:
        reason = {
            errno.EBADF: f"descriptor {dest.fd} is not open for writing",
            errno.EPIPE: "the reader closed it before everything was written",
        }.get(exc.errno) or _reason(exc)
        raise _io_error(dest.path, exc, reason) from None


def _open_fifo(dest: Destination) -> int:
    """Open a FIFO for writing once a process reads it (within FIFO_WAIT s), in blocking mode."""
    deadline = time.monotonic() + FIFO_WAIT
    while True:
        try:
            fd = os.open(dest.real, os.O_WRONLY | os.O_NONBLOCK)
            break
        except OSError as exc:
            if exc.errno != errno.ENXIO:
                raise
            if time.monotonic() > deadline:
                raise _fail(dest.path, f"a FIFO that no process read within {FIFO_WAIT:g} s") from None
            time.sleep(0.05)
    os.set_blocking(fd, True)
    return fd


def sweep(folder: Path, names: Iterable[str]) -> None:
    """Remove the stale temporaries (`.NAME.PID.XXXXXXXX.tmp`, or `.NAME.XXXXXXXX.tmp` of earlier
    versions) that killed runs left for the files `names` in `folder` (symdyn.leftovers)."""
    heads = {re.escape(_short(n)) for n in names}
    if not heads:
        return
    pattern = re.compile(r"\.(?:" + "|".join(sorted(heads)) + r")\.(?:([0-9]+)\.)?[a-z0-9_]{8}\.tmp\Z")
    try:
        candidates = [p for p in folder.iterdir() if p.name.endswith(".tmp")]
    except OSError:
        return
    for path in candidates:
        match = pattern.match(path.name)
        regular = match and path.is_file() and not path.is_symlink()
        if regular and is_stale(path, int(match[1]) if match[1] else None):
            remove(path)


def check_folder(out: str | os.PathLike) -> tuple[Path, list[str]]:
    """Refuse an output folder symdyn would not write into (before any work is done): '', a path
    that exists and is no folder, one through a file, one whose missing part goes up (".."); the
    deepest folder of `out` that exists and the names below it to create."""
    if os.fspath(out) == "":
        raise SymdynError("'': the output folder is empty")
    out = Path(out)
    missing: list[str] = []
    probe = out
    try:
        while not os.path.lexists(probe) and probe != probe.parent:
            missing.append(probe.name)
            probe = probe.parent
    except ValueError:  # a NUL character
        raise _fail(repr(os.fspath(out)), "an output path cannot hold a NUL character") from None
    if not probe.is_dir():
        raise _fail(str(out), "exists and is not a folder" if not missing else f"{probe} is not a folder")
    if ".." in missing:
        raise _fail(
            str(out),
            f"the path goes up ('..') from {probe / missing[-1]}, which does not exist (symdyn "
            "creates no folder only to pass through it)",
        )
    return probe, missing


def make_folder(out: str | os.PathLike) -> list[Path]:
    """Create the missing folders of `out` (check_folder's rules); the ones created, outermost first."""
    probe, missing = check_folder(out)
    created: list[Path] = []
    try:
        for name in reversed(missing):
            probe = probe / name
            try:
                os.mkdir(probe)
                created.append(probe)
            except FileExistsError:
                if not probe.is_dir():
                    raise
    except OSError as exc:
        remove_folders(created)
        raise _fail(str(out), f"cannot create folder {probe} ({_reason(exc)})") from None
    return created


def remove_folders(created: list[Path]) -> None:
    """Remove the folders make_folder created (innermost first) when they are still empty."""
    for folder in reversed(created):
        with contextlib.suppress(OSError):
            os.rmdir(folder)


@contextlib.contextmanager
def folder_lock(folder: Path, wait: float | None = None) -> Iterator[None]:
    """Hold an exclusive lock on `folder` (flock on the folder itself: no lock file is left), waiting
    up to `wait` (LOCK_WAIT) seconds for another run that holds it; SymdynError after that.
    Without fcntl (Windows) there is no lock."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    wait = LOCK_WAIT if wait is None else wait
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError as exc:
        raise _fail(str(folder), _reason(exc)) from None
    try:
        deadline = time.monotonic() + wait
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    raise _fail(
                        str(folder), f"another symdyn run has been writing into this folder for {wait:g} s"
                    ) from None
                time.sleep(0.02)
        yield
    finally:
        os.close(fd)  # closing the descriptor releases the lock
