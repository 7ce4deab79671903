"""What an interrupted run leaves behind: when a temporary file or folder of symdyn's is stale.

`symdyn generate` stages each file as `.NAME.PID.XXXXXXXX.tmp` in the output folder, the
compile cache builds each entry in `.build-PID-XXXXXXXX/` under its root, and the C compiler
runs in `$TMPDIR/symdyn-build-PID-XXXXXXXX/`; the first two are renamed into place when
complete, the last removed. A run killed before that leaves them. The next run removes
the ones that are stale: their process (PID, on this machine) is gone, or they are older than
STALE_SECONDS (also the rule for leftovers without a PID, from earlier versions). A temporary
of a run still going (its process alive, younger than that) is never touched, so concurrent
runs are safe.
"""

from __future__ import annotations

import os
import shutil
import stat
import time
from pathlib import Path

__all__ = ["STALE_SECONDS", "is_stale", "remove", "pid_of", "sweep_folders"]

#: Age after which a temporary is stale whatever its process (no build takes an hour).
STALE_SECONDS = 3600.0


def _alive(pid: int) -> bool:
    """Whether a process `pid` exists on this machine (POSIX; elsewhere: assumed alive)."""
    if os.name != "posix":
        return True  # os.kill(pid, 0) is not a probe on Windows: rely on the age alone
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # it exists but belongs to someone else
        return True
    return True


def is_stale(path: Path, pid: int | None, now: float | None = None) -> bool:
    """Whether the temporary at `path`, made by process `pid` (None: unknown), is left over."""
    try:
        age = (time.time() if now is None else now) - path.lstat().st_mtime
    except OSError:
        return False  # gone already
    return age > STALE_SECONDS or (pid is not None and not _alive(pid))


def remove(path: Path) -> bool:
    """Remove a leftover file or folder; False when it could not be removed (left for later)."""
    try:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()
    except FileNotFoundError:
        return True
    except OSError:
        return False
    return True


def pid_of(name: str, prefix: str) -> int | None:
    """The process that made the folder `name` (PREFIX + PID-XXXXXXXX); None when it does not say."""
    head, sep, _ = name[len(prefix) :].partition("-")
    return int(head) if sep and head.isdigit() else None


def sweep_folders(parent: Path, prefix: str) -> None:
    """Remove the stale folders named PREFIX... under `parent` that this user owns (a live run's
    folder, or another user's in a shared $TMPDIR, is left alone)."""
    try:
        folders = [p for p in parent.iterdir() if p.name.startswith(prefix)]
    except OSError:
        return
    uid = os.getuid() if hasattr(os, "getuid") else None
    for folder in folders:
        try:
            st = folder.lstat()
        except OSError:
            continue
        ours = stat.S_ISDIR(st.st_mode) and (uid is None or st.st_uid == uid)
        if ours and is_stale(folder, pid_of(folder.name, prefix)):
            remove(folder)
