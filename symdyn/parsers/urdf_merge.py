"""Rigid parts merged into one body: the links a body carries, and their masses and inertias.

A body of the loaded robot is the child link of one of its joints together with
everything that moves rigidly with it: links joined by fixed joints and, when a
tip cuts one chain out of the tree, the side branches and whatever lies below the
tip, their movable joints locked (at 0, or a mimic joint at multiplier * 0 +
offset, its independent master locked at 0). `body_parts` collects them with
their frames in the body frame; `merge_inertials` adds their masses, averages
their centres of mass, rotates each inertia tensor into the body axes
(I' = R I R^T) and moves it to the common centre of mass by the parallel-axis
theorem (symdyn.model.inertia.rotate, parallel_axis). Links without <inertial>
are massless and add nothing.
"""

from __future__ import annotations

from collections.abc import Container

import sympy as sp

from ..model.inertia import parallel_axis, rotate
from ..spatial.transform import Transform, rot_axis
from .urdf_elements import UrdfInertial, UrdfJoint
from .urdf_mimic import mimic_error, resolve_mimic
from .urdf_tree import UrdfTree

__all__ = ["body_parts", "merge_inertials"]


def body_parts(tree: UrdfTree, start: str, bodies: Container[str]) -> list[tuple[str, Transform]]:
    """(link, body_T_link) of `start` and every link rigidly attached to it: the walk stops at the
    joints named in `bodies` (each starts a body of its own) and locks the other movable joints."""
    parts = []
    stack = [(start, Transform.identity())]
    while stack:
        name, T = stack.pop()
        parts.append((name, T))
        for j in reversed(tree.children[name]):
            if j.name not in bodies:
                stack.append((j.child, T @ _locked_transform(tree, j, bodies)))
    return parts


def _locked_transform(tree: UrdfTree, joint: UrdfJoint, bodies: Container[str]) -> Transform:
    """origin @ motion of a joint held at its locked position (a fixed joint: its origin)."""
    if joint.type in ("floating", "planar"):
        raise tree.reader.error(
            f"joint '{joint.name}' is {joint.type}: symdyn handles revolute, continuous, prismatic "
            "and fixed joints only (choose a base below it, or another tip)",
            link=tree.links[joint.child],
            field=f"joint({joint.name}).type",
            line=joint.line,
        )
    if joint.type == "fixed":
        return joint.origin
    value = sp.S.Zero
    followed = resolve_mimic(tree.reader, joint)
    if followed is not None:
        master, _, offset = followed
        if master.name in bodies:
            raise mimic_error(
                tree.reader,
                joint,
                f"mimic joint '{joint.name}' follows the chain joint '{master.name}', so it cannot be "
                "locked: load the whole tree (no tip) to let both move, or choose a tip whose chain "
                "includes neither",
            )
        value = offset  # multiplier * 0 + offset: the master is locked at 0 (or is not loaded)
    if joint.type == "prismatic":
        motion = Transform.from_translation(list(joint.axis * value))
    else:
        motion = Transform.from_rotation(rot_axis(list(joint.axis), value))
    return joint.origin @ motion


def merge_inertials(
    parts: list[tuple[UrdfInertial, Transform]],
) -> tuple[sp.Expr, sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Mass, centre of mass and inertia about it (body axes) of rigidly joined inertials."""
    items = []
    for inertial, T in parts:
        frame = T @ inertial.origin  # the inertial frame in the body frame
        tensor = inertial.tensor if sp.eye(3) == frame.R else rotate(inertial.tensor, frame.R)
        if inertial.mass == 0 and tensor == sp.zeros(3, 3):
            continue  # a massless frame adds nothing
        items.append((inertial.mass, frame.p, sp.ImmutableMatrix(tensor)))
    if not items:
        zero = sp.ImmutableMatrix(sp.zeros(3, 1))
        return sp.S.Zero, zero, sp.ImmutableMatrix(sp.zeros(3, 3))
    if len(items) == 1:
        return items[0]
    mass = sum((m for m, _, _ in items), sp.S.Zero)
    if mass == 0:
        com = sp.ImmutableMatrix(sp.zeros(3, 1))
    else:
        com = sp.ImmutableMatrix(sum((m * c for m, c, _ in items), sp.zeros(3, 1)) / mass)
    tensor = sp.zeros(3, 3)
    for m, c, inertia in items:
        tensor += parallel_axis(inertia, m, list(c - com))
    return mass, com, sp.ImmutableMatrix(tensor)
