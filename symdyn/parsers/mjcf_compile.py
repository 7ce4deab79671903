"""An MJCF file compiled by MuJoCo itself (the `mujoco` package, the `mjcf` extra), and the names
of its compiled model.

MuJoCo's compiler resolves everything the format lets a file say indirectly: <default> classes
and childclass, <include>, angle="degree", euler sequences, quat/axisangle/xyaxes/zaxis
orientations, fullinertia/diaginertia with quat, inertia computed from geoms. symdyn reads the
compiled model (mujoco.MjModel) rather than the XML, so that it sees what MuJoCo simulates.
A file MuJoCo rejects (a missing include, an unknown attribute, a missing mesh) is a SymdynError
with MuJoCo's own message (the element and its line) on one line; MuJoCo's warnings, which it
would print itself, become SymdynWarnings naming the file.
"""

from __future__ import annotations

import math
import os
import signal
import sys
import warnings
from typing import Any

import numpy as np

from ..errors import SymdynError, SymdynWarning
from ..model.bounded import MAX_MAGNITUDE
from . import contained
from .optional import optional_module
from .safe_xml import Element, parse_xml
from .source import check_link_count

__all__ = ["check_numbers", "compile_mjcf", "model_name", "mujoco_module", "names"]

#: the arrays of the compiled model that symdyn reads, by the kind of object they describe
_ARRAYS = {
    "body": ("pos", "quat", "ipos", "iquat", "mass", "inertia"),
    "jnt": ("pos", "axis", "range"),
    "site": ("pos", "quat"),
    "tendon": ("armature", "damping", "frictionloss", "stiffness"),
}
_DOF_ARRAYS = ("armature", "damping", "frictionloss")
#: seconds and bytes of address space MuJoCo's compiler may use on one file
TIMEOUT = contained.TIMEOUT
MEMORY = contained.MEMORY
#: the server child that compiles MJCF files in contained children (symdyn.parsers.mjcf_run)
_SERVER = contained.Server(
    [sys.executable, "-B", os.path.join(os.path.dirname(__file__), "mjcf_run.py")],
    env={**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"},  # one thread: safe to fork
)
#: the fields that are magnitudes (>= 0), as in a URDF's <dynamics> and a robot file's friction
_NONNEGATIVE = {"jnt": _DOF_ARRAYS, "tendon": _ARRAYS["tendon"]}
#: the words of messages for each kind of object
_NOUNS = {"body": "body", "jnt": "joint", "site": "site", "tendon": "tendon"}


def mujoco_module(file: str | None = None) -> Any:
    """The `mujoco` package, or SymdynError naming the `mjcf` extra."""
    return optional_module("mujoco", "mjcf", "reading an MJCF (MuJoCo) file", file)


def compile_mjcf(raw: bytes, file: str, said: list[str] | None = None) -> Any:
    """The mujoco.MjModel of the MJCF file `file` (whose bytes are `raw`).

    MuJoCo's warnings become SymdynWarnings naming the file, now, or with `said` given, are
    appended to it for the caller to warn with once its own checks of the model have passed (a
    file refused for a negative armature then prints its one line, not also the singular M that
    MuJoCo saw).

    The bytes are first read by symdyn's hardened XML parser (a DOCTYPE, and so any entity, is
    refused) and must have the top element <mujoco>; MuJoCo then compiles the file from its path,
    so that <include file=...> and asset paths resolve next to it, in a contained child process
    (symdyn.parsers.mjcf_run) of at most MEMORY bytes and TIMEOUT s, which hands the model back
    as MJB bytes.
    """
    root = parse_xml(raw, file)
    if root.tag != "mujoco":
        raise SymdynError(f"not an MJCF file: its top element is <{root.tag}>, not <mujoco>", file=file)
    check_link_count(_count_tags(root, "body"), "bodies", file)  # before MuJoCo compiles them
    mujoco = mujoco_module(file)
    answer, mjb = _SERVER.request({"file": os.path.abspath(file)}, TIMEOUT, MEMORY)
    texts = [f"{file}: MuJoCo: {_one_line(text)}" for text in dict.fromkeys(answer.get("warnings", []))]
    if said is not None:
        said += texts
    for text in texts if said is None else ():
        warnings.warn(text, SymdynWarning, stacklevel=4)
    if "error" in answer and "bad_alloc" not in answer["error"]:
        raise SymdynError(f"MuJoCo's compiler refused it: {_one_line(answer['error'])}", file=file)
    if not mjb or answer.get("status"):
        raise SymdynError(_failure(answer), file=file)
    return mujoco.MjModel.from_binary_path("model.mjb", {"model.mjb": mjb})


def _failure(answer: dict) -> str:
    """Why the contained compiler gave no model: out of time, out of memory, or a crash."""
    status = int(answer.get("status", 0))
    killed = os.WIFSIGNALED(status) and os.WTERMSIG(status) in (signal.SIGXCPU, signal.SIGKILL)
    if answer.get("timed_out") or killed:
        return f"MuJoCo's compiler needed more than {TIMEOUT} s"
    signalled = os.WIFSIGNALED(status) and os.WTERMSIG(status) != signal.SIGXCPU
    if answer.get("memory") or "bad_alloc" in answer.get("error", "") or not signalled:
        return f"MuJoCo's compiler needed more than {MEMORY / 2**30:g} GiB of memory"
    return f"MuJoCo's compiler crashed (signal {os.WTERMSIG(status)})"


def _count_tags(root: Element, tag: str) -> int:
    """How many elements with the tag `tag` the file makes below `root`: each counted as many
    times as the <replicate count=N> elements around it repeat it (iterative: bodies nest
    deeply). A count that is not a whole number counts once: MuJoCo's compiler names it."""
    count, stack = 0, [(root, 1)]
    while stack:
        el, times = stack.pop()
        count += times * (el.tag == tag)
        if el.tag == "replicate":
            text = el.attrib.get("count", "1").strip()
            times *= int(text) if text.isdigit() else 1
        stack.extend((child, times) for child in el.children)
    return count


def _one_line(text: str) -> str:
    return "; ".join(line.strip() for line in text.splitlines() if line.strip())


def names(model: Any, kind: str, count: int, default: str) -> list[str]:
    """The names of the model's objects of `kind` ("body", "jnt", "site"): names[i] of object i,
    f"{default}{i}" for an unnamed one."""
    raw = bytes(model.names)
    addresses = getattr(model, f"name_{kind}adr")
    out = []
    for i in range(count):
        start = int(addresses[i])
        name = raw[start : raw.index(b"\0", start)].decode("utf-8", "replace")
        out.append(name or f"{default}{i}")
    return out


def model_name(model: Any) -> str:
    """The <mujoco model="..."> name ('MuJoCo Model' when the file gives none)."""
    raw = bytes(model.names)
    return raw[: raw.index(b"\0")].decode("utf-8", "replace")


def check_numbers(model: Any, file: str) -> None:
    """Every number symdyn reads from the compiled model is finite and at most MAX_MAGNITUDE =
    1e150 in absolute value, as in a URDF; a joint's or tendon's armature, damping, frictionloss
    and stiffness are not negative (MuJoCo accepts -1), with the URDF loader's message.
    SymdynError naming the body, joint, site or tendon and the field.
    """
    labels = {
        kind: names(model, kind, len(getattr(model, f"{kind}_{_ARRAYS[kind][0]}")), _NOUNS[kind])
        for kind in _ARRAYS
    }
    checks = [
        (f"{_NOUNS[kind]} '{labels[kind][i]}'", f, getattr(model, f"{kind}_{f}")[i])
        for kind in _ARRAYS
        for f in _ARRAYS[kind]
        for i in range(len(getattr(model, f"{kind}_{f}")))
    ]
    dofs = [
        ("jnt", labels["jnt"][int(model.dof_jntid[d])], f, getattr(model, f"dof_{f}")[d])
        for f in _DOF_ARRAYS
        for d in range(model.nv)
    ]
    checks += [(f"joint '{name}'", f, x) for _, name, f, x in dofs]
    checks += [("option", "gravity", model.opt.gravity), ("model", "qpos0", model.qpos0)]
    for what, fld, values in checks:
        for x in np.atleast_1d(values):
            if not (math.isfinite(float(x)) and abs(float(x)) <= MAX_MAGNITUDE):
                raise SymdynError(
                    f"{what}: {fld} {float(x)!r} is not a finite number of at most {MAX_MAGNITUDE:g} "
                    "in absolute value",
                    file=file,
                )
    tendons = [
        ("tendon", labels["tendon"][t], f, getattr(model, f"tendon_{f}")[t])
        for f in _NONNEGATIVE["tendon"]
        for t in range(model.ntendon)
    ]
    for kind, name, fld, x in dofs + tendons:
        if float(x) < 0:
            noun = _NOUNS[kind]
            raise SymdynError(
                f"must not be negative (got {float(x):g})", file=file, field=f"{noun}({name}).{fld}"
            )
