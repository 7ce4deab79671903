"""The URDF tree: the walk from base to tip, the choice of the chain, and the merging of rigid parts.

`UrdfTree` holds the parent and child joints of every link and refuses graphs
that are not one tree (cycles, two parents, several roots). Its `path` is the
chain of joints from a base link down to a tip link; `default_tip` picks the
single leaf whose chain is not a prefix of another's.

Everything that moves rigidly with a chain body (links joined by fixed joints,
side branches and whatever lies below the tip, their joints locked at 0 or a
mimic joint's multiplier * 0 + offset) is merged into it by `merge_inertials`:
masses add, centres of mass average, and each inertia tensor is rotated into
the body axes (I' = R I R^T) and moved to the common centre of mass by the
parallel-axis theorem (symdyn.model.inertia.rotate, parallel_axis).
"""

from __future__ import annotations

import sympy as sp

from ..errors import SymdynError
from ..model.inertia import parallel_axis, rotate
from ..spatial.transform import Transform, rot_axis
from .source import did_you_mean
from .urdf_elements import MOVABLE, UrdfInertial, UrdfJoint, UrdfReader

__all__ = ["UrdfTree", "body_parts", "default_tip", "link_name", "merge_inertials"]


class UrdfTree:
    """Parent and child joints of every link; refuses graphs that are not one tree."""

    def __init__(self, reader: UrdfReader) -> None:
        self.reader = reader
        self.links = reader.links
        self.joints = reader.joints
        self.parent: dict[str, UrdfJoint] = {}
        self.children: dict[str, list[UrdfJoint]] = {name: [] for name in self.links}
        for j in self.joints.values():
            child = self.links[j.child]
            if j.parent == j.child:
                raise reader.error(
                    f"joint '{j.name}' joins link '{j.child}' to itself (a cycle)",
                    link=child,
                    field=f"joint({j.name}).child",
                    line=j.line,
                )
            if j.child in self.parent:
                other = self.parent[j.child]
                raise reader.error(
                    f"link '{j.child}' is the child of two joints, '{other.name}' (line {other.line}) "
                    f"and '{j.name}': a URDF is a tree, not a closed loop",
                    link=child,
                    field=f"joint({j.name}).child",
                    line=j.line,
                )
            self.parent[j.child] = j
            self.children[j.parent].append(j)
        self._check_tree()

    def _check_tree(self) -> None:
        roots = [name for name in self.links if name not in self.parent]
        reached: set[str] = set()
        stack = list(roots)
        while stack:
            name = stack.pop()
            reached.add(name)
            stack.extend(j.child for j in self.children[name])
        unreached = [name for name in self.links if name not in reached]
        if unreached:  # each link has at most one parent: what no root reaches lies on a cycle
            cycle = [unreached[0]]
            while True:
                nxt = self.parent[cycle[-1]].parent
                if nxt in cycle:
                    cycle = cycle[cycle.index(nxt) :] + [nxt]
                    break
                cycle.append(nxt)
            cycle.reverse()  # parent -> child order
            j = self.parent[cycle[1]]
            raise self.reader.error(
                "the joints form a cycle: " + " -> ".join(cycle) + " (a URDF is a tree)",
                link=self.links[cycle[1]],
                field=f"joint({j.name}).child",
                line=j.line,
            )
        if len(roots) > 1:
            raise self.reader.error(
                f"the links form {len(roots)} separate trees, with roots {', '.join(roots)}: "
                "a URDF has one root link (is a joint missing?)"
            )
        self.root = roots[0]

    def path(self, base: str, tip: str) -> list[UrdfJoint] | None:
        """The joints from base down to tip, or None if tip is not below base."""
        joints = []
        name = tip
        while name != base:
            if name not in self.parent:
                return None
            j = self.parent[name]
            joints.append(j)
            name = j.parent
        return joints[::-1]

    def leaves(self, base: str) -> list[str]:
        out, stack = [], [base]
        while stack:
            name = stack.pop()
            kids = self.children[name]
            if not kids and name != base:
                out.append(name)
            stack.extend(j.child for j in kids)
        return sorted(out, key=lambda name: self.links[name].index)  # file order


def link_name(reader: UrdfReader, name: str | None, what: str) -> str:
    if not isinstance(name, str) or name not in reader.links:
        raise SymdynError(
            f"{what} link {name!r} is not a link of the robot{did_you_mean(str(name), reader.links)}",
            file=reader.file,
        )
    return name


def default_tip(tree: UrdfTree, base: str) -> str:
    """The single leaf below base; leaves whose movable joints are a prefix of another's don't count."""
    leaves = tree.leaves(base)
    if not leaves:
        raise SymdynError(f"the base link '{base}' has no links below it", file=tree.reader.file)
    chains = {leaf: tuple(j.name for j in tree.path(base, leaf) if j.movable) for leaf in leaves}
    best: dict[tuple[str, ...], str] = {}
    for leaf in leaves:
        c = chains[leaf]
        if any(o != c and o[: len(c)] == c for o in chains.values()):
            continue  # hangs by fixed joints from a longer chain: merged or locked either way
        best.setdefault(c, leaf)
    if len(best) == 1:
        return next(iter(best.values()))
    candidates = list(best.values())
    common = _common_ancestor(tree, base, candidates)
    hint = f", or '{common}' to lock everything below it" if common else ""
    raise SymdynError(
        f"the tree below '{base}' has several leaf links ending different chains: "
        f"{', '.join(candidates)}; choose the tip (tip=... or --tip LINK){hint}",
        file=tree.reader.file,
    )


def _common_ancestor(tree: UrdfTree, base: str, leaves: list[str]) -> str | None:
    paths = [[base] + [j.child for j in tree.path(base, leaf)] for leaf in leaves]
    common = None
    for names in zip(*paths, strict=False):
        if len(set(names)) != 1:
            break
        common = names[0]
    return None if common == base else common


# --------------------------------------------------------------------------- merging


def _locked_transform(tree: UrdfTree, joint: UrdfJoint, chain: set[str]) -> Transform:
    """origin @ motion of an off-chain joint held at its locked position (0, or a mimic's offset)."""
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
    value = _locked_value(tree, joint, chain)
    if joint.type == "prismatic":
        motion = Transform.from_translation(list(joint.axis * value))
    else:
        motion = Transform.from_rotation(rot_axis(list(joint.axis), value))
    return joint.origin @ motion


def _locked_value(tree: UrdfTree, joint: UrdfJoint, chain: set[str], seen: tuple[str, ...] = ()) -> sp.Expr:
    """The position of a locked joint: 0, or multiplier * (its master's position) + offset."""
    if joint.mimic is None:
        return sp.S.Zero
    master_name, multiplier, offset = joint.mimic
    master = tree.joints.get(master_name)
    where = {
        "link": tree.links[joint.child],
        "field": f"joint({joint.name}).mimic.joint",
        "line": joint.mimic_line,
    }
    if master is None:
        raise tree.reader.error(
            f"mimics joint '{master_name}', which does not exist{did_you_mean(master_name, tree.joints)}",
            **where,
        )
    if master.name in chain:
        raise tree.reader.error(
            f"mimic joint '{joint.name}' follows the chain joint '{master.name}': symdyn does not "
            "couple joints (choose a tip whose chain includes neither, or lock both)",
            **where,
        )
    if master.name == joint.name or master.name in seen:
        raise tree.reader.error("mimic joints follow each other in a cycle", **where)
    if master.type not in MOVABLE:
        return offset
    return multiplier * _locked_value(tree, master, chain, (*seen, joint.name)) + offset


def body_parts(tree: UrdfTree, start: str, path: set[str], chain: set[str]) -> list[tuple[str, Transform]]:
    """(link, body_T_link) of every link rigidly attached to `start` once off-chain joints are locked."""
    parts = []
    stack = [(start, Transform.identity())]
    while stack:
        name, T = stack.pop()
        parts.append((name, T))
        for j in reversed(tree.children[name]):
            if j.name in path:
                if j.movable:
                    continue  # the next body of the chain
                stack.append((j.child, T @ j.origin))
            else:
                stack.append((j.child, T @ _locked_transform(tree, j, chain)))
    return parts


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
