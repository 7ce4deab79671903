"""The URDF tree: its joints depth first, the body each joint hangs from, the walk from a base to a tip.

`UrdfTree` holds the parent and child joints of every link and refuses graphs
that are not one tree (cycles, two parents, several roots). `depth_first` lists
the joints below a base in the order the whole-tree load numbers them: depth
first, the child joints of each link in the order of their names (urdfdom keeps
a link's children sorted by joint name, so this is the order of Pinocchio and
the other urdfdom-based loaders, not the order of the file). `carrier` finds the
body a movable joint hangs from, and `path` is the chain of joints from a base
link down to a tip link (what a tip cuts out of the tree).
"""

from __future__ import annotations

from collections.abc import Container

from ..errors import SymdynError
from ..spatial.transform import Transform
from .source import did_you_mean
from .urdf_elements import UrdfJoint, UrdfReader

__all__ = ["UrdfTree", "link_name"]


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

    def depth_first(self, base: str) -> list[UrdfJoint]:
        """Every joint below `base`, each before the joints below it; siblings in order of joint name."""
        out: list[UrdfJoint] = []
        stack = sorted(self.children[base], key=_name, reverse=True)
        while stack:
            j = stack.pop()
            out.append(j)
            stack.extend(sorted(self.children[j.child], key=_name, reverse=True))
        return out

    def carrier(
        self, joint: UrdfJoint, bodies: Container[str], base: str
    ) -> tuple[UrdfJoint | None, Transform]:
        """The nearest joint above `joint` whose name is in `bodies` (None: the base), and the
        product of the origins of the joints in between: the frame of `joint`'s parent link in the
        body frame of that joint's child link (or in the base link's frame)."""
        between: list[UrdfJoint] = []
        found = None
        name = joint.parent
        while name != base:
            above = self.parent[name]
            if above.name in bodies:
                found = above
                break
            assert above.type == "fixed", f"joint {above.name} lies between two bodies"
            between.append(above)
            name = above.parent
        T = Transform.identity()
        for j in reversed(between):  # from the body down, as the chain is walked
            T = T @ j.origin
        return found, T

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


def link_name(reader: UrdfReader, name: str | None, what: str) -> str:
    if not isinstance(name, str) or name not in reader.links:
        raise SymdynError(
            f"{what} link {name!r} is not a link of the robot{did_you_mean(str(name), reader.links)}",
            file=reader.file,
        )
    return name


def _name(joint: UrdfJoint) -> str:
    return joint.name
