"""Expand one xacro file with the `xacro` package, in a child process of symdyn (run as a script).

symdyn.parsers.xacro_expand starts `python xacro_run.py` with a JSON request on stdin:
{"file": path, "args": {name: value}, "packages": {name: folder}, "memory": bytes}, and reads
one JSON answer on stdout: {"urdf": text} or {"error": message, "file": path, "line": n}.
A child process bounds what the expansion may cost (xacro evaluates the ${...} expressions of
the file in its restricted Python namespace: the parent kills a child that runs too long, and
the child's address space is capped) and keeps xacro's global state out of symdyn's process.

`$(find pkg)` and `package://pkg/...` in include file names resolve through the request's
packages, then the folders of ROS_PACKAGE_PATH (a folder named pkg in one of them, or one of
them named pkg); an unknown package is an error naming it. This file imports the standard
library and xacro only, so that it runs without symdyn on the path.
"""

from __future__ import annotations

import json
import os
import re
import sys


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
    """The first line of `file` that holds one of `needles` (where xacro met the problem)."""
    if not file or not needles:
        return None
    try:
        with open(file, encoding="utf-8", errors="replace") as fh:
            for number, text in enumerate(fh, start=1):
                if any(n and n in text for n in needles):
                    return number
    except OSError:
        return None
    return None


def _needles(exc: BaseException) -> list[str]:
    """Text of the file that the error is about: the expression, argument or package it names."""
    if isinstance(exc, PackageNotFoundError):
        return [f"$(find {exc.name})", f"package://{exc.name}/"]
    text = str(exc)
    out = re.findall(r"when evaluating expression '(.*)'", text)
    out += [f"$(arg {n})" for n in re.findall(r"^Undefined substitution argument (\S+)", text)]
    out += re.findall(r"name '(\w+)' is not defined", text)
    out += re.findall(r"unknown macro name: (\S+)", text)
    return out


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
        message = re.sub(r" \[Errno \d+\].*", "", _one_line(str(exc))) or type(exc).__name__
        undefined = re.match(r"Undefined substitution argument (\S+)", message)
        if undefined:
            name = undefined.group(1)
            message = f"undefined argument '{name}': give it with --xacro-arg {name}:=VALUE (xacro_args=)"
        return {"error": message, "file": current, "line": _line_of(current, _needles(exc))}


def main() -> None:
    request = json.loads(sys.stdin.read())
    memory = int(request.get("memory", 0))
    try:
        import resource  # POSIX only: elsewhere the time limit alone bounds the expansion
    except ImportError:
        resource = None
    if memory and resource is not None:
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    try:
        answer = expand(request)
    except MemoryError:
        answer = {"error": "the expansion ran out of memory", "file": request["file"], "line": None}
    sys.stdout.write(json.dumps(answer))


if __name__ == "__main__":
    main()
