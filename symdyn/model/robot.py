"""The immutable robot model: a kinematic tree of links joined by general 1-DOF joints.

Every loader (standard DH, modified DH, URDF) produces this model. Link i owns a
*body frame* that moves with it. Its joint has a constant `placement`, the body
frame of link i at q_i = 0 expressed in the body frame of its parent link (the
previous link unless `parent` says otherwise; the base frame for a link on the
base), and a unit `axis` in link i's own body frame:

    parent_T_i(q_i) = placement @ Rot(axis, q_i)     (revolute)
    parent_T_i(q_i) = placement @ Trans(axis * q_i)  (prismatic)

Joint offsets (DH theta/d offsets) are folded into `placement`. Centre of mass,
inertia tensor (about the centre of mass) are expressed in the body frame.
`frame` is the convention's frame i (e.g. the standard-DH frame at the distal
end) relative to the body frame: it is used only to report kinematics in the
frames the user wrote, never by the dynamics.

Links come in depth-first order (a parent before its children; symdyn.model.topology).
A link whose joint `mimic`s another's has no coordinate of its own, so the robot has
`n` independent coordinates (degrees of freedom) and `nb` = len(links) bodies.

A link may give its joint's range, `limits` = (lower, upper) in rad or m (the robot file's
`limits`, the URDF's <limit>); None when it gives none. Nothing in the dynamics depends on it:
significance pruning (symdyn.algorithms.pruning) bounds terms over these ranges.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import sympy as sp

from ..errors import SymdynError
from ..spatial.transform import Transform, rot_axis
from ..symbolic import float_zero as _float_zero  # noqa: F401  (SymPy's Float.is_zero, fast)
from .contacts import Contact, check_contacts
from .frames import Frame, check_frame_names, unknown_frame
from .free_flyer import NQ_BASE, NV_BASE, BaseBody
from .friction import Friction
from .limits import check_limits
from .loops import Loop, check_loops, loop_path
from .parameter_names import parameter_names_problem, parameter_number
from .table import robot_table
from .tendons import Tendon
from .topology import Coordinate, Mimic, check_parents, idle_joints, is_chain

__all__ = [
    "Friction",
    "Motor",
    "Link",
    "Robot",
    "Mimic",
    "Frame",
    "BaseBody",
    "Tendon",
    "Contact",
    "JOINT_TYPES",
    "DEFAULT_GRAVITY",
]

JOINT_TYPES = ("revolute", "prismatic")
#: Gravity (base frame) when the robot description gives none: 9.81 m/s^2 along -z.
DEFAULT_GRAVITY = (sp.Integer(0), sp.Integer(0), sp.Float(-9.81))


@dataclass(frozen=True)
class Motor:
    """A rotor reflected through a gearbox: adds gear_ratio**2 * inertia to M[i, i]."""

    inertia: sp.Expr = sp.S.Zero
    gear_ratio: sp.Expr = sp.S.One

    @property
    def reflected_inertia(self) -> sp.Expr:
        return self.gear_ratio**2 * self.inertia


@dataclass(frozen=True)
class Link:
    """One link with the joint that moves it relative to its parent."""

    name: str
    joint: str  # "revolute" | "prismatic"
    placement: Transform
    axis: sp.ImmutableMatrix  # 3x1 unit vector in the body frame
    mass: sp.Expr
    com: sp.ImmutableMatrix  # 3x1, body frame
    inertia: sp.ImmutableMatrix  # 3x3 tensor about the centre of mass, body-frame axes
    friction: Friction = field(default_factory=Friction)
    motor: Motor = field(default_factory=Motor)
    frame: Transform = field(default_factory=Transform.identity)
    #: index of the parent link in Robot.links, -1 for the base; None: the previous link
    parent: int | None = None
    #: this joint follows another: q = multiplier * q_other + offset (no coordinate of its own)
    mimic: Mimic | None = None
    #: the joint's range (lower, upper) in rad or m: numbers, or expressions of valued parameters; None: none
    limits: tuple[sp.Expr, sp.Expr] | None = None
    #: the joint's own name where the file gives joints names (URDF, MJCF), for messages only
    joint_name: str | None = field(default=None, compare=False, repr=False)

    def joint_transform(self, q) -> Transform:
        """parent_T_i(q): the body frame of this link in its parent's body frame."""
        if self.joint == "revolute":
            return self.placement @ Transform.from_rotation(rot_axis(list(self.axis), q))
        return self.placement @ Transform.from_translation(list(self.axis * q))

    def subs(self, mapping: Mapping) -> Link:
        x = dict(mapping)
        return replace(
            self,
            placement=self.placement.subs(x),
            axis=self.axis.xreplace(x),
            mass=sp.sympify(self.mass).xreplace(x),
            com=self.com.xreplace(x),
            inertia=self.inertia.xreplace(x),
            friction=self.friction.subs(x),
            motor=Motor(
                sp.sympify(self.motor.inertia).xreplace(x),
                sp.sympify(self.motor.gear_ratio).xreplace(x),
            ),
            frame=self.frame.subs(x),
            mimic=None
            if self.mimic is None
            else Mimic(
                self.mimic.joint,
                sp.sympify(self.mimic.multiplier).xreplace(x),
                sp.sympify(self.mimic.offset).xreplace(x),
            ),
            limits=None if self.limits is None else tuple(sp.sympify(v).xreplace(x) for v in self.limits),
        )


def _entries(k: int) -> str:
    return f"{k} entry" if k == 1 else f"{k} entries"


def _is_zero(x) -> bool:
    """Whether a number or expression is exactly zero (a free symbol may be anything: False)."""
    return sp.sympify(x).is_zero is True


def _listed(values) -> list | None:
    """The items of an iterable as a list; None for a non-iterable (a bare number)."""
    try:
        return list(values)
    except TypeError:
        return None


@dataclass(frozen=True)
class Robot:
    """An immutable manipulator: a serial chain or a kinematic tree on a fixed base.

    `values` holds the parameters the file gave values for (symbol -> SymPy
    number or expression); `params` the free parameter symbols (no value), in
    order of first appearance in the file. `floating`: the base is not fixed but joined to the
    world by a free flyer (symdyn.model.free_flyer; `nq` and `nv` count its coordinates too),
    and `base` must then be the identity. Otherwise `base` = world_T_base places the base frame in
    the world (identity: the base frame is the world frame) and `gravity` is the gravitational
    acceleration in the world frame; `base_gravity` is it in the base frame, what the dynamics
    use. `frames` are the named frames besides the links' own (symdyn.model.frames).
    """

    name: str
    links: tuple[Link, ...]
    gravity: sp.ImmutableMatrix
    params: tuple[sp.Symbol, ...] = ()
    values: tuple[tuple[sp.Symbol, sp.Expr], ...] = ()
    source: str | None = None
    source_sha256: str | None = None
    convention: str = "standard"
    frames: tuple[Frame, ...] = ()
    base: Transform = field(default_factory=Transform.identity)
    #: the base is joined to the world by a free flyer (symdyn.model.free_flyer) instead of fixed
    floating: bool = False
    #: closures of kinematic loops over the tree of `links` (symdyn.model.loops)
    loops: tuple[Loop, ...] = ()
    #: the links whose joints are driven (indices into links); None: every joint off the loops
    actuated: tuple[int, ...] | None = None
    #: the body the free flyer moves (its mass and inertia): used only when `floating`
    base_body: BaseBody = field(default_factory=BaseBody)
    #: fixed tendons and joint springs (symdyn.model.tendons): couplings with constant coefficients
    tendons: tuple[Tendon, ...] = ()
    #: contacts with the world at named frames (symdyn.model.contacts), rows in this order
    contacts: tuple[Contact, ...] = ()

    def __post_init__(self) -> None:
        problem = check_parents(self.parents)
        if problem:
            raise SymdynError(f"robot '{self.name}': {problem}")
        check_frame_names(self.name, [link.name for link in self.links], self.frames, self.nb)
        mimics = [link.mimic is not None for link in self.links]
        check_loops(self.name, [link.name for link in self.links], mimics, self.loops, self.actuated)
        if self.floating and self.loops:
            raise SymdynError(
                f"robot '{self.name}': closed loops (field 'loops') on a floating base are not handled "
                "yet: the loop functions are derived for a fixed base",
                file=self.source,
            )
        if self.floating and self.base != Transform.identity():
            raise SymdynError(
                f"robot '{self.name}': a floating base has no fixed placement in the world (its "
                "position and orientation are coordinates): give 'base: floating' without a placement"
            )
        self._check_tendons()
        self._check_contacts()
        for i, link in enumerate(self.links):
            m = link.mimic
            if m is None:
                continue
            if not (0 <= m.joint < len(self.links)) or m.joint == i:
                raise SymdynError(f"robot '{self.name}': link {i + 1} ({link.name}) mimics no other joint")
            if self.links[m.joint].mimic is not None:
                other = self.links[m.joint].name
                raise SymdynError(
                    f"robot '{self.name}': link {i + 1} ({link.name}) mimics {other}, which is a mimic "
                    "joint itself (mimic the joint that it follows instead)"
                )

    def _check_tendons(self) -> None:
        """One coefficient per link in every tendon, and none on a floating base."""
        for t in self.tendons:
            if len(t.coefficients) != len(self.links):
                raise SymdynError(
                    f"robot '{self.name}': tendon '{t.name}' has {len(t.coefficients)} coefficients, "
                    f"expected {len(self.links)} (one per link)",
                    file=self.source,
                )
        if self.floating and self.tendons:
            raise SymdynError(
                f"robot '{self.name}': fixed tendons and joint springs ('{self.tendons[0].name}') on a "
                "floating base are not handled yet: fix the base, or remove the tendon's armature, "
                "damping, frictionloss and stiffness",
                file=self.source,
            )

    def _check_contacts(self) -> None:
        """Contacts at existing frames, with unique identifier names; none beside closed loops."""
        if not isinstance(self.contacts, tuple):
            raise SymdynError(f"robot '{self.name}': contacts must be a tuple of Contact", file=self.source)
        if not self.contacts:
            return
        try:
            check_contacts(self.name, self.contacts, self.frame_names, "contacts")
        except SymdynError as e:
            raise SymdynError(e.reason, file=self.source) from None
        if self.loops:
            raise SymdynError(
                f"robot '{self.name}': contacts (field 'contacts') on a robot with closed loops are not "
                "handled yet: the contact functions are derived for a tree",
                file=self.source,
            )

    def __repr__(self) -> str:
        """A header line and one row per link (symdyn.model.table), instead of every matrix."""
        return robot_table(self)

    __str__ = __repr__

    @property
    def base_gravity(self) -> sp.ImmutableMatrix:
        """g in the base frame, base_R_world g (`gravity` itself when the base is not rotated)."""
        R = self.base.R
        return self.gravity if sp.eye(3) == R else sp.ImmutableMatrix(R.T * self.gravity)

    @property
    def frame_names(self) -> tuple[str, ...]:
        """Every frame's name: the links' (in order), then the other frames'."""
        return tuple(link.name for link in self.links) + tuple(f.name for f in self.frames)

    def frame(self, name: str, where: str = "frame") -> Frame:
        """The frame named `name`: a link's (its convention frame, `Link.frame`) or one of `frames`.

        Raises:
            SymdynError: an unknown name, naming the near matches.
        """
        for i, link in enumerate(self.links):
            if link.name == name:
                return Frame(name, i, link.frame)
        for f in self.frames:
            if f.name == name:
                return f
        raise unknown_frame(name, self.frame_names, f"{where}: robot '{self.name}'", self.source)

    @cached_property
    def n(self) -> int:
        """Number of independent joint coordinates (degrees of freedom)."""
        return sum(1 for link in self.links if link.mimic is None)

    @property
    def nq(self) -> int:
        """Size of the configuration vector: n, or 7 + n on a floating base (position, quaternion)."""
        return self.n + NQ_BASE if self.floating else self.n

    @property
    def nv(self) -> int:
        """Size of the velocity, acceleration and force vectors: n, or 6 + n on a floating base."""
        return self.n + NV_BASE if self.floating else self.n

    @property
    def actuated_links(self) -> tuple[int, ...]:
        """The links whose joints are driven: `actuated`, or by default every link with a
        coordinate of its own that lies on no loop's path (all of them for a tree)."""
        if self.actuated is not None:
            return tuple(sorted(self.actuated))
        on_loops = {i for loop in self.loops for i in loop_path(self.parents, loop.link, loop.to)}
        return tuple(i for i, link in enumerate(self.links) if link.mimic is None and i not in on_loops)

    @property
    def nb(self) -> int:
        """Number of moving bodies (links with a joint, mimic joints included)."""
        return len(self.links)

    @cached_property
    def parents(self) -> tuple[int, ...]:
        """lambda(i) per link: the index of its parent link, -1 for the base."""
        return tuple(i - 1 if link.parent is None else link.parent for i, link in enumerate(self.links))

    @property
    def is_chain(self) -> bool:
        """A serial chain without mimic joints: every link carries the next."""
        return self.n == self.nb and is_chain(self.parents)

    @cached_property
    def coordinates(self) -> tuple[Coordinate, ...]:
        """Per link, how its joint position follows from the independent coordinates."""
        index = {}
        for i, link in enumerate(self.links):
            if link.mimic is None:
                index[i] = len(index)
        out = []
        for i, link in enumerate(self.links):
            m = link.mimic
            out.append(
                Coordinate(index[i]) if m is None else Coordinate(index[m.joint], m.multiplier, m.offset)
            )
        return tuple(out)

    def selection(self) -> sp.ImmutableMatrix:
        """S (nb x n): the body joint rates from the independent ones, qd_b = S qd."""
        S = sp.zeros(self.nb, self.n)
        for i, c in enumerate(self.coordinates):
            S[i, c.index] = c.multiplier
        return sp.ImmutableMatrix(S)

    def body_positions(self, q: Sequence) -> list:
        """q_b: each body's joint position from the n independent ones (symbols or numbers)."""
        return [
            q[c.index] if c.multiplier == 1 and c.offset == 0 else c.multiplier * q[c.index] + c.offset
            for c in self.coordinates
        ]

    def body_rates(self, qd: Sequence) -> list:
        """qd_b = S qd (or qdd_b = S qdd): each body's joint rate from the independent ones."""
        return [qd[c.index] if c.multiplier == 1 else c.multiplier * qd[c.index] for c in self.coordinates]

    def idle_joints(self) -> tuple[int, ...]:
        """The links whose joint moves nothing with mass or inertia: M(q) is singular.

        Joint i is idle when it has no rotor inertia and its subtree has zero mass and zero
        rotational inertia (zero mass for a prismatic joint): M has a zero row for it
        (symdyn.model.topology.idle_joints). A coordinate that drives several links (mimic
        joints) is idle only when all of them are. Decided on the numbers of the robot with
        its valued parameters substituted: a free parameter may take any value, so a mass
        or inertia that names one counts as non-zero.

        Returns:
            The indices of the idle links in self.links, in increasing order.
        """
        links = self.resolved().links
        weightless = [_is_zero(lk.mass) for lk in links]
        massless = [
            w and all(_is_zero(x) for x in lk.inertia) for w, lk in zip(weightless, links, strict=True)
        ]
        turns = [lk.joint == "revolute" for lk in links]
        geared = [not _is_zero(lk.motor.reflected_inertia) for lk in links]
        idle = set(idle_joints(self.parents, massless, weightless, turns, geared))
        coordinates = self.coordinates
        busy = {c.index for i, c in enumerate(coordinates) if i not in idle}
        return tuple(i for i in sorted(idle) if coordinates[i].index not in busy)

    def joint_ranges(self) -> tuple[tuple[float, float] | None, ...]:
        """Per independent coordinate, the range (lower, upper) its own link's `limits` give
        (rad or m, valued parameters substituted), None where the link gives none. A mimic
        joint's own limits do not enter: its coordinate is its master's.

        Raises:
            SymdynError: limits that are not numbers, or not lower < upper (naming the link).
        """
        out = []
        for i, link in enumerate(self.resolved().links):
            if link.mimic is None:
                where = {"link_index": i + 1, "link_name": link.name, "file": self.source}
                out.append(None if link.limits is None else check_limits(link.limits, **where))
        return tuple(out)

    @property
    def value_map(self) -> dict[sp.Symbol, sp.Expr]:
        return dict(self.values)

    def resolved(self) -> Robot:
        """This robot with every valued parameter substituted: only `params` stay symbolic."""
        if not self.values:
            return self
        return self._substituted(self.value_map, values=())

    def param_values(self, params=None, where: str = "") -> dict[sp.Symbol, float]:
        """Numbers for the free parameters: a sequence in `params` order or a name/symbol map.

        Args:
            params: None (only when the robot has no free parameters), a sequence of one
                number per free parameter in `self.params` order, or a map from each free
                parameter (name or symbol) to a number.
            where: the public function asking, to start error messages with.

        Returns:
            free parameter symbol -> float (empty for a robot without free parameters).

        Raises:
            SymdynError: a missing, extra, unknown or non-numeric value.
        """
        prefix = f"{where}: " if where else ""
        if params is None:
            if self.params:
                raise SymdynError(
                    f"{prefix}robot '{self.name}' has free parameters ({self._listing()}); give their values"
                )
            return {}
        if isinstance(params, Mapping):
            by_name = {str(k): v for k, v in params.items()}
            names = [str(p) for p in self.params]
            problem = parameter_names_problem(by_name, names, self.name)
            if problem:
                raise SymdynError(prefix + problem)
            given = [by_name[k] for k in names]
        else:
            given = None if isinstance(params, (str, bytes)) else _listed(params)
            if given is None:
                raise SymdynError(
                    f"{prefix}params must be a sequence of numbers or a name -> number map, got {params!r}"
                )
            if len(given) != len(self.params):
                raise SymdynError(
                    f"{prefix}params has {len(given)} values, expected {len(self.params)} (one per free "
                    f"parameter: {self._listing()})"
                )
        values = {p: parameter_number(str(p), v, prefix) for p, v in zip(self.params, given, strict=True)}
        return values

    def _listing(self) -> str:
        return ", ".join(str(p) for p in self.params) or "none"

    def joint_values(self, values, name: str = "q", where: str = "") -> np.ndarray:
        """One number per joint, as a float array of shape (n,).

        Args:
            values: n numbers (any sequence or array), or None for zeros.
            name: what the vector is (q, qd, qdd, tau), for messages.
            where: the public function asking, to start error messages with.

        Raises:
            SymdynError: not n numbers.
        """
        prefix = f"{where}: " if where else ""
        if values is None:
            return np.zeros(self.n)
        try:
            a = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            raise SymdynError(f"{prefix}{name} must hold numbers, got {values!r}") from None
        if a.ndim != 1:
            raise SymdynError(f"{prefix}{name} has shape {a.shape}, expected ({self.n},) (one per joint)")
        if a.size != self.n:
            raise SymdynError(f"{prefix}{name} has {_entries(a.size)}, expected {self.n} (one per joint)")
        return a

    def numeric(self, params=None) -> Robot:
        """A fully numeric copy (every parameter substituted), for the numeric algorithms."""
        r = self.resolved()
        if not r.params:
            return r
        mapping = {p: sp.Float(v, 17) for p, v in r.param_values(params).items()}
        return r._substituted(mapping, params=())

    def _substituted(self, mapping: Mapping, **changes) -> Robot:
        """A copy with `mapping` substituted into every link and gravity, and `changes` applied."""
        return replace(
            self,
            links=tuple(link.subs(mapping) for link in self.links),
            gravity=self.gravity.xreplace(mapping),
            frames=tuple(f.subs(mapping) for f in self.frames),
            base=self.base.subs(mapping),
            loops=tuple(loop.subs(mapping) for loop in self.loops),
            base_body=self.base_body.subs(mapping),
            tendons=tuple(t.subs(mapping) for t in self.tendons),
            **changes,
        )
