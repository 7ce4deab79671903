"""Expand one xacro file with the `xacro` package, in a child process of symdyn (run as a script).

symdyn.parsers.xacro_expand starts `python xacro_run.py` with a JSON request on stdin:
{"file": path, "args": {name: value}, "packages": {name: folder}, "memory": bytes, "seconds": s},
and reads one JSON answer on stdout: {"urdf": text} or {"error": message, "file": path, "line": n}.
A xacro file is a program (its ${...} are Python expressions, and xacro's restricted namespace
does not stop one from reaching os.system through Python's object graph), so this child confines
itself (symdyn.parsers.contained: rlimits, a seccomp filter, an audit hook) before it imports
xacro: it may compute and read files, nothing else. An act refused is the answer "xacro tried to
run a process (os.system): a xacro file may only compute", whatever the expression made of it.

`$(find pkg)` and `package://pkg/...` in include file names resolve through the request's
packages, then the folders of ROS_PACKAGE_PATH (a folder named pkg in one of them, or one of
them named pkg); an unknown package is an error naming it. This file imports the standard
library, xacro and its sibling contained.py only, so that it runs without symdyn on the path.
"""

from __future__ import annotations

import errno
import importlib
import json
import os
import re
import sys
from xml.sax.saxutils import escape

#: the modules xacro imports while it works (not when it is imported), imported before confining
_PRELOAD = ("yaml", "xml.dom.minidom", "xml.dom.expatbuilder", "xml.dom.xmlbuilder", "xml.parsers.expat",
            "ast", "glob", "copy", "math", "collections", "enum", "textwrap", "optparse", "io")  # fmt: skip
_MEMORY = "xacro needed more than {:g} GiB of memory"
_KERNEL = "xacro tried a system call that symdyn's sandbox refused (EPERM): a xacro file may only compute"


class PackageNotFoundError(Exception):
    """A $(find pkg) or package://pkg that no --package-dir and no ROS_PACKAGE_PATH folder gives."""

    def __init__(self, name: str) -> None:
        super().__init__(
            f"package '{name}' not found: give its folder with --package-dir {name}=DIR "
            "(package_dirs= in Python) or add the folder that holds it to ROS_PACKAGE_PATH"
        )
        self.name = name


def find_package(name: str, packages: dict[str, str]) -> str:
    """The folder of package `name`: the request's, else one found along ROS_PACKAGE_PATH."""
    if name in packages:
        return packages[name]
    for root in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if not root:
            continue
        root = os.path.abspath(root)
        if os.path.basename(os.path.normpath(root)) == name and os.path.isdir(root):
            return root
        if os.path.isdir(os.path.join(root, name)):
            return os.path.join(root, name)
    raise PackageNotFoundError(name)


def _line_of(file: str | None, needles: list[str]) -> int | None:
    """The line of `file` where xacro met the problem: the first line that holds the first of
    `needles` (the most precise first) found in the file."""
    if not file or not needles:
        return None
    try:
        with open(file, encoding="utf-8", errors="replace") as fh:
            lines = fh.read().splitlines()
    except OSError:
        return None
    for needle in needles:
        for form in dict.fromkeys((needle, escape(needle, {'"': "&quot;"}))):  # as written in XML too
            for number, text in enumerate(lines, start=1):
                if form and form in text:
                    return number
    return None


def _needles(exc: BaseException) -> list[str]:
    """Text of the file that the error is about: the expression, argument or package it names."""
    if isinstance(exc, PackageNotFoundError):
        return [f"$(find {exc.name})", f"package://{exc.name}/"]
    text = str(exc)
    undefined = _undefined_argument(text)
    if undefined:  # the argument is on the line, the expression around it may be elsewhere too
        return [f"$(arg {undefined})"]
    expressions = re.findall(r"when evaluating expression '(.*)' *$", text, re.M)
    out = ["${" + e + "}" for e in expressions] + expressions
    out += re.findall(r"name '(\w+)' is not defined", text)
    out += re.findall(r"unknown macro name: (\S+)", text)
    return out


def _undefined_argument(text: str) -> str | None:
    """The name of the argument in xacro's "Undefined substitution argument NAME" message."""
    found = re.match(r"Undefined substitution argument ([^\s;]+)", text)
    return found.group(1) if found else None


def _caused_by(exc: BaseException | None, kind: type[BaseException]) -> BaseException | None:
    """The error of type `kind` in `exc` or what it wraps (xacro's .exc, the cause, the context)."""
    for _ in range(10):
        if exc is None or isinstance(exc, kind):
            return exc
        exc = getattr(exc, "exc", None) or exc.__cause__ or exc.__context__
    return None


def _one_line(text: str) -> str:
    return "; ".join(part.strip() for part in text.splitlines() if part.strip())


def expand(request: dict) -> dict:
    """The answer to one request (see the module documentation)."""
    import xacro
    import xacro.substitution_args as substitution_args

    packages = request.get("packages", {})
    substitution_args._eval_find = lambda name: find_package(name, packages)
    plain = xacro.abs_filename_spec

    def filename_spec(spec: str) -> str:
        if spec.startswith("package://"):
            name, _, rest = spec[len("package://") :].partition("/")
            return os.path.join(find_package(name, packages), rest)
        return plain(spec)

    xacro.abs_filename_spec = filename_spec
    file = request["file"]
    try:
        doc = xacro.process_file(file, mappings=dict(request.get("args", {})))
        return {"urdf": doc.toxml()}
    except PackageNotFoundError as exc:
        current = xacro.filestack[-1] if xacro.filestack else file
        return {"error": str(exc), "file": current, "line": _line_of(current, _needles(exc))}
    except Exception as exc:  # xacro's own errors (XacroException and what it lets through)
        current = xacro.filestack[-1] if xacro.filestack else file
        cause = getattr(exc, "exc", None)
        if isinstance(cause, PackageNotFoundError):
            return {"error": str(cause), "file": current, "line": _line_of(current, _needles(cause))}
        line = _line_of(current, _needles(exc))
        if _caused_by(exc, MemoryError):
            return {"error": _MEMORY.format(request.get("memory", 0) / 2**30), "file": current, "line": line}
        denied = _caused_by(exc, PermissionError)
        if denied is not None and denied.errno == errno.EPERM:  # the kernel's seccomp filter said no
            return {"error": _KERNEL, "file": current, "line": line}
        message = re.sub(r" \[Errno \d+\].*", "", _one_line(str(exc))) or type(exc).__name__
        name = _undefined_argument(str(exc))
        if name:
            message = f"undefined argument '{name}': give it with --xacro-arg {name}:=VALUE (xacro_args=)"
        return {"error": message, "file": current, "line": line}


def main() -> None:
    request = json.loads(sys.stdin.read())
    import contained  # this file's sibling (the script's folder is on sys.path)

    for name in _PRELOAD:  # what xacro imports on the way, loaded before imports are closed
        importlib.import_module(name)
    close_imports = contained.confine(int(request["memory"]), float(request["seconds"]), threads=False)
    import xacro  # noqa: F401 - imported under the audit hook, then imports are closed
    import xacro.substitution_args  # noqa: F401

    close_imports()
    try:
        answer = expand(request)
    except MemoryError:
        answer = {"error": _MEMORY.format(request["memory"] / 2**30), "file": request["file"], "line": None}
    tried = contained.refused()
    if tried:
        answer = {
            "error": f"xacro tried {tried}: a xacro file may only compute",
            "file": answer.get("file", request["file"]),
            "line": answer.get("line"),
        }
    sys.stdout.write(json.dumps(answer))


if __name__ == "__main__":
    main()
