"""`symdyn cache`: where the cache is and how big (or --clear); and the applications' cached robot.

The applications (simulate, analyze) key their cache entry by the robot file's bytes and
the options that change the robot (--base, --tip, --floating, --params), so a second run of an
unchanged file finds its compiled library without parsing the file, deriving or importing SymPy
(symdyn.apps.compilation.compile.cached_dynamics). A URDF is read this way too when it needs no expansion:
the loader's own test (symdyn.parsers.xacro_expand.is_xacro) decides, so the xacro namespace that
exported URDFs declare does not count. MJCF and xacro files, whose robot depends on the files they
include (and on --xacro-arg), are loaded every time and compiled through symdyn.compile's cache,
keyed by the loaded robot.
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
    from ..apps.compilation.compile import cached_dynamics

    try:
        with open(args.robot, "rb") as fh:
            raw = fh.read()
    except OSError:
        return _uncached(make_robot)
    if _reads_other_files(raw, args.robot) or args.xacro_arg or args.package_dir:
        return _uncached(make_robot)
    digest = hashlib.sha256(raw).hexdigest()
    floating = bool(getattr(args, "floating", False))
    key = {"file": digest, "base": args.base, "tip": args.tip, "floating": floating, **options}
    return cached_dynamics(key, make_robot)


def _reads_other_files(raw: bytes, file: str) -> bool:
    """Whether the robot of these bytes depends on other files: an MJCF file (its includes and
    assets) or a URDF that xacro must expand, by the loader's own tests; a file that is not even
    well-formed XML goes to the loader too, for its message."""
    from ..errors import SymdynError
    from ..parsers.safe_xml import looks_like_xml, parse_xml
    from ..parsers.xacro_expand import is_xacro

    if not looks_like_xml(raw):
        return False
    try:
        root = parse_xml(raw, file)
    except SymdynError:
        return True
    return root.tag != "robot" or is_xacro(file, root)


def _uncached(make_robot):
    """The robot compiled through symdyn.compile's own cache (keyed by the loaded robot): for the
    loader's own error on a file that cannot be read, and for files whose robot depends on other
    files (MJCF and xacro includes), which the key of the file's bytes would miss."""
    from ..apps.compilation.compile import compile

    return compile(make_robot())


def _size(count: int) -> str:
    for unit in ("B", "kB", "MB", "GB"):
        if count < 1000 or unit == "GB":
            return f"{count:.0f} {unit}" if unit == "B" else f"{count:.1f} {unit}"
        count /= 1000
    raise AssertionError


def cmd_cache(args: argparse.Namespace) -> int:
    from ..apps.compilation import cache

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
