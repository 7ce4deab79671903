"""`symdyn cache`: where the cache is and how big (or --clear); and the applications' cached robot.

The applications (simulate, analyze) key their cache entry by the robot file's bytes and
the options that change the robot (--base, --tip, --params), so a second run of an unchanged
file finds its compiled library without parsing the file, deriving or importing SymPy
(symdyn.apps.compile.cached_dynamics). MJCF and xacro files, whose robot depends on the files
they include (and on --xacro-arg), are loaded every time and compiled through symdyn.compile's
cache, keyed by the loaded robot.
"""

from __future__ import annotations

import argparse
import hashlib

__all__ = ["CACHE_HELP", "cache_arguments", "cmd_cache", "cached_plant"]


def cached_plant(args: argparse.Namespace, make_robot, **options):
    """The CompiledDynamics of the robot argument, from the cache when the file is unchanged.

    make_robot() loads the robot (with its options applied) on a cache miss; `options`
    (e.g. params={...}) are part of the key.
    """
    from ..apps.compile import cached_dynamics

    try:
        with open(args.robot, "rb") as fh:
            raw = fh.read()
    except OSError:
        return _uncached(make_robot)
    if b"<mujoco" in raw or b"xacro" in raw:  # MJCF and xacro read other files too (includes)
        return _uncached(make_robot)
    digest = hashlib.sha256(raw).hexdigest()
    key = {"file": digest, "base": args.base, "tip": args.tip, **options}
    return cached_dynamics(key, make_robot)


def _uncached(make_robot):
    """The robot compiled through symdyn.compile's own cache (keyed by the loaded robot): for the
    loader's own error on a file that cannot be read, and for files whose robot depends on other
    files (MJCF and xacro includes), which the key of the file's bytes would miss."""
    from ..apps.compile import compile

    return compile(make_robot())


def _size(count: int) -> str:
    for unit in ("B", "kB", "MB", "GB"):
        if count < 1000 or unit == "GB":
            return f"{count:.0f} {unit}" if unit == "B" else f"{count:.1f} {unit}"
        count /= 1000
    raise AssertionError


def cmd_cache(args: argparse.Namespace) -> int:
    from ..apps import cache

    if args.clear:
        removed = cache.clear()
        print(f"{cache.cache_dir()}: removed {removed} entr{'y' if removed == 1 else 'ies'}")
        return 0
    root, count, size = cache.usage()
    entries = f"{count} entr{'y' if count == 1 else 'ies'}"
    print(f"{root}: {entries}, {_size(size)} (relocate with ${cache.CACHE_ENV})")
    left, left_size = cache.leftovers()
    if left:
        print(
            f"{root}: {left} unfinished build folder{'' if left == 1 else 's'} (.build-*), "
            f"{_size(left_size)}: a build under way, or left by a killed one (the next build "
            "removes those of finished processes and any older than an hour; --clear removes them all)"
        )
    return 0


#: The one-line help of `symdyn cache` (symdyn --help).
CACHE_HELP = "show the cache of compiled robots (location, size) or clear it"


def cache_arguments(c: argparse.ArgumentParser) -> None:
    """The options of the subcommand `cache`."""
    c.description = (
        "symdyn caches each robot's generated code and compiled library, keyed by the robot's "
        "content, symdyn's version and the options. Without options: print the cache folder, its entries "
        "and size. The folder is $SYMDYN_CACHE_DIR, else the user's cache folder (~/.cache/symdyn on Linux)."
    )
    c.add_argument("--clear", action="store_true", help="remove every cache entry")
    c.set_defaults(func=cmd_cache)
