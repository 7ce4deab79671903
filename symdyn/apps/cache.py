"""The cache of derived and generated artefacts: one folder per entry, verified before it is trusted.

Where: $SYMDYN_CACHE_DIR when set, else the user's cache folder for "symdyn"
(platformdirs: ~/.cache/symdyn on Linux, honouring $XDG_CACHE_HOME;
~/Library/Caches/symdyn on macOS; %LOCALAPPDATA%\\symdyn\\Cache on Windows).
Layout: <root>/v1/<key>/ holds the entry's files and manifest.json, which records
the key, the format, free-form metadata and the SHA-256 digest of every file.

An entry is looked up by its key (`entry_key`: a SHA-256 over symdyn's version and
whatever the caller says the content depends on). It is trusted only when its manifest
names the same key and format and every file still has its recorded digest; anything
else (a truncated file, a foreign or hand-edited folder) is removed and rebuilt. An entry
is built in a private staging folder under the root and published by one rename, so a
reader never sees half an entry, and two processes building the same entry both end
with a complete one (the loser of the rename uses the winner's after verifying it).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from .. import __version__

__all__ = ["CACHE_ENV", "Entry", "cache_dir", "entry_key", "lookup", "get_or_build", "clear", "usage"]

#: The environment variable that relocates the cache.
CACHE_ENV = "SYMDYN_CACHE_DIR"
FORMAT = 1
_LAYOUT = f"v{FORMAT}"
_MANIFEST = "manifest.json"
_STAGING = ".build-"


def cache_dir() -> Path:
    """The cache's root folder ($SYMDYN_CACHE_DIR, else the user's cache folder for symdyn)."""
    env = os.environ.get(CACHE_ENV, "").strip()
    if env:
        return Path(env).expanduser()
    try:
        import platformdirs
    except ImportError:  # the XDG rule, which platformdirs follows on Linux
        base = os.environ.get("XDG_CACHE_HOME", "").strip() or os.path.join(os.path.expanduser("~"), ".cache")
        return Path(base) / "symdyn"
    return Path(platformdirs.user_cache_dir("symdyn", appauthor=False))


@lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """SHA-256 over the name, size and modification time of symdyn's modules and templates.

    Part of every key, so that an edited checkout (same version number) never reuses
    artefacts of other code; it costs a stat per file, not a read.
    """
    package = Path(__file__).resolve().parents[1]
    files = sorted(
        [*package.rglob("*.py"), *package.parent.glob("templates/*/*.j2"), *package.glob("templates/*/*.j2")]
    )
    stamp = [(str(f.relative_to(f.parents[1])), f.stat().st_size, f.stat().st_mtime_ns) for f in files]
    return hashlib.sha256(json.dumps(stamp).encode()).hexdigest()


def entry_key(**parts) -> str:
    """A SHA-256 (hex) over symdyn's version and code, the cache format and `parts` (JSON-ready)."""
    head = {"symdyn": __version__, "code": code_fingerprint(), "format": FORMAT}
    text = json.dumps({**head, **parts}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@dataclass(frozen=True)
class Entry:
    """A verified cache entry: its folder, key and metadata."""

    path: Path
    key: str
    meta: dict

    def file(self, name: str) -> Path:
        return self.path / name


def _verified(folder: Path, key: str) -> Entry | None:
    try:
        manifest = json.loads((folder / _MANIFEST).read_text(encoding="utf-8"))
        if manifest.get("key") != key or manifest.get("format") != FORMAT:
            return None
        files = manifest["files"]
        present = {p.name for p in folder.iterdir()} - {_MANIFEST}
        if set(files) != present:
            return None
        if any(_digest(folder / name) != digest for name, digest in files.items()):
            return None
        return Entry(folder, key, manifest["meta"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def _remove(folder: Path) -> None:
    shutil.rmtree(folder, ignore_errors=True)


def lookup(key: str) -> Entry | None:
    """The entry for `key` when it exists and verifies; a folder that does not verify is removed."""
    folder = cache_dir() / _LAYOUT / key
    if not folder.is_dir():
        return None
    entry = _verified(folder, key)
    if entry is None:
        _remove(folder)
    return entry


def get_or_build(key: str, build: Callable[[Path], dict]) -> Entry:
    """The entry for `key`, built first when missing or corrupt.

    build(folder) writes the entry's files into `folder` and returns its metadata (JSON-ready).
    """
    entry = lookup(key)
    if entry is not None:
        return entry
    layout = cache_dir() / _LAYOUT
    layout.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=_STAGING, dir=layout))
    try:
        meta = build(staging)
        files = {p.name: _digest(p) for p in sorted(staging.iterdir())}
        manifest = {"key": key, "format": FORMAT, "symdyn": __version__, "files": files, "meta": meta}
        (staging / _MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True), encoding="utf-8")
        final = layout / key
        for _ in range(3):
            try:
                os.rename(staging, final)
                return Entry(final, key, meta)
            except OSError:  # another process published first, or a bad folder sits there
                entry = _verified(final, key)
                if entry is not None:
                    return entry
                _remove(final)
        raise OSError(f"{final}: cannot publish the cache entry")
    finally:
        _remove(staging)


def usage() -> tuple[Path, int, int]:
    """(root folder, number of entries, total bytes) of the cache."""
    root = cache_dir()
    layout = root / _LAYOUT
    count = size = 0
    if layout.is_dir():
        for folder in layout.iterdir():
            if folder.is_dir() and not folder.name.startswith(_STAGING):
                count += 1
                size += sum(p.stat().st_size for p in folder.iterdir() if p.is_file())
    return root, count, size


def clear() -> int:
    """Remove every entry (and leftover staging folder); returns how many entries were removed.

    Only symdyn's own layout folder is touched, never other files under the root.
    """
    layout = cache_dir() / _LAYOUT
    if not layout.is_dir():
        return 0
    count = sum(1 for f in layout.iterdir() if f.is_dir() and not f.name.startswith(_STAGING))
    _remove(layout)
    return count
