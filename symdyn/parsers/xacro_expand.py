"""xacro files expanded into URDF before the URDF loader reads them (docs/urdf.md, "xacro").

A file is a xacro file when its name ends in .xacro, or its <robot> holds a <xacro:...> element.
A declaration of the xacro namespace alone (xmlns:xacro, which many exported URDFs keep) does not
make one: such a file is read as the plain URDF it is. It is expanded by the `xacro`
package (the `xacro` extra) in a child process (symdyn.parsers.xacro_run) with the arguments
NAME:=VALUE given (`xacro_args`) and the package folders given (`package_dirs`, for
`$(find pkg)` and `package://pkg/` includes; then ROS_PACKAGE_PATH). A xacro file is a program:
the child is contained (symdyn.parsers.contained) so that it may compute and read files, nothing
else, for at most TIMEOUT seconds and MEMORY bytes. An error of xacro (an undefined argument or
property, a missing package or include, an act refused) is a SymdynError on one line naming the
file, and the line of the xacro source where the text it concerns can be found.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import os
import signal
import sys
from collections.abc import Mapping
from pathlib import Path

from ..errors import SymdynError
from . import contained
from .safe_xml import Element

__all__ = ["is_xacro", "expand_xacro", "xacro_options", "TIMEOUT", "MEMORY"]

#: seconds the expansion may take
TIMEOUT = contained.TIMEOUT
#: bytes of address space the expanding process may use
MEMORY = contained.MEMORY
_RUNNER = Path(__file__).with_name("xacro_run.py")


def is_xacro(file: str, root: Element) -> bool:
    """Whether the file is a xacro file (see the module documentation)."""
    if file.endswith(".xacro"):
        return True
    stack = [root]
    while stack:
        el = stack.pop()
        if el.tag.startswith("xacro:"):
            return True
        stack.extend(el.children)
    return False


def xacro_options(
    file: str, xacro_args: Mapping[str, str] | None, package_dirs: Mapping[str, str] | None
) -> tuple[dict[str, str], dict[str, str]]:
    """The xacro arguments and package folders, checked: names and values are strings, folders exist."""
    out = []
    for what, given in (("xacro argument", xacro_args), ("package folder", package_dirs)):
        checked = {}
        for name, value in (given or {}).items():
            if not isinstance(name, str) or not name or not isinstance(value, (str, os.PathLike)):
                raise SymdynError(f"{what} {name!r}={value!r}: name and value must be strings", file=file)
            checked[name] = os.fspath(value)
        out.append(checked)
    for name, folder in out[1].items():
        if not os.path.isdir(folder):
            raise SymdynError(f"package folder {name}={folder}: no such folder", file=file)
        out[1][name] = os.path.abspath(folder)
    return out[0], out[1]


def expand_xacro(
    file: str, xacro_args: Mapping[str, str] | None = None, package_dirs: Mapping[str, str] | None = None
) -> tuple[bytes, str]:
    """The URDF that xacro makes of `file`, as bytes, and their sha256 hex digest.

    Raises:
        SymdynError: the xacro package is missing (naming the extra), the expansion fails (xacro's
            message, naming the file and line), takes more than TIMEOUT s or MEMORY bytes.
    """
    args, packages = xacro_options(file, xacro_args, package_dirs)
    if importlib.util.find_spec("xacro") is None:
        raise SymdynError(
            "expanding a xacro file needs the Python package 'xacro', which is not installed: "
            "pip install 'symdyn[xacro]'",
            file=file,
        )
    request = {
        "file": os.path.abspath(file),
        "args": args,
        "packages": packages,
        "memory": MEMORY,
        "seconds": TIMEOUT,
    }
    done = contained.run([sys.executable, "-B", str(_RUNNER)], json.dumps(request).encode(), TIMEOUT)
    if done.timed_out or done.status in (-signal.SIGXCPU, -signal.SIGKILL):
        raise SymdynError(f"xacro did not finish expanding the file within {TIMEOUT} s", file=file)
    try:
        answer = json.loads(done.stdout)
    except ValueError:
        last = (done.stderr.decode("utf-8", "replace").strip().splitlines() or ["no output"])[-1]
        raise SymdynError(f"xacro failed: {last}", file=file) from None
    if "error" in answer:
        where = answer.get("file") or file
        where = file if os.path.abspath(where) == request["file"] else where
        line = f" (line {answer['line']})" if answer.get("line") else ""
        raise SymdynError(f"xacro: {answer['error']}{line}", file=where)
    urdf = answer["urdf"].encode("utf-8")
    return urdf, hashlib.sha256(urdf).hexdigest()
