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
import warnings
from typing import Any

import numpy as np

from ..errors import SymdynError, SymdynWarning
from ..model.bounded import MAX_MAGNITUDE
from .optional import optional_module
from .safe_xml import Element, parse_xml
from .source import check_link_count

__all__ = ["check_numbers", "compile_mjcf", "model_name", "mujoco_module", "names"]

#: the arrays of the compiled model that symdyn reads, by the kind of object they describe
_ARRAYS = {
    "body": ("pos", "quat", "ipos", "iquat", "mass", "inertia"),
    "jnt": ("pos", "axis", "range"),
    "site": ("pos", "quat"),
}
_DOF_ARRAYS = ("armature", "damping", "frictionloss")


def mujoco_module(file: str | None = None) -> Any:
    """The `mujoco` package, or SymdynError naming the `mjcf` extra."""
    return optional_module("mujoco", "mjcf", "reading an MJCF (MuJoCo) file", file)


def compile_mjcf(raw: bytes, file: str) -> Any:
    """The mujoco.MjModel of the MJCF file `file` (whose bytes are `raw`).

    The bytes are first read by symdyn's hardened XML parser (a DOCTYPE, and so any entity, is
    refused) and must have the top element <mujoco>; MuJoCo then compiles the file from its path,
    so that <include file=...> and asset paths resolve next to it.
    """
    root = parse_xml(raw, file)
    if root.tag != "mujoco":
        raise SymdynError(f"not an MJCF file: its top element is <{root.tag}>, not <mujoco>", file=file)
    check_link_count(_count_tags(root, "body"), "<body> elements", file)  # before MuJoCo compiles them
    mujoco = mujoco_module(file)
    said: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(said.append)  # MuJoCo would print its warnings itself
    try:
        return mujoco.MjModel.from_xml_path(file)
    except ValueError as exc:
        raise SymdynError(f"MuJoCo's compiler refused it: {_one_line(str(exc))}", file=file) from None
    finally:
        mujoco.set_mju_user_warning(previous)
        for text in dict.fromkeys(said):
            warnings.warn(f"{file}: MuJoCo: {_one_line(text)}", SymdynWarning, stacklevel=4)


def _count_tags(root: Element, tag: str) -> int:
    """How many elements below `root` have the tag `tag` (iterative: bodies nest deeply)."""
    count, stack = 0, [root]
    while stack:
        el = stack.pop()
        count += el.tag == tag
        stack.extend(el.children)
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
    1e150 in absolute value, as in a URDF; SymdynError naming the body, joint or site and the field.
    """
    labels = {
        kind: names(model, kind, len(getattr(model, f"{kind}_{_ARRAYS[kind][0]}")), kind) for kind in _ARRAYS
    }
    checks = [
        (f"{kind} '{labels[kind][i]}'", f, getattr(model, f"{kind}_{f}")[i])
        for kind in _ARRAYS
        for f in _ARRAYS[kind]
        for i in range(len(getattr(model, f"{kind}_{f}")))
    ]
    checks += [
        (f"joint '{labels['jnt'][int(model.dof_jntid[d])]}'", f, getattr(model, f"dof_{f}")[d])
        for f in _DOF_ARRAYS
        for d in range(model.nv)
    ]
    checks += [("option", "gravity", model.opt.gravity), ("model", "qpos0", model.qpos0)]
    for what, fld, values in checks:
        for x in np.atleast_1d(values):
            if not (math.isfinite(float(x)) and abs(float(x)) <= MAX_MAGNITUDE):
                raise SymdynError(
                    f"{what}: {fld} {float(x)!r} is not a finite number of at most {MAX_MAGNITUDE:g} "
                    "in absolute value",
                    file=file,
                )
