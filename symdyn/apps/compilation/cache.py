"""The cache of derived and generated artefacts: one folder per entry, verified before it is trusted.

Where: $SYMDYN_CACHE_DIR when set (a relative path is taken from the current folder when read),
else the user's cache folder for "symdyn"
(platformdirs: ~/.cache/symdyn on Linux, honouring $XDG_CACHE_HOME;
~/Library/Caches/symdyn on macOS; %LOCALAPPDATA%\\symdyn\\Cache on Windows).
Layout: <root>/v1/<key>/ holds the entry's files and manifest.json, which records
the key, the format, free-form metadata and the SHA-256 digest of every file.

An entry is looked up by its key (`entry_key`: a SHA-256 over symdyn's version and
whatever the caller says the content depends on). It is trusted only when its manifest
names the same key and format, its folder holds exactly the files the manifest lists, and
every file still has its recorded digest before it is used: `lookup` checks the digests of
the files the caller names as the ones it will load (all of them unless told), and
`Entry.file` checks any other file when it is first asked for (so a warm run hashes the
library it loads, not the generated sources it never reads). Anything else (a truncated
file, a foreign or hand-edited folder) is removed and rebuilt; a file found corrupt by
`Entry.file` removes the entry and raises `CorruptEntryError`, on which the caller rebuilds.
An entry is built in a private staging folder under the root (`.build-PID-XXXXXXXX`) and
published by one rename, so a reader never sees half an entry, and two processes building the
same entry both end with a complete one (the loser of the rename uses the winner's after
verifying it). A build removes the staging folders that runs killed mid-build left, once stale
(symdyn.leftovers: their process gone, or older than an hour); `usage` counts them.
A cache folder that cannot be written (read-only, full) raises SymdynError naming it and
$SYMDYN_CACHE_DIR, never a raw OSError.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from ... import __version__
from ...errors import SymdynError
from ...leftovers import sweep_folders

__all__ = [
    "CACHE_ENV",
    "CorruptEntryError",
    "Entry",
    "cache_dir",
    "entry_key",
    "lookup",
    "get_or_build",
    "clear",
    "usage",
    "leftovers",
]

#: The environment variable that relocates the cache.
CACHE_ENV = "SYMDYN_CACHE_DIR"
FORMAT = 1
_LAYOUT = f"v{FORMAT}"
_MANIFEST = "manifest.json"
_STAGING = ".build-"


def cache_dir() -> Path:
    """The cache's root folder ($SYMDYN_CACHE_DIR, else the user's cache folder for symdyn)."""
    env = os.environ.get(CACHE_ENV, "").strip()
    if env:  # absolute now: the compiler runs in another folder, and a relative root would move with it
        return Path(os.path.abspath(os.path.expanduser(env)))
    try:
        import platformdirs
    except ImportError:  # the XDG rule, which platformdirs follows on Linux
        base = os.environ.get("XDG_CACHE_HOME", "").strip() or os.path.join(os.path.expanduser("~"), ".cache")
        return Path(base) / "symdyn"
    return Path(platformdirs.user_cache_dir("symdyn", appauthor=False))


def _stamps(folder: str, suffix: str, depth: int, under: str) -> list[tuple[str, int, int]]:
    """(path below `under`, size, mtime in ns) of the files named *suffix in `folder`, `depth` levels down
    (-1: every level), sub-folders "__pycache__" and hidden ones skipped."""
    found = []
    with os.scandir(folder) as entries:
        for e in entries:
            if e.is_dir() and depth != 0 and e.name != "__pycache__" and not e.name.startswith("."):
                found += _stamps(e.path, suffix, depth - 1, under)
            elif e.name.endswith(suffix) and depth <= 0 and e.is_file():
                st = e.stat()
                found.append((e.path[len(under) + 1 :], st.st_size, st.st_mtime_ns))
    return found


@lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """SHA-256 over the name, size and modification time of symdyn's modules and templates.

    Part of every key, so that an edited checkout (same version number) never reuses
    artefacts of other code; it costs a stat per file, not a read. The templates are
    templates/*/*.j2 beside the package (a checkout) or inside it (an installed wheel).
    """
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    root = os.path.dirname(package)
    stamp = _stamps(package, ".py", -1, root)
    for templates in (os.path.join(root, "templates"), os.path.join(package, "templates")):
        if os.path.isdir(templates):
            stamp += _stamps(templates, ".j2", 1, root)
    return hashlib.sha256(json.dumps(sorted(stamp)).encode()).hexdigest()


def entry_key(**parts) -> str:
    """A SHA-256 (hex) over symdyn's version and code, the cache format and `parts` (JSON-ready)."""
    head = {"symdyn": __version__, "code": code_fingerprint(), "format": FORMAT}
    text = json.dumps({**head, **parts}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


class CorruptEntryError(SymdynError):
    """A file of a cache entry no longer has its recorded digest (the entry has been removed)."""


@dataclass(frozen=True)
class Entry:
    """A cache entry: its folder, key, metadata, and the manifest's digest of every file.

    `checked` names the files whose digest has been verified in this process.
    """

    path: Path
    key: str
    meta: dict
    digests: dict[str, str] = field(default_factory=dict, repr=False, compare=False)
    checked: set[str] = field(default_factory=set, repr=False, compare=False)

    def file(self, name: str) -> Path:
        """The path of the entry's file `name`, its digest verified before the first use.

        Raises CorruptEntryError, after removing the entry, when the file no longer matches the manifest.
        """
        path = self.path / name
        if name not in self.checked:
            if not _matches(path, self.digests.get(name)):
                _remove(self.path)
                raise CorruptEntryError(
                    f"{path}: the cache entry's file changed since it was built; entry removed"
                )
            self.checked.add(name)
        return path


def _matches(path: Path, digest: str | None) -> bool:
    try:
        return digest is not None and _digest(path) == digest
    except OSError:
        return False


def _verified(folder: Path, key: str, load: Callable[[dict], Iterable[str]] | None = None) -> Entry | None:
    """The entry in `folder` when its manifest, its list of files and the digests of the files to load hold.

    load(meta) names the files whose digests are checked now (default: every file).
    """
    try:
        manifest = json.loads((folder / _MANIFEST).read_text(encoding="utf-8"))
        if manifest.get("key") != key or manifest.get("format") != FORMAT:
            return None
        files = manifest["files"]
        present = {p.name for p in folder.iterdir()} - {_MANIFEST}
        if set(files) != present:
            return None
        entry = Entry(folder, key, manifest["meta"], dict(files))
        names = files if load is None else [name for name in load(entry.meta) if name]
        if any(not _matches(folder / name, files.get(name)) for name in names):
            return None
        entry.checked.update(names)
        return entry
    except (OSError, ValueError, KeyError, TypeError, AttributeError, RecursionError):
        return None  # RecursionError: json's reader on a manifest of deeply nested brackets


def _remove(folder: Path) -> None:
    shutil.rmtree(folder, ignore_errors=True)


def lookup(key: str, load: Callable[[dict], Iterable[str]] | None = None) -> Entry | None:
    """The entry for `key` when it exists and verifies; a folder that does not verify is removed.

    load(meta): the names of the files the caller will load, from the entry's metadata; their
    digests are verified now, the other files' when Entry.file first gives them (default: all now).
    """
    folder = cache_dir() / _LAYOUT / key
    if not folder.is_dir():
        return None
    entry = _verified(folder, key, load)
    if entry is None:
        _remove(folder)
    return entry


def get_or_build(key: str, build: Callable[[Path], dict]) -> Entry:
    """The entry for `key`, built first when missing or corrupt.

    build(folder) writes the entry's files into `folder` and returns its metadata (JSON-ready).

    Raises:
        SymdynError: the cache folder cannot be written (its OSError, said in one line).
    """
    entry = lookup(key)
    if entry is not None:
        return entry
    try:
        return _build_entry(key, build)
    except OSError as e:
        raise SymdynError(
            f"the symdyn cache at {cache_dir()} cannot be written ({e.strerror or e}"
            f"{': ' + str(e.filename) if e.filename else ''}); make it writable, or point ${CACHE_ENV} "
            "to a writable folder"
        ) from None


def _staging_folders(layout: Path) -> list[Path]:
    try:
        return [p for p in layout.iterdir() if p.name.startswith(_STAGING) and p.is_dir()]
    except OSError:
        return []


def _build_entry(key: str, build: Callable[[Path], dict]) -> Entry:
    import tempfile

    layout = cache_dir() / _LAYOUT
    layout.mkdir(parents=True, exist_ok=True)
    sweep_folders(layout, _STAGING)
    staging = Path(tempfile.mkdtemp(prefix=f"{_STAGING}{os.getpid()}-", dir=layout))
    try:
        meta = build(staging)
        files = {p.name: _digest(p) for p in sorted(staging.iterdir())}
        manifest = {"key": key, "format": FORMAT, "symdyn": __version__, "files": files, "meta": meta}
        (staging / _MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True), encoding="utf-8")
        final = layout / key
        for _ in range(3):
            try:
                os.rename(staging, final)
                return Entry(final, key, meta, files, set(files))
            except OSError:  # another process published first, or a bad folder sits there
                entry = _verified(final, key)
                if entry is not None:
                    return entry
                _remove(final)
        raise OSError(f"{final}: cannot publish the cache entry")
    finally:
        _remove(staging)


def _folder_size(folder: Path) -> int:
    size = 0
    for dirpath, _, names in os.walk(folder):
        for name in names:
            with contextlib.suppress(OSError):  # removed meanwhile
                size += os.lstat(os.path.join(dirpath, name)).st_size
    return size


def usage() -> tuple[Path, int, int]:
    """(root folder, number of entries, total bytes of the entries) of the cache."""
    root = cache_dir()
    layout = root / _LAYOUT
    count = size = 0
    if layout.is_dir():
        for folder in layout.iterdir():
            if folder.is_dir() and not folder.name.startswith(_STAGING):
                count += 1
                size += _folder_size(folder)
    return root, count, size


def leftovers() -> tuple[int, int]:
    """(number, total bytes) of the staging folders in the cache: builds under way, or left by
    killed ones (removed by the next build once stale, and by `clear`)."""
    folders = _staging_folders(cache_dir() / _LAYOUT)
    return len(folders), sum(_folder_size(f) for f in folders)


def clear() -> int:
    """Remove every entry (and leftover staging folder); returns how many entries were removed.

    Only symdyn's own layout folder is touched, never other files under the root.

    Raises:
        SymdynError: the cache folder cannot be written.
    """
    layout = cache_dir() / _LAYOUT
    if not layout.is_dir():
        return 0
    count = sum(1 for f in layout.iterdir() if f.is_dir() and not f.name.startswith(_STAGING))
    try:
        shutil.rmtree(layout)
    except OSError as e:
        raise SymdynError(
            f"the symdyn cache at {cache_dir()} cannot be cleared ({e.strerror or e}"
            f"{': ' + str(e.filename) if e.filename else ''})"
        ) from None
    return count
