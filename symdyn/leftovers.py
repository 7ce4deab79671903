"""What an interrupted run leaves behind: when a temporary file or folder of symdyn's is stale.

`symdyn generate` stages each file as `.NAME.PID.XXXXXXXX.tmp` in the output folder and the
compile cache builds each entry in `.build-PID-XXXXXXXX/` under its root; both are renamed
into place when complete. A run killed before the rename leaves them. The next run removes
the ones that are stale: their process (PID, on this machine) is gone, or they are older than
STALE_SECONDS (also the rule for leftovers without a PID, from earlier versions). A temporary
of a run still going (its process alive, younger than that) is never touched, so concurrent
runs are safe.
"""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

__all__ = ["STALE_SECONDS", "is_stale", "remove"]

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
