"""The numeric oracle's inputs: a `Robot` as NumPy arrays, and the checked arguments.

symdyn.rnea evaluates rigid-body dynamics with NumPy only; this module is its side that
reads the model. `numeric_model` converts `robot.numeric(params)` to arrays once per robot
and parameter values (cached), and `checked_inputs` checks what every public function of
symdyn.rnea is given (the robot, the parameter values, the joint vectors) and says what it
expected. `body_positions` and `body_rates` expand the n independent joint vectors to the
nb bodies (a mimic joint follows q_j = multiplier q_i + offset), and `project` takes body
efforts back, S^T tau_b. Nothing here imports SymPy or the symbolic derivation.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import SymdynError

__all__ = [
    "NumericModel",
    "numeric_model",
    "checked_inputs",
    "skew",
    "body_positions",
    "body_rates",
    "project",
]


@dataclass(frozen=True, eq=False)
class NumericModel:
    """A robot as NumPy arrays (nb links, n independent joints): everything the numeric
    algorithms read.

    `revolute` (nb,) bool; `R0`, `p0` (nb,3,3), (nb,3) the constant placement;
    `axis` (nb,3) in the body frame; `mass` (nb,); `com` (nb,3) body frame;
    `inertia` (nb,3,3) about the centre of mass; `spatial_inertia` (nb,6,6) about
    the body origin; `viscous`, `coulomb`, `reflected` (nb,) friction and
    gear_ratio**2 * rotor inertia; `coulomb_minus` (nb,) the Coulomb magnitude for negative
    rates (`coulomb` where `asymmetric` (nb,) bool is False); `gravity` (3,) in the base frame
    (the robot's world gravity turned by the base rotation, base_R_world g); `base_R`, `base_p`
    (3,3), (3,) the base frame in the world; `frame_link` (nf,) int and `frame_R`, `frame_p`
    (nf,3,3), (nf,3): the link (-1: base) and placement in its body frame of every frame
    (`frame_names`: the links' names, then Robot.frames'); `parent` (nb,) int,
    lambda(i) with -1 for the base (parents before children); `coordinate` (nb,) int, the
    independent coordinate each body's joint follows, with `multiplier` and `offset` (nb,)
    (q_i = multiplier_i q[coordinate_i] + offset_i); `selection` (nb, n) the matrix S of
    qd_b = S qd; `own` (n,) int, per coordinate the link whose joint it is (not a mimic);
    `names` the links' names and `name` the robot's, for messages. `floating`: the base floats
    (Robot.floating), `base_inertia` (6,6) the spatial inertia of its body about the base origin
    (zero on a fixed base). `tendon_coef` (nt, nb) the fixed tendons' coefficients over the bodies'
    joint positions and `tendon_armature`, `tendon_damping`, `tendon_friction`,
    `tendon_stiffness`, `tendon_length` (nt,) their passive properties (symdyn.model.tendons).
    """

    revolute: np.ndarray
    R0: np.ndarray
    p0: np.ndarray
    axis: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    spatial_inertia: np.ndarray
    viscous: np.ndarray
    coulomb: np.ndarray
    coulomb_minus: np.ndarray
    asymmetric: np.ndarray
    reflected: np.ndarray
    gravity: np.ndarray
    base_R: np.ndarray
    base_p: np.ndarray
    frame_link: np.ndarray
    frame_R: np.ndarray
    frame_p: np.ndarray
    frame_names: tuple[str, ...]
    parent: np.ndarray
    coordinate: np.ndarray
    multiplier: np.ndarray
    offset: np.ndarray
    selection: np.ndarray
    own: np.ndarray
    names: tuple[str, ...]
    name: str
    floating: bool
    base_inertia: np.ndarray
    tendon_coef: np.ndarray
    tendon_armature: np.ndarray
    tendon_damping: np.ndarray
    tendon_friction: np.ndarray
    tendon_stiffness: np.ndarray
    tendon_length: np.ndarray

    def __post_init__(self) -> None:
        for value in vars(self).values():  # cached and shared: make every array read-only
            if isinstance(value, np.ndarray):
                value.flags.writeable = False

    @property
    def n(self) -> int:
        """Number of independent joint coordinates (the length of q, qd, qdd, tau)."""
        return self.selection.shape[1]

    @property
    def nb(self) -> int:
        """Number of bodies (links)."""
        return len(self.revolute)


def skew(v: np.ndarray) -> np.ndarray:
    """The cross-product matrix [v]x, with v of shape (..., 3) -> (..., 3, 3)."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    o = np.zeros_like(x)
    return np.stack([np.stack([o, -z, y], -1), np.stack([z, o, -x], -1), np.stack([-y, x, o], -1)], -2)


def _floats(expr, shape, what: str) -> np.ndarray:
    try:
        return np.array(np.asarray(expr).tolist(), dtype=float).reshape(shape)
    except (TypeError, ValueError) as exc:
        raise SymdynError(f"{what} is not numeric after substitution: {expr}") from exc


def _model(robot, params, where: str) -> NumericModel:
    """The cached numeric model, after checking the robot and its parameter values."""
    if not all(hasattr(robot, a) for a in ("links", "params", "param_values", "numeric")):
        raise SymdynError(f"{where}: robot must be a symdyn Robot, got {type(robot).__name__}")
    values = robot.param_values(params, where)  # names, count and numbers checked here
    return _numeric_model(robot, tuple(values[p] for p in robot.params))


def numeric_model(robot, params=None) -> NumericModel:
    """Convert `robot.numeric(params)` to NumPy arrays, once per (robot, parameter values).

    Args:
        robot: a `symdyn.Robot`.
        params: values of its free parameters (`robot.params`): a sequence in that order or a
            name -> number map; None when it has none.

    Raises:
        SymdynError: missing, extra, unknown or non-numeric parameter values.
    """
    return _model(robot, params, "numeric_model")


@lru_cache(maxsize=256)
def _numeric_model(robot, values: tuple[float, ...]) -> NumericModel:
    r = robot.numeric(list(values) if values else None)
    links = r.links
    for k, lk in enumerate(links, 1):
        if lk.joint not in ("revolute", "prismatic"):
            raise SymdynError(f"unknown joint type {lk.joint!r}", link_index=k, link_name=lk.name)
    R0 = np.array([_floats(lk.placement.R, (3, 3), f"{lk.name} placement") for lk in links])
    p0 = np.array([_floats(lk.placement.p, (3,), f"{lk.name} placement") for lk in links])
    axis = np.array([_floats(lk.axis, (3,), f"{lk.name} axis") for lk in links])
    mass = np.array([_floats(lk.mass, (), f"{lk.name} mass") for lk in links])
    com = np.array([_floats(lk.com, (3,), f"{lk.name} com") for lk in links])
    inertia = np.array([_floats(lk.inertia, (3, 3), f"{lk.name} inertia") for lk in links])
    n = len(links)
    R0, inertia = R0.reshape(n, 3, 3), inertia.reshape(n, 3, 3)
    p0, axis, com, mass = p0.reshape(n, 3), axis.reshape(n, 3), com.reshape(n, 3), mass.reshape(n)
    spatial = _spatial_inertias(mass, com, inertia)
    body = r.base_body
    base_inertia = _spatial_inertias(
        _floats(body.mass, (1,), "base mass"),
        _floats(body.com, (1, 3), "base com"),
        _floats(body.inertia, (1, 3, 3), "base inertia"),
    )[0]
    fr = [
        (lk.friction.viscous, lk.friction.coulomb, lk.motor.reflected_inertia, lk.friction.coulomb_minus)
        for lk in links
    ]
    fr = [(*t[:3], t[1] if t[3] is None else t[3]) for t in fr]
    fr = np.array(
        [[_floats(x, (), f"{lk.name} friction/motor") for x in t] for lk, t in zip(links, fr, strict=True)]
    ).reshape(n, 4)
    coords = r.coordinates
    coordinate = np.array([c.index for c in coords], dtype=int).reshape(n)
    multiplier = np.array(
        [_floats(c.multiplier, (), f"{lk.name} mimic") for lk, c in zip(links, coords, strict=True)]
    )
    offset = np.array(
        [_floats(c.offset, (), f"{lk.name} mimic") for lk, c in zip(links, coords, strict=True)]
    )
    selection = np.zeros((n, r.n))
    selection[np.arange(n), coordinate] = multiplier
    base_R = _floats(r.base.R, (3, 3), "base.rpy")
    frames = [(i, lk.name, lk.frame) for i, lk in enumerate(links)] + [
        (f.link, f.name, f.placement) for f in r.frames
    ]
    frame_R = np.array([_floats(T.R, (3, 3), f"frame {name}") for _, name, T in frames]).reshape(-1, 3, 3)
    frame_p = np.array([_floats(T.p, (3,), f"frame {name}") for _, name, T in frames]).reshape(-1, 3)
    tendons = np.array(
        [
            [_floats(x, (), f"tendon {t.name}") for x in (*t.coefficients, *_tendon_properties(t))]
            for t in r.tendons
        ]
    ).reshape(len(r.tendons), n + 5)
    return NumericModel(
        revolute=np.array([lk.joint == "revolute" for lk in links], dtype=bool),
        R0=R0, p0=p0, axis=axis, mass=mass, com=com, inertia=inertia,
        spatial_inertia=spatial, viscous=fr[:, 0], coulomb=fr[:, 1], reflected=fr[:, 2],
        coulomb_minus=fr[:, 3], asymmetric=np.array([lk.friction.asymmetric for lk in links], dtype=bool),
        gravity=base_R.T @ _floats(r.gravity, (3,), "gravity"), base_R=base_R,
        base_p=_floats(r.base.p, (3,), "base.xyz"), frame_link=np.array([k for k, _, _ in frames], dtype=int),
        frame_R=frame_R, frame_p=frame_p, frame_names=tuple(name for _, name, _ in frames),
        parent=np.array(r.parents, dtype=int).reshape(n),
        coordinate=coordinate, multiplier=multiplier.reshape(n), offset=offset.reshape(n),
        selection=selection, own=np.array([i for i, lk in enumerate(links) if lk.mimic is None], dtype=int),
        names=tuple(lk.name for lk in links), name=r.name,
        floating=bool(r.floating), base_inertia=base_inertia,
        tendon_coef=tendons[:, :n], tendon_armature=tendons[:, n], tendon_damping=tendons[:, n + 1],
        tendon_friction=tendons[:, n + 2], tendon_stiffness=tendons[:, n + 3],
        tendon_length=tendons[:, n + 4],
    )  # fmt: skip


def _tendon_properties(t) -> tuple:
    """A tendon's armature, damping, frictionloss, stiffness and spring length, in that order."""
    return (t.armature, t.damping, t.frictionloss, t.stiffness, t.springlength)


def _spatial_inertias(mass: np.ndarray, com: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """Spatial inertias (k,6,6) about the body origins: [[Ic + m cx cx^T, m cx], [m cx^T, m 1]]."""
    cx = skew(com)
    m = mass[:, None, None]
    spatial = np.zeros((len(mass), 6, 6))
    spatial[:, :3, :3] = inertia + m * cx @ np.swapaxes(cx, -1, -2)
    spatial[:, :3, 3:] = m * cx
    spatial[:, 3:, :3] = m * np.swapaxes(cx, -1, -2)
    spatial[:, 3:, 3:] = m * np.eye(3)
    return spatial


def _states(where: str, n: int, *named: tuple) -> tuple[list[np.ndarray], bool]:
    """Joint vectors (name, value), each (n,) or (N, n), or (name, value, size, what) with their
    own size (a floating robot's q of NQ entries, v of NV: `what` says so), all with one number of
    states N, as (N, size) arrays; and whether they were single states."""
    arrays = []
    for name, x, *sized in named:
        size, what = sized if sized else (n, "one per joint")
        try:
            a = np.asarray(x, dtype=float)
        except (TypeError, ValueError):
            raise SymdynError(f"{where}: {name} must hold numbers, got {x!r}") from None
        if a.ndim == 1 and a.shape != (size,):
            count = f"{a.size} entry" if a.size == 1 else f"{a.size} entries"
            raise SymdynError(f"{where}: {name} has {count}, expected {size} ({what})")
        if a.ndim not in (1, 2) or a.shape[-1] != size:
            rows = f"{what}: one row per state" if sized else "one column per joint"
            raise SymdynError(
                f"{where}: {name} has shape {a.shape}, expected ({size},) or (N, {size}) ({rows})"
            )
        arrays.append(a)
    if len({a.shape[:-1] for a in arrays}) > 1 or len({a.ndim for a in arrays}) > 1:
        shapes = ", ".join(f"{t[0]} {a.shape}" for t, a in zip(named, arrays, strict=True))
        raise SymdynError(
            f"{where}: the joint vectors differ in shape ({shapes}); give each one state or N states"
        )
    return [a.reshape(-1, a.shape[-1]) for a in arrays], not arrays or arrays[0].ndim == 1


def checked_inputs(where: str, robot, params, *named: tuple[str, object]):
    """The numeric model and the joint vectors of a public function of symdyn.rnea, checked.

    Args:
        where: the function's name, to start error messages with.
        robot: a `symdyn.Robot` with n joints.
        params: values of its free parameters (see `numeric_model`).
        named: (name, value) of each joint vector, e.g. ("q", q): (n,) each, or (N, n) each.

    Returns:
        (model, the vectors as (N, n) arrays, whether they were single states).

    Raises:
        SymdynError: not a Robot, bad parameter values, a vector of the wrong shape or not
            numeric, vectors of different shapes.
    """
    mdl = _model(robot, params, where)
    arrays, single = _states(where, mdl.n, *named)
    return mdl, arrays, single


def body_positions(mdl: NumericModel, q: np.ndarray) -> np.ndarray:
    """q_b (N, nb): each body's joint position, multiplier q[coordinate] + offset, from q (N, n)."""
    return q[:, mdl.coordinate] * mdl.multiplier + mdl.offset


def body_rates(mdl: NumericModel, qd: np.ndarray) -> np.ndarray:
    """qd_b = S qd (N, nb) from qd (N, n); the same for accelerations."""
    return qd[:, mdl.coordinate] * mdl.multiplier


def project(mdl: NumericModel, tau_b: np.ndarray) -> np.ndarray:
    """S^T tau_b (N, n): body efforts (N, nb) on the independent coordinates (virtual work)."""
    return tau_b @ mdl.selection
