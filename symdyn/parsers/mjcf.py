"""MJCF (MuJoCo XML) -> `symdyn.model.robot.Robot`, read as MuJoCo compiles it (docs/mjcf.md).

The file is compiled by MuJoCo (symdyn.parsers.mjcf_compile) and the compiled model's arrays are
walked, body by body (MuJoCo numbers a parent before its children):

* a hinge joint becomes a revolute link, a slide joint a prismatic one, named after the body.
  symdyn rotates a link about the origin of its body frame, MuJoCo about the joint's anchor
  (jnt_pos, in the body frame): the link's body frame is MuJoCo's body frame moved to the
  anchor (same axes), so its centre of mass is ipos - anchor; `Link.frame` gives MuJoCo's body
  frame back. The axis is jnt_axis. A joint's ref (qpos0) is folded into the placement, so that
  q is MuJoCo's qpos;
* a body with several joints becomes a chain of links, one per joint in MuJoCo's order (each
  joint moves the body frame the earlier ones moved): the links of the first joints are massless
  and named after their joint, the last carries the body's mass and its name;
* a body without joints is welded to its parent: it is merged into the parent's link (masses
  add, inertias move to the common centre of mass: symdyn.parsers.urdf_merge) and keeps its
  frame under its name (`Robot.frames`); bodies welded to the world are the ground;
* sites are frames on the link of their body, named after the site, or 'site:NAME' when a body
  (or a link named after a joint) has the site's name (MuJoCo keeps the two kinds of names apart);
* armature becomes the rotor inertia (gear ratio 1: M gains the armature on its diagonal, as in
  MuJoCo), damping the viscous friction and frictionloss the Coulomb friction c sign(qd) (MuJoCo
  enforces it as a constraint instead: the same force while the joint slides);
* gravity is <option gravity> (zero when the flag gravity is disabled; disabling the damper or
  frictionloss flags drops those terms too); a joint's range is the link's limits when the
  joint is limited;
* a fixed tendon over one joint adds its armature, damping and frictionloss to that joint's; a
  fixed tendon over several joints, a tendon's spring and a joint's spring (stiffness about
  springref) become `Robot.tendons` (symdyn.parsers.mjcf_tendons, which also says what is
  refused and warned about).

A free joint on a root body (a body whose parent is the world) makes the robot floating, always
(MuJoCo simulates it so; floating=True asks for it and refuses a file without one): that body is
the floating base (its inertial is `Robot.base_body`, its frame the base frame) joined to the world
by symdyn's free flyer, whose coordinates are Pinocchio's (symdyn.model.free_flyer), not MuJoCo's
(qpos [x y z qw qx qy qz], qvel with the linear velocity in the world frame); the other bodies
welded to the world are the scenery and are left out.

Refused, naming the file, body and joint: ball joints; a free joint below the root, or more than
one; a floating model with joints outside the floating body's tree.
Refused too: a negative armature, damping or frictionloss (as in a URDF), and a number written
in the file that is not finite or a direction MuJoCo cannot normalise (symdyn.parsers.mjcf_attributes:
MuJoCo reads nan as 0, which the compiled model no longer shows).
Warned about and ignored: gravity compensation, equality constraints, spatial tendons' passive
forces, fluid forces, and tendons and springs on a floating base, which symdyn does not model.
Every number is a compiled double (symdyn.parsers.mjcf_values: rotations snapped to exact
multiples of pi/2 within 1e-9 rad).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field
from typing import Any

import sympy as sp

from ..errors import SymdynError, SymdynWarning
from ..model.contacts import with_contacts
from ..model.frames import Frame
from ..model.inertia import check_inertia
from ..model.robot import BaseBody, Friction, Link, Motor, Robot
from ..model.tendons import Tendon
from ..spatial.transform import Transform, rot_axis
from .mjcf_attributes import check_attributes
from .mjcf_compile import check_numbers, compile_mjcf, model_name, mujoco_module, names
from .mjcf_tendons import Coupling, TendonTerms, tendon_terms
from .mjcf_values import number, pose, vector
from .source import check_link_count, read_source
from .urdf_elements import UrdfInertial, numeric, urdf_robot_name
from .urdf_merge import merge_inertials

__all__ = ["load_mjcf", "mjcf_from_bytes"]

_FREE, _BALL, _SLIDE, _HINGE = 0, 1, 2, 3
_OUTSIDE = -2


@dataclass
class _Walk:
    """What the walk has built: the links (fields for Link), the frames, and where each body sits."""

    file: str
    model: Any
    links: list[dict] = field(default_factory=list)
    parts: list[list[tuple[UrdfInertial, Transform]]] = field(default_factory=list)
    frames: list[Frame] = field(default_factory=list)
    #: per body: (link index or -1, the MuJoCo body frame in that link's body frame); _OUTSIDE:
    #: a body outside a floating robot (the scenery)
    owner: list[tuple[int, Transform]] = field(default_factory=list)
    #: the body of the free joint (the floating base), or None
    free_body: int | None = None
    #: the inertials of the floating base's body, in its frame
    base_parts: list[tuple[UrdfInertial, Transform]] = field(default_factory=list)
    #: what the fixed tendons add to each dof (symdyn.parsers.mjcf_tendons)
    tendons: TendonTerms = field(default_factory=TendonTerms)
    #: the link of each dof (MuJoCo's dof index -> index into links)
    dof_link: dict[int, int] = field(default_factory=dict)


def load_mjcf(path: str | os.PathLike, floating: bool = False, contacts: object = None) -> Robot:
    """Read an MJCF (MuJoCo XML) file and return its robot on a fixed base.

    The file is compiled by MuJoCo (the `mujoco` package: pip install 'symdyn[mjcf]') and read
    from the compiled model (see the module documentation and docs/mjcf.md). Raises SymdynError
    naming the file (and the body and joint) for bad input, with MuJoCo's message for a file its
    compiler rejects; warns with SymdynWarning for what is ignored and for implausible inertias.
    `symdyn.load_robot` reads MJCF too (it recognises the top element <mujoco>). A free joint on
    the root body makes a floating robot (floating=True: the file must have one). contacts: the
    robot's contacts with the world (symdyn.model.contacts; docs/contacts.md).
    """
    file, raw, digest = read_source(path, "MJCF file")
    return with_contacts(mjcf_from_bytes(raw, file, digest, floating=floating), contacts)


def _free_body(model: Any, file: str, body_names: list[str], joint_names: list[str]) -> int | None:
    """The body of the model's free joint (a root body), None without one."""
    free = [j for j in range(model.njnt) if int(model.jnt_type[j]) == _FREE]
    if not free:
        return None
    if len(free) > 1:
        listed = ", ".join(f"'{joint_names[j]}'" for j in free)
        raise SymdynError(
            f"free joints {listed}: symdyn models one floating base (one free joint, on the root body)",
            file=file,
            field=f"joint({joint_names[free[1]]}).type",
        )
    b = int(model.jnt_bodyid[free[0]])
    if int(model.body_parentid[b]) != 0:
        raise SymdynError(
            f"body '{body_names[b]}', joint '{joint_names[free[0]]}' is a free joint below the root: a "
            "floating base is a body whose parent is the world",
            file=file,
            field=f"joint({joint_names[free[0]]}).type",
        )
    return b


def mjcf_from_bytes(raw: bytes, file: str, digest: str, floating: bool = False) -> Robot:
    """The `Robot` of the MJCF file `file` (its bytes `raw`, their sha256 `digest`)."""
    check_attributes(raw, file)  # before MuJoCo reads a nan as 0, which the compiled model hides
    said: list[str] = []  # MuJoCo's warnings, said once the model passes symdyn's checks
    model = compile_mjcf(raw, file, said)
    check_link_count(model.nbody - 1, "bodies once compiled", file)  # <replicate> and <include> add some
    check_numbers(model, file)
    for text in said:
        warnings.warn(text, SymdynWarning, stacklevel=3)
    flags = _disabled(model)
    body_names = names(model, "body", model.nbody, "body")
    joint_names = names(model, "jnt", model.njnt, "joint")
    site_names = names(model, "site", model.nsite, "site")
    free = _free_body(model, file, body_names, joint_names)
    tendons = tendon_terms(model, file, flags, floating=free is not None)
    _warn_ignored(file, model, flags, body_names, joint_names, tendons.ignored)
    if floating and free is None:
        raise SymdynError(
            "no free joint: a floating MJCF robot has a free joint on its root body (<freejoint/>)", file=file
        )
    walk = _Walk(file, model, owner=[(-1, Transform.identity())], free_body=free, tendons=tendons)
    for b in range(1, model.nbody):
        _body(walk, b, body_names, joint_names, flags)
    taken = set(body_names[1:]) | {fields["name"] for fields in walk.links}
    for s in range(model.nsite):
        k, T = walk.owner[int(model.site_bodyid[s])]
        if k == _OUTSIDE:
            continue
        where = {"file": file, "field": f"site({site_names[s]}).quat"}
        name = _site_frame_name(site_names[s], taken)
        walk.frames.append(Frame(name, k, T @ pose(model.site_pos[s], model.site_quat[s], **where)))
    if not walk.links and free is None:  # (a free body alone is a floating rigid body)
        raise SymdynError("no hinge or slide joint: the model has nothing that moves", file=file)
    gravity = [sp.S.Zero] * 3 if "gravity" in flags else [number(g) for g in model.opt.gravity]
    return Robot(
        name=urdf_robot_name(model_name(model)),
        links=tuple(_link(walk, i, fields) for i, fields in enumerate(walk.links)),
        gravity=sp.ImmutableMatrix(3, 1, gravity),
        source=file,
        source_sha256=digest,
        convention="mjcf",
        frames=tuple(walk.frames),
        floating=free is not None,
        base_body=BaseBody() if free is None else _base_body(walk, body_names[free]),
        tendons=tuple(_tendon(walk, c) for c in tendons.couplings),
    )


def _tendon(walk: _Walk, c: Coupling) -> Tendon:
    """A coupling over MuJoCo's dofs as a Tendon over the links (symdyn.model.tendons)."""
    coefficients = [sp.S.Zero] * len(walk.links)
    for dof, value in c.coefficients.items():
        coefficients[walk.dof_link[dof]] = number(value)
    return Tendon(
        c.name,
        tuple(coefficients),
        *(number(v) for v in (c.armature, c.damping, c.frictionloss, c.stiffness, c.springlength)),
    )


def _base_body(walk: _Walk, name: str) -> BaseBody:
    """The floating base's body: the free joint's body and the bodies welded to it."""
    mass, com, inertia = merge_inertials(walk.base_parts)
    mass, com, inertia = numeric(mass), com.applyfunc(numeric), inertia.applyfunc(numeric)
    check_inertia(mass, inertia, file=walk.file, link_name=name)
    return BaseBody(name, mass, com, inertia)


def _disabled(model: Any) -> set[str]:
    """The disabled flags of <option><flag> that change the dynamics symdyn derives."""
    mujoco = mujoco_module()
    bits = mujoco.mjtDisableBit
    out = set()
    for name, bit in (
        ("gravity", bits.mjDSBL_GRAVITY),
        ("damper", bits.mjDSBL_DAMPER),
        ("frictionloss", bits.mjDSBL_FRICTIONLOSS),
        ("spring", bits.mjDSBL_SPRING),
    ):
        if int(model.opt.disableflags) & int(bit):
            out.add(name)
    if int(model.opt.disableflags) & int(bits.mjDSBL_CONSTRAINT):
        out.add("frictionloss")  # MuJoCo's frictionloss is a constraint
    return out


def _site_frame_name(site: str, taken: set[str]) -> str:
    """The name of a site's frame: the site's name, or 'site:NAME' when a body (or a link named
    after a joint) has that name (MuJoCo keeps the names of bodies and sites apart)."""
    return f"site:{site}" if site in taken else site


def _warn_ignored(
    file: str, model: Any, flags: set[str], bodies: list[str], joints: list[str], tendons: list[str]
) -> None:
    """A SymdynWarning for each kind of force MuJoCo applies that symdyn's model leaves out
    (`tendons`: what the tendons and fluid leave out, symdyn.parsers.mjcf_tendons)."""
    ignored = []
    held = [bodies[b] for b in range(model.nbody) if float(model.body_gravcomp[b]) != 0]
    if held:
        ignored.append(f"the gravity compensation of body {', '.join(repr(n) for n in held)}")
    if model.neq:
        ignored.append(f"{model.neq} equality constraint(s)")
    ignored += tendons
    for what in ignored:
        warnings.warn(f"{file}: {what} is ignored: symdyn does not model it", SymdynWarning, stacklevel=4)


def _body(walk: _Walk, b: int, body_names: list[str], joint_names: list[str], flags: set[str]) -> None:
    """Body b: merged into its parent's link (no joint), or one link per joint."""
    model, name = walk.model, body_names[b]
    parent = int(model.body_parentid[b])
    k, T_parent = walk.owner[parent]
    first, count = int(model.body_jntadr[b]), int(model.body_jntnum[b])
    if b == walk.free_body:
        if count > 1:
            raise SymdynError(
                f"body '{name}' has a free joint and other joints: a floating base has the free joint alone",
                file=walk.file,
            )
        k, T, first, count = -1, Transform.identity(), first + 1, 0
    elif k == _OUTSIDE or (walk.free_body is not None and parent == 0):
        if count:
            raise SymdynError(
                f"body '{name}', joint '{joint_names[first]}' moves outside the floating body's tree: a "
                "floating robot is one tree on its free joint",
                file=walk.file,
            )
        walk.owner.append((_OUTSIDE, Transform.identity()))
        return
    else:
        T = T_parent @ pose(model.body_pos[b], model.body_quat[b], file=walk.file, field=f"body({name}).quat")
    for n, j in enumerate(range(first, first + count)):
        _refuse_joint(walk, int(model.jnt_type[j]), name, joint_names[j])
        T = _joint(walk, j, k, T, name if n == count - 1 else joint_names[j], flags, joint_names[j])
        k = len(walk.links) - 1
    walk.owner.append((k, T))
    if not count:
        walk.frames.append(Frame(name, k, T))
    massive = float(model.body_mass[b]) != 0 or any(float(x) != 0 for x in model.body_inertia[b])
    if massive and (k >= 0 or walk.free_body is not None):
        inertial = UrdfInertial(
            number(model.body_mass[b]),
            pose(model.body_ipos[b], model.body_iquat[b], file=walk.file, field=f"body({name}).iquat"),
            sp.ImmutableMatrix(sp.diag(*[number(x) for x in model.body_inertia[b]])),
        )
        (walk.parts[k] if k >= 0 else walk.base_parts).append((inertial, T))


def _refuse_joint(walk: _Walk, kind: int, body: str, joint: str) -> None:
    """A free or ball joint is refused, naming the body and the joint."""
    if kind == _FREE:
        why = "a free joint below the root: a floating base is a body whose parent is the world"
    elif kind == _BALL:
        why = "a ball joint: symdyn handles hinge and slide joints only (write it as three hinge joints)"
    else:
        return
    raise SymdynError(
        f"body '{body}', joint '{joint}' is {why}", file=walk.file, field=f"joint({joint}).type"
    )


def _joint(
    walk: _Walk, j: int, parent: int, T: Transform, name: str, flags: set[str], joint_name: str
) -> Transform:
    """Append the link of joint j, whose MuJoCo body frame sits at T in link `parent`'s frame;
    return that body frame (moved by this joint) in the new link's frame."""
    model = walk.model
    hinge = int(model.jnt_type[j]) == _HINGE
    axis = vector(model.jnt_axis[j])
    shift = Transform.from_translation(list(vector(model.jnt_pos[j]))) if hinge else Transform.identity()
    ref = number(model.qpos0[int(model.jnt_qposadr[j])])
    placement = T @ shift
    if ref != 0:
        motion = rot_axis(list(axis), -ref) if hinge else None
        placement = placement @ (
            Transform.from_rotation(motion.applyfunc(numeric))
            if hinge
            else Transform.from_translation(list(-axis * ref))
        )
    dof = int(model.jnt_dofadr[j])
    limits = None
    if bool(model.jnt_limited[j]):
        lower, upper = (number(x) for x in model.jnt_range[j])
        limits = (lower, upper) if lower < upper else None
    walk.dof_link[dof] = len(walk.links)
    walk.links.append(
        {
            "name": name,
            "joint": "revolute" if hinge else "prismatic",
            "placement": placement,
            "axis": axis,
            "friction": Friction(
                sp.S.Zero if "damper" in flags else _with(model.dof_damping[dof], walk.tendons.damping, dof),
                sp.S.Zero
                if "frictionloss" in flags
                else _with(model.dof_frictionloss[dof], walk.tendons.frictionloss, dof),
            ),
            "motor": Motor(_with(model.dof_armature[dof], walk.tendons.armature, dof), sp.S.One),
            "frame": shift.inverse(),
            "parent": parent,
            "limits": limits,
            "joint_name": joint_name,
        }
    )
    walk.parts.append([])
    return shift.inverse()


def _with(value: float, tendon: dict[int, float], dof: int) -> sp.Expr:
    """A joint's coefficient plus what a fixed tendon over it alone adds (symdyn.parsers.mjcf_tendons)."""
    return number(float(value) + tendon[dof]) if dof in tendon else number(value)


def _link(walk: _Walk, i: int, fields: dict) -> Link:
    """Link i with the merged mass, centre of mass and inertia of the bodies it carries."""
    mass, com, inertia = merge_inertials(walk.parts[i])
    mass, com, inertia = numeric(mass), com.applyfunc(numeric), inertia.applyfunc(numeric)
    check_inertia(mass, inertia, file=walk.file, link_index=i + 1, link_name=fields["name"])
    parent = fields.pop("parent")
    return Link(
        mass=mass,
        com=com,
        inertia=inertia,
        parent=None if parent == i - 1 else parent,
        **fields,
    )
