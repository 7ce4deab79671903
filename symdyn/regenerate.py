"""Rewrite generated/ from the example robots: `python -m symdyn.regenerate [--check]`.

Run from the repository root. generated/<robot>/ receives every target's
files for roger_arm, puma560 and panda. With --check nothing is written and
the exit status says whether generated/ is up to date (tests/test_generated.py
does the same comparison and shows the diff).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from .codegen import TARGETS, render
from .codegen.output import write_files
from .parsers import load_robot

__all__ = ["EXAMPLES", "render_all", "main"]

EXAMPLES = ("roger_arm", "puma560", "panda")
TOOLCHAIN_FILE = "TOOLCHAIN"


def toolchain() -> str:
    """The versions that byte-identical output depends on (SymPy's printing, CasADi's format)."""
    import casadi
    import sympy

    from . import __version__

    return f"symdyn {__version__}\nsympy {sympy.__version__}\ncasadi {casadi.__version__}\n"


def render_all(root: Path) -> dict[str, dict[str, str | bytes]]:
    """robot name -> {file name: content} for every example robot and target."""
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name in EXAMPLES:
            robot = load_robot(root / "examples" / f"{name}.yaml")
            out[name] = render(robot, targets=tuple(TARGETS))
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m symdyn.regenerate", description=__doc__)
    parser.add_argument("--root", default=".", help="repository root (default: current folder)")
    parser.add_argument("--check", action="store_true", help="compare only, write nothing")
    args = parser.parse_args(argv)
    root = Path(args.root)
    stale = []
    stamp = root / "generated" / TOOLCHAIN_FILE
    versions = toolchain()
    if not stamp.is_file() or stamp.read_text() != versions:
        stale.append(str(stamp))
        if not args.check:
            write_files(stamp.parent, {TOOLCHAIN_FILE: versions}, force=True)
    for name, files in render_all(root).items():
        folder = root / "generated" / name
        for fname, content in files.items():
            data = content.encode() if isinstance(content, str) else content
            path = folder / fname
            if not path.is_file() or path.read_bytes() != data:
                stale.append(str(path))
        if not args.check:
            write_files(folder, files, force=False)
    if args.check:
        print("\n".join(stale) if stale else "generated/ is up to date")
        return 1 if stale else 0
    print(f"rewrote generated/ ({len(stale)} files changed)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
