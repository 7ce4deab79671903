"""URDF mimic joints: q_follower = multiplier * q_master + offset, traced to an independent joint.

A joint with `<mimic joint="m" multiplier="k" offset="o"/>` (k default 1, o default 0)
has no coordinate of its own: q = k q_m + o. When the master is itself a mimic joint
(a follows b, b follows c), the chain is composed into one relation with the
independent joint at its end:

    q_a = k_ab q_b + o_ab,  q_b = k_bc q_c + o_bc
    =>  q_a = (k_ab k_bc) q_c + (k_ab o_bc + o_ab)

(Pinocchio refuses such chains; the composition is exact, so symdyn accepts them.)
Refused, naming the file, the child link of the joint whose <mimic> is wrong and the
field joint(NAME).mimic.joint: a master that does not exist, a master that is not a
revolute, continuous or prismatic joint, and joints that follow each other in a cycle.
A <mimic> on a fixed joint is ignored (the joint does not move; Talos' grippers have them).
"""

from __future__ import annotations

import sympy as sp

from ..errors import SymdynError
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
    if joint.mimic is None or not joint.movable:
        return None
    multiplier, offset = sp.S.One, sp.S.Zero
    followed = [joint.name]
    current = joint
    while current.mimic is not None:
        name, k, o = current.mimic
        master = reader.joints.get(name)
        if master is None:
            hint = did_you_mean(name, reader.joints)
            raise mimic_error(reader, current, f"mimics joint '{name}', which does not exist{hint}")
        if master.name in followed:
            cycle = " -> ".join([*followed[followed.index(master.name) :], master.name])
            raise mimic_error(reader, current, f"mimic joints follow each other in a cycle: {cycle}")
        if not master.movable:
            raise mimic_error(
                reader,
                current,
                f"mimics joint '{name}', which is a {master.type} joint: only a revolute, continuous "
                "or prismatic joint can be followed",
            )
        # q_joint = multiplier q_current + offset and q_current = k q_master + o
        multiplier, offset = multiplier * k, multiplier * o + offset
        followed.append(master.name)
        current = master
    return current, multiplier, offset
