"""The independent numeric oracle: rigid-body dynamics of a `Robot` with NumPy only.

Every symbolic derivation and every generated function is judged against this
module, so it shares no code with them: it reads the `Robot` model, converts it
once to NumPy arrays (`numeric_model`, cached per robot and parameter values)
and never calls SymPy while evaluating. It also uses a different formulation
from the lecture's link-frame recursion (slides 14-15): Featherstone's
spatial-vector algorithms in body coordinates, with motion vectors
v = [omega; v_O] and force vectors f = [n_O; f] (angular part first, both
taken at the body-frame origin O and expressed in body-frame axes):

* inverse dynamics: the recursive Newton-Euler algorithm (RNEA) on spatial
  vectors, gravity entered as a fictitious base acceleration a_0 = [0; -g];
* mass matrix: the composite-rigid-body algorithm (CRBA);
* energies and kinematics: poses composed in the base frame.

Body i moves relative to body i-1 by parent_T_i(q_i) = placement @ Rot(axis, q_i)
(revolute, motion subspace S_i = [axis; 0]) or placement @ Trans(axis q_i)
(prismatic, S_i = [0; axis]). Every public function accepts a single state
(vectors of length n) or a batch (arrays of shape (N, n)).
"""

from __future__ import annotations

import sys
import types
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .errors import SymdynError

__all__ = [
    "NumericModel",
    "numeric_model",
    "rnea",
    "mass_matrix",
    "gravity_torque",
    "bias_torque",
    "friction_torque",
    "forward_dynamics",
    "kinetic_energy",
    "potential_energy",
    "forward_kinematics",
    "link_com_positions",
]


@dataclass(frozen=True, eq=False)
class NumericModel:
    """A robot as NumPy arrays (n links): everything the numeric algorithms read.

    `revolute` (n,) bool; `R0`, `p0` (n,3,3), (n,3) the constant placement;
    `axis` (n,3) in the body frame; `mass` (n,); `com` (n,3) body frame;
    `inertia` (n,3,3) about the centre of mass; `spatial_inertia` (n,6,6) about
    the body origin; `viscous`, `coulomb`, `reflected` (n,) friction and
    gear_ratio**2 * rotor inertia; `gravity` (3,) in the base frame.
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
    reflected: np.ndarray
    gravity: np.ndarray

    def __post_init__(self) -> None:
        for value in vars(self).values():  # cached and shared: make every array read-only
            value.flags.writeable = False

    @property
    def n(self) -> int:
        return len(self.revolute)


def _skew(v: np.ndarray) -> np.ndarray:
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
    # Spatial inertia about the body origin: [[Ic + m cx cx^T, m cx], [m cx^T, m 1]].
    cx = _skew(com)
    m = mass[:, None, None]
    spatial = np.zeros((n, 6, 6))
    spatial[:, :3, :3] = inertia + m * cx @ np.swapaxes(cx, -1, -2)
    spatial[:, :3, 3:] = m * cx
    spatial[:, 3:, :3] = m * np.swapaxes(cx, -1, -2)
    spatial[:, 3:, 3:] = m * np.eye(3)
    fr = [(lk.friction.viscous, lk.friction.coulomb, lk.motor.reflected_inertia) for lk in links]
    fr = np.array(
        [[_floats(x, (), f"{lk.name} friction/motor") for x in t] for lk, t in zip(links, fr, strict=True)]
    ).reshape(n, 3)
    return NumericModel(
        revolute=np.array([lk.joint == "revolute" for lk in links], dtype=bool),
        R0=R0, p0=p0, axis=axis, mass=mass, com=com, inertia=inertia,
        spatial_inertia=spatial, viscous=fr[:, 0], coulomb=fr[:, 1], reflected=fr[:, 2],
        gravity=_floats(r.gravity, (3,), "gravity"),
    )  # fmt: skip


def _states(where: str, n: int, *named: tuple[str, object]) -> tuple[list[np.ndarray], bool]:
    """Joint vectors (name, value), each (n,) or (N, n) and all of one shape, as (N, n) arrays;
    and whether they were single states."""
    arrays = []
    for name, x in named:
        try:
            a = np.asarray(x, dtype=float)
        except (TypeError, ValueError):
            raise SymdynError(f"{where}: {name} must hold numbers, got {x!r}") from None
        if a.ndim == 1 and a.shape != (n,):
            count = f"{a.size} entry" if a.size == 1 else f"{a.size} entries"
            raise SymdynError(f"{where}: {name} has {count}, expected {n} (one per joint)")
        if a.ndim not in (1, 2) or a.shape[-1] != n:
            raise SymdynError(
                f"{where}: {name} has shape {a.shape}, expected ({n},) or (N, {n}) (one column per joint)"
            )
        arrays.append(a)
    if len({a.shape for a in arrays}) > 1:
        shapes = ", ".join(f"{name} {a.shape}" for (name, _), a in zip(named, arrays, strict=True))
        raise SymdynError(
            f"{where}: the joint vectors differ in shape ({shapes}); give each one state or N states"
        )
    return [a.reshape(-1, n) for a in arrays], arrays[0].ndim == 1


def _inputs(where: str, robot, params, *named: tuple[str, object]):
    """The checked numeric model and joint vectors of a public function (see `_states`)."""
    mdl = _model(robot, params, where)
    arrays, single = _states(where, mdl.n, *named)
    return mdl, arrays, single


def _out(a: np.ndarray, single: bool) -> np.ndarray:
    return a[0] if single else a


def _joint_poses(mdl: NumericModel, q: np.ndarray):
    """Per joint i: (E, r) with E = parent_R_i (N,3,3) and r = origin of body i in parent (N,3)."""
    out = []
    for i in range(mdl.n):
        qi = q[:, i]
        if mdl.revolute[i]:
            k = mdl.axis[i]
            K = _skew(k)
            c, s = np.cos(qi)[:, None, None], np.sin(qi)[:, None, None]
            rot = c * np.eye(3) + s * K + (1.0 - c) * np.outer(k, k)  # Rodrigues
            out.append((mdl.R0[i] @ rot, np.broadcast_to(mdl.p0[i], (len(qi), 3))))
        else:
            E = np.broadcast_to(mdl.R0[i], (len(qi), 3, 3))
            out.append((E, mdl.p0[i] + qi[:, None] * (mdl.R0[i] @ mdl.axis[i])))
    return out


def _motion_transforms(poses) -> list[np.ndarray]:
    """i_X_{i-1} = [[E^T, 0], [-E^T [r]x, E^T]]: parent motion vectors into body i coordinates."""
    xs = []
    for E, r in poses:
        Et = np.swapaxes(E, -1, -2)
        X = np.zeros((len(E), 6, 6))
        X[:, :3, :3] = Et
        X[:, 3:, 3:] = Et
        X[:, 3:, :3] = -Et @ _skew(r)
        xs.append(X)
    return xs


def _subspaces(mdl: NumericModel) -> np.ndarray:
    """Motion subspaces S_i (n,6) in body coordinates: [axis; 0] revolute, [0; axis] prismatic."""
    S = np.zeros((mdl.n, 6))
    S[mdl.revolute, :3] = mdl.axis[mdl.revolute]
    S[~mdl.revolute, 3:] = mdl.axis[~mdl.revolute]
    return S


def _crm(v: np.ndarray) -> np.ndarray:
    """Spatial motion cross product matrix v x = [[w x, 0], [v_O x, w x]] for v (N,6)."""
    W, V = _skew(v[:, :3]), _skew(v[:, 3:])
    out = np.zeros((len(v), 6, 6))
    out[:, :3, :3] = W
    out[:, 3:, 3:] = W
    out[:, 3:, :3] = V
    return out


def _mv(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("...ij,...j->...i", A, x)


def _rnea(mdl, q, qd, qdd, g_on: bool, f_on: bool) -> np.ndarray:
    """Spatial RNEA on a batch (all arguments (N, n)); see `rnea`."""
    N, n = q.shape
    X = _motion_transforms(_joint_poses(mdl, q))
    S = _subspaces(mdl)
    v = np.zeros((N, 6))
    a = np.zeros((N, 6))
    if g_on:
        a[:, 3:] = -mdl.gravity  # fictitious base acceleration a_0 = [0; -g]
    forces = []
    for i in range(n):
        v = _mv(X[i], v) + S[i] * qd[:, i, None]
        vx = _crm(v)
        a = _mv(X[i], a) + S[i] * qdd[:, i, None] + _mv(vx, S[i]) * qd[:, i, None]
        Iv = _mv(mdl.spatial_inertia[i], v)
        # f = I a + v x* (I v), with v x* = -(v x)^T the force cross product.
        forces.append(_mv(mdl.spatial_inertia[i], a) - _mv(np.swapaxes(vx, -1, -2), Iv))
    tau = np.zeros((N, n))
    for i in reversed(range(n)):
        tau[:, i] = forces[i] @ S[i]
        if i > 0:
            forces[i - 1] = forces[i - 1] + _mv(np.swapaxes(X[i], -1, -2), forces[i])
    tau += mdl.reflected * qdd
    if f_on:
        tau += mdl.viscous * qd + mdl.coulomb * np.sign(qd)
    return tau


def rnea(robot, q, qd, qdd, params=None, *, gravity=True, friction=True) -> np.ndarray:
    """Inverse dynamics tau = M(q) qdd + V(q, qd) + G(q) + F(qd), by the spatial RNEA.

    Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 5.3; the lecture's 3-vector form
    is R. Grupen, "Dynamics" (2015), slides 14-15 (symdyn.algorithms.newton_euler).
    Body frames, spatial vectors at each body origin. Outward: v_i = X_i v_{i-1} + S_i qd_i,
    a_i = X_i a_{i-1} + S_i qdd_i + v_i x S_i qd_i, from v_0 = 0 and a_0 = [0; -g] (gravity
    in the base frame; a_0 = 0 with gravity=False); body force f_i = I_i a_i + v_i x* I_i v_i.
    Inward: tau_i = S_i^T f_i, f_{i-1} += X_i^T f_i. Then tau_i += gear_ratio^2 J_m qdd_i
    (reflected rotor inertia) and, unless friction=False, viscous qd_i + coulomb sign(qd_i).

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd, qdd: joint positions, velocities, accelerations: (n,) each, or (N, n) each for
            N states.
        params: the free parameters' values (see `numeric_model`).
        gravity, friction: include gravity, resp. joint friction.

    Returns:
        Joint efforts tau, (n,) or (N, n).

    Raises:
        SymdynError: a vector of the wrong shape or not numeric, or bad parameter values.
    """
    mdl, (q, qd, qdd), single = _inputs("rnea", robot, params, ("q", q), ("qd", qd), ("qdd", qdd))
    return _out(_rnea(mdl, q, qd, qdd, gravity, friction), single)


def _mass_matrix(mdl: NumericModel, q: np.ndarray) -> np.ndarray:
    """M for a batch q (N, n) -> (N, n, n); see `mass_matrix`."""
    N, n = q.shape
    X = _motion_transforms(_joint_poses(mdl, q))
    S = _subspaces(mdl)
    Ic = [np.broadcast_to(mdl.spatial_inertia[i], (N, 6, 6)).copy() for i in range(n)]
    M = np.zeros((N, n, n))
    for i in reversed(range(n)):
        if i > 0:
            Ic[i - 1] += np.swapaxes(X[i], -1, -2) @ Ic[i] @ X[i]
        F = Ic[i] @ S[i]
        M[:, i, i] = F @ S[i] + mdl.reflected[i]
        for j in range(i, 0, -1):
            F = _mv(np.swapaxes(X[j], -1, -2), F)
            M[:, i, j - 1] = M[:, j - 1, i] = F @ S[j - 1]
    return M


def mass_matrix(robot, q, params=None) -> np.ndarray:
    """Joint-space inertia M(q) by the composite-rigid-body algorithm (body frames).

    Featherstone (2008), sec. 6.2. Composite inertias Ic_{i-1} += X_i^T Ic_i X_i (inward);
    F = Ic_i S_i, M_ii = S_i^T F, and for j < i, M_ij = M_ji = S_j^T (X_{j+1}^T ... X_i^T F).
    The diagonal also gets the reflected rotor inertia gear_ratio^2 J_m.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        M, (n, n) or (N, n, n).
    """
    mdl, (q,), single = _inputs("mass_matrix", robot, params, ("q", q))
    return _out(_mass_matrix(mdl, q), single)


def gravity_torque(robot, q, params=None) -> np.ndarray:
    """G(q) = rnea(q, 0, 0) without friction: the joint efforts that hold the arm still.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        G, (n,) or (N, n).
    """
    mdl, (q,), single = _inputs("gravity_torque", robot, params, ("q", q))
    z = np.zeros_like(q)
    return _out(_rnea(mdl, q, z, z, True, False), single)


def bias_torque(robot, q, qd, params=None) -> np.ndarray:
    """V(q, qd) = rnea(q, qd, 0) with gravity and friction off: Coriolis and centrifugal terms.

    (Not the "bias" V + G + F of `symdyn.Dynamics`.)

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd: (n,) each, or (N, n) each.
        params: the free parameters' values (see `numeric_model`).

    Returns:
        V, (n,) or (N, n).
    """
    mdl, (q, qd), single = _inputs("bias_torque", robot, params, ("q", q), ("qd", qd))
    return _out(_rnea(mdl, q, qd, np.zeros_like(q), False, False), single)


def friction_torque(robot, qd, params=None) -> np.ndarray:
    """F(qd)_i = viscous_i qd_i + coulomb_i sign(qd_i) (joint space; sign(0) = 0).

    Args:
        robot: a `symdyn.Robot` with n joints.
        qd: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        F, (n,) or (N, n).
    """
    mdl, (qd,), single = _inputs("friction_torque", robot, params, ("qd", qd))
    return _out(mdl.viscous * qd + mdl.coulomb * np.sign(qd), single)


def forward_dynamics(robot, q, qd, tau, params=None) -> np.ndarray:
    """qdd solving M(q) qdd = tau - V(q, qd) - G(q) - F(qd) (numpy.linalg.solve, joint space).

    V + G + F comes from one RNEA pass with qdd = 0, M from the CRBA.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd, tau: (n,) each, or (N, n) each.
        params: the free parameters' values (see `numeric_model`).

    Returns:
        qdd, (n,) or (N, n).
    """
    mdl, (q, qd, tau), single = _inputs("forward_dynamics", robot, params, ("q", q), ("qd", qd), ("tau", tau))
    h = _rnea(mdl, q, qd, np.zeros_like(q), True, True)
    M = _mass_matrix(mdl, q)
    return _out(np.linalg.solve(M, (tau - h)[..., None])[..., 0], single)


def kinetic_energy(robot, q, qd, params=None) -> float | np.ndarray:
    """T = sum_i 1/2 v_i^T I_i v_i + 1/2 gear_ratio_i^2 J_m,i qd_i^2 (= 1/2 qd^T M qd).

    v_i is the spatial velocity of body i and I_i its spatial inertia, both in body i's frame
    at its origin.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd: (n,) each, or (N, n) each.
        params: the free parameters' values (see `numeric_model`).

    Returns:
        T, a float or (N,).
    """
    mdl, (q, qd), single = _inputs("kinetic_energy", robot, params, ("q", q), ("qd", qd))
    X = _motion_transforms(_joint_poses(mdl, q))
    S = _subspaces(mdl)
    v = np.zeros((len(q), 6))
    T = 0.5 * (mdl.reflected * qd**2).sum(axis=1)
    for i in range(mdl.n):
        v = _mv(X[i], v) + S[i] * qd[:, i, None]
        T = T + 0.5 * np.einsum("ni,ij,nj->n", v, mdl.spatial_inertia[i], v)
    return float(T[0]) if single else T


def _poses(mdl: NumericModel, q: np.ndarray) -> list[np.ndarray]:
    """Base-frame poses base_T_i (N,4,4), composed from the joint transforms."""
    N = len(q)
    T = np.broadcast_to(np.eye(4), (N, 4, 4))
    out = []
    for E, r in _joint_poses(mdl, q):
        J = np.zeros((N, 4, 4))
        J[:, :3, :3], J[:, :3, 3], J[:, 3, 3] = E, r, 1.0
        T = T @ J
        out.append(T)
    return out


def forward_kinematics(robot, q, params=None) -> list[np.ndarray]:
    """The 4x4 pose base_T_i = prod_k parent_T_k(q_k) of every body frame, in the base frame.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        A list of n arrays (4, 4), or (N, 4, 4) for a batch.
    """
    mdl, (q,), single = _inputs("forward_kinematics", robot, params, ("q", q))
    return [_out(T, single) for T in _poses(mdl, q)]


def _com_positions(mdl: NumericModel, q: np.ndarray) -> np.ndarray:
    """Centres of mass in the base frame for a batch q (N, n) -> (N, n, 3)."""
    Ts = _poses(mdl, q)
    return np.stack([_mv(T[:, :3, :3], mdl.com[i]) + T[:, :3, 3] for i, T in enumerate(Ts)], 1)


def link_com_positions(robot, q, params=None) -> np.ndarray:
    """Centres of mass in the base frame, p_ci = base_R_i com_i + base_p_i.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        (n, 3), or (N, n, 3) for a batch.
    """
    mdl, (q,), single = _inputs("link_com_positions", robot, params, ("q", q))
    return _out(_com_positions(mdl, q), single)


def potential_energy(robot, q, params=None) -> float | np.ndarray:
    """U = -sum_i m_i g^T p_ci, gravity g and centres of mass p_ci in the base frame.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        U, a float or (N,).
    """
    mdl, (q,), single = _inputs("potential_energy", robot, params, ("q", q))
    U = -np.einsum("i,nij,j->n", mdl.mass, _com_positions(mdl, q), mdl.gravity)
    return float(U[0]) if single else U


class _CallableModule(types.ModuleType):
    """`symdyn.rnea` is both this module and the public function symdyn.rnea(robot, q, qd, qdd)."""

    def __call__(self, robot, q, qd, qdd, params=None, **kwargs):
        return rnea(robot, q, qd, qdd, params, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
