"""URDF mimic joints: q_follower = multiplier * q_master + offset, traced to an independent joint.

A joint with `<mimic joint="m" multiplier="k" offset="o"/>` (k default 1, o default 0)
has no coordinate of its own: q = k q_m + o.
Refused, naming the file, the child link of the joint whose <mimic> is wrong and the
field joint(NAME).mimic.joint: a master that does not exist, a master that is not a
revolute, continuous or prismatic joint, a master that is a mimic joint itself (a follows
b, b follows c: the message gives the composed relation with c to write instead, as
symdyn.parsers.mimic_chain computes it), and joints that follow each other in a cycle.
A <mimic> on a fixed joint is ignored (the joint does not move; Talos' grippers have them).
"""

from __future__ import annotations

import sympy as sp

from ..errors import SymdynError
from .mimic_chain import follow_mimics, number_text
from .source import did_you_mean
from .urdf_elements import UrdfJoint, UrdfReader

__all__ = ["resolve_mimic", "mimic_error"]


def mimic_error(reader: UrdfReader, joint: UrdfJoint, message: str) -> SymdynError:
    """An error about `joint`'s <mimic>, naming its child link, the field and the line."""
    return reader.error(
        message,
        link=reader.links[joint.child],
        field=f"joint({joint.name}).mimic.joint",
        line=joint.mimic_line,
    )


def resolve_mimic(reader: UrdfReader, joint: UrdfJoint) -> tuple[UrdfJoint, sp.Expr, sp.Expr] | None:
    """(independent master, multiplier, offset) with q_joint = multiplier * q_master + offset,
    or None for a joint that moves on its own (no <mimic>, or a fixed joint)."""

    def master_of(name: str) -> tuple[str, sp.Expr, sp.Expr] | None:
        j = reader.joints[name]
        if j.mimic is None or not j.movable:
            return None
        master = reader.joints.get(j.mimic[0])
        if master is None:
            hint = did_you_mean(j.mimic[0], reader.joints)
            raise mimic_error(reader, j, f"mimics joint '{j.mimic[0]}', which does not exist{hint}")
        if not master.movable:
            raise mimic_error(
                reader,
                j,
                f"mimics joint '{master.name}', which is a {master.type} joint: only a revolute, "
                "continuous or prismatic joint can be followed",
            )
        return j.mimic

    def cycle_error(name: str, cycle: list[str]) -> SymdynError:
        return mimic_error(
            reader, reader.joints[name], f"mimic joints follow each other in a cycle: {' -> '.join(cycle)}"
        )

    def chain_error(name: str, master: str, end: str, k: sp.Expr, o: sp.Expr) -> SymdynError:
        return mimic_error(
            reader,
            reader.joints[name],
            f"mimics joint '{master}', which is a mimic joint itself: follow '{end}' directly, "
            f'with <mimic joint="{end}" multiplier="{number_text(k)}" offset="{number_text(o)}"/>',
        )

    followed = follow_mimics(joint.name, master_of, cycle_error, chain_error)
    if followed is None:
        return None
    master, multiplier, offset = followed
    return reader.joints[master], multiplier, offset
