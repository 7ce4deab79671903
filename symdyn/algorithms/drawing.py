"""The geometry of a robot's drawing at a configuration q (symdyn.model.scene), in numbers.

The joint model of symdyn.model.robot evaluated with NumPy, once the robot's parameters are
substituted (Robot.numeric): along the tree, body frame i in the world is

    world_T_i(q) = world_T_lambda(i) placement_i Rot(axis_i, q_i)     (revolute)
    world_T_i(q) = world_T_lambda(i) placement_i Trans(axis_i q_i)    (prismatic)

from world_T_base = Robot.base (fixed base) or, on a floating robot, the free flyer's pose
q[:7] = (x, y, z, qx, qy, qz, qw) (symdyn.model.free_flyer; the quaternion normalised), at the
body positions q_b of the mimic rule. A frame F on link k (its convention frame Link.frame, a
named frame, a contact, a loop's closure point) is world_T_k k_T_F. A DH robot's rows are read
back from consecutive DH frames (symdyn.model.scene.DHMark has the two conventions), so the
picture shows the table the robot really has, not the one the file meant.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..errors import SymdynError
from ..model.scene import DHMark, FrameMarker, JointMarker, MassMarker, Scene, Segment

__all__ = ["scene", "scene_function", "default_configuration"]

#: The farthest a drawn point may be from the world's origin (m): beyond, a picture's arithmetic
#: overflows.
FAR = 1e12
#: Residual below which a relative transform counts as a DH row (the frames of a DH file are
#: exact up to rounding).
_DH_TOLERANCE = 1e-9


def _array(expr, shape, what: str) -> np.ndarray:
    try:
        a = np.array(np.asarray(expr).tolist(), dtype=float).reshape(shape)
    except (TypeError, ValueError):
        raise SymdynError(f"draw: {what} is not a number after substituting the parameters") from None
    if not np.isfinite(a).all():
        raise SymdynError(f"draw: {what} is not finite")
    return a


def _homogeneous(T, what: str) -> np.ndarray:
    H = np.eye(4)
    H[:3, :3] = _array(T.R, (3, 3), what)
    H[:3, 3] = _array(T.p, (3,), what)
    return H


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues: exp(angle [axis]x) for a unit axis."""
    x, y, z = axis
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def _contacts(robot) -> list[tuple[str, int, np.ndarray]]:
    """(name, link, k_T_C) of each contact the model has: a Robot.contacts entry at a named frame
    (symdyn.model.contacts.Contact: Robot.frame gives its link and placement), or an object with a
    link index and a placement Transform or a point in the link's body frame."""
    out = []
    for c in getattr(robot, "contacts", ()) or ():
        name = str(getattr(c, "name", "contact"))
        if isinstance(getattr(c, "frame", None), str):
            f = robot.frame(c.frame, f"contact '{name}'")
            out.append((name, f.link, _homogeneous(f.placement, f"contact '{name}' frame")))
            continue
        link = int(getattr(c, "link", -1))
        placement = getattr(c, "placement", None)
        if placement is not None:
            H = _homogeneous(placement, f"contact '{name}' placement")
        else:
            H = np.eye(4)
            H[:3, 3] = _array(getattr(c, "point", (0, 0, 0)), (3,), f"contact '{name}' point")
        out.append((name, link, H))
    return out


def default_configuration(robot) -> np.ndarray:
    """q = 0 (a floating robot: its base at the origin, the identity quaternion)."""
    q = np.zeros(robot.nq)
    if robot.floating:
        q[6] = 1.0
    return q


class _Geometry:
    """The robot's constant numbers (placements, axes, frames, masses) and the scene at any q."""

    def __init__(self, robot, params=None) -> None:
        r = robot.numeric(params)
        self.robot = r
        links = r.links
        self.names = [lk.name for lk in links]
        self.parents = list(r.parents)
        self.revolute = [lk.joint == "revolute" for lk in links]
        self.placement = [_homogeneous(lk.placement, f"link '{lk.name}' placement") for lk in links]
        self.axis = [_array(lk.axis, (3,), f"link '{lk.name}' axis") for lk in links]
        self.link_frame = [_homogeneous(lk.frame, f"link '{lk.name}' frame") for lk in links]
        self.mass = [float(_array(lk.mass, (), f"link '{lk.name}' mass")) for lk in links]
        self.com = [_array(lk.com, (3,), f"link '{lk.name}' com") for lk in links]
        self.frames = [(f.name, f.link, _homogeneous(f.placement, f"frame '{f.name}'")) for f in r.frames]
        self.contacts = _contacts(r)
        self.loops = [
            (lp.link, _array(lp.point, (3,), f"loop '{lp.name}'"), lp.to, _array(lp.to_point, (3,), "loop"))
            for lp in r.loops
        ]
        self.base = _homogeneous(r.base, "the base placement")
        self.coordinates = [(c.index, float(c.multiplier), float(c.offset)) for c in r.coordinates]
        self.dh = r.convention if r.convention in ("standard", "modified") else None

    def configuration(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(world_T_base, q_b): q checked (nq numbers, finite; a non-zero quaternion)."""
        r = self.robot
        try:
            a = np.asarray(q, dtype=float)
        except (TypeError, ValueError):
            raise SymdynError(f"draw: q must hold numbers, got {q!r}") from None
        if a.ndim != 1 or a.size != r.nq:
            what = " (x y z qx qy qz qw and the joints)" if r.floating else " (one per joint)"
            raise SymdynError(f"draw: q has shape {a.shape}, expected ({r.nq},){what}")
        if not np.isfinite(a).all():
            raise SymdynError("draw: q is not finite")
        base = self.base
        if r.floating:
            quat = a[3:7]
            norm = float(np.linalg.norm(quat))
            if not norm > 1e-12:
                raise SymdynError("draw: the base quaternion q[3:7] is zero")
            qx, qy, qz, qw = quat / norm
            base = np.eye(4)
            base[:3, :3] = [
                [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
                [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
                [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)],
            ]
            base[:3, 3] = a[:3]
            a = a[7:]
        qb = np.array([m * a[k] + o for k, m, o in self.coordinates])
        return base, qb

    def bodies(self, base: np.ndarray, qb: np.ndarray) -> list[np.ndarray]:
        """world_T_i of every body (module docstring)."""
        out: list[np.ndarray] = []
        for i, (P, axis) in enumerate(zip(self.placement, self.axis, strict=True)):
            J = np.eye(4)
            if self.revolute[i]:
                J[:3, :3] = _rotation(axis, qb[i])
            else:
                J[:3, 3] = axis * qb[i]
            p = self.parents[i]
            out.append((out[p] if p >= 0 else base) @ P @ J)
        return out

    def scene(self, q) -> Scene:
        base, qb = self.configuration(q)
        with np.errstate(over="ignore", invalid="ignore"):  # a far configuration is refused below
            return self._scene(q, base, qb)

    def _scene(self, q, base: np.ndarray, qb: np.ndarray) -> Scene:
        T = self.bodies(base, qb)
        on = lambda k: base if k < 0 else T[k]  # noqa: E731  (the pose of link k, -1: the base)
        frames = [FrameMarker("base", "base", base[:3, 3].copy(), base[:3, :3].copy(), "0")]
        link_frames = [Ti @ F for Ti, F in zip(T, self.link_frame, strict=True)]
        for i, F in enumerate(link_frames):
            frames.append(FrameMarker(self.names[i], "link", F[:3, 3], F[:3, :3], str(i + 1)))
        for name, k, H in self.frames:
            F = on(k) @ H
            frames.append(FrameMarker(name, "frame", F[:3, 3], F[:3, :3], name))
        for name, k, H in self.contacts:
            F = on(k) @ H
            frames.append(FrameMarker(name, "contact", F[:3, 3], F[:3, :3], name))
        joints = [
            JointMarker(
                self.names[i], "revolute" if self.revolute[i] else "prismatic", Ti[:3, 3], Ti[:3, :3] @ a
            )
            for i, (Ti, a) in enumerate(zip(T, self.axis, strict=True))
        ]
        segments = []
        for i, Ti in enumerate(T):
            segments.append(Segment(on(self.parents[i])[:3, 3], Ti[:3, 3]))
            if not np.allclose(link_frames[i][:3, 3], Ti[:3, 3], atol=1e-12):
                segments.append(Segment(Ti[:3, 3], link_frames[i][:3, 3]))
        for f in frames:
            if f.kind == "frame":
                k = next(k for name, k, _ in self.frames if name == f.name)
                segments.append(Segment(on(k)[:3, 3], f.origin))
        for k, p, to, p_to in self.loops:
            a, b = on(k)[:3, :3] @ p + on(k)[:3, 3], on(to)[:3, :3] @ p_to + on(to)[:3, 3]
            segments += [Segment(on(k)[:3, 3], a), Segment(on(to)[:3, 3], b), Segment(a, b, "loop")]
        masses = [
            MassMarker(self.names[i], Ti[:3, :3] @ c + Ti[:3, 3], m)
            for i, (Ti, c, m) in enumerate(zip(T, self.com, self.mass, strict=True))
        ]
        dh = self._dh(base, link_frames)
        pts = np.array([f.origin for f in frames] + [s.end for s in segments] + [m.position for m in masses])
        if not (np.isfinite(pts).all() and np.abs(pts).max() < FAR):
            raise SymdynError(f"draw: the robot reaches beyond {FAR:g} m (or is not finite) at this q")
        size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))) if len(pts) else 0.0
        scale = 0.12 * size if size > 1e-9 else 0.1
        q_all = np.asarray(q, dtype=float).copy()
        return Scene(
            self.robot.name, q_all, tuple(frames), tuple(joints), tuple(segments), tuple(masses), dh, scale
        )

    def _dh(self, base: np.ndarray, link_frames: list[np.ndarray]) -> tuple[DHMark, ...]:
        """The DH rows read back from consecutive DH frames (DHMark), where they fit a row exactly."""
        if self.dh is None:
            return ()
        out = []
        for i, F in enumerate(link_frames):
            p = self.parents[i]
            Fp = base if p < 0 else link_frames[p]
            rel = np.linalg.inv(Fp) @ F
            row = _standard_row(rel) if self.dh == "standard" else _modified_row(rel)
            if row is None:
                continue
            a, d, alpha, theta = (0.0 if abs(v) < 1e-12 else v for v in row)  # rounding, not geometry
            foot = Fp[:3, 3] + d * Fp[:3, 2] if self.dh == "standard" else Fp[:3, 3] + a * Fp[:3, 0]
            out.append(DHMark(i + 1, self.dh, a, d, alpha, theta, Fp[:3, 3], foot, F[:3, 3]))
        return tuple(out)


def _standard_row(T: np.ndarray) -> tuple[float, float, float, float] | None:
    """(a, d, alpha, theta) of T = Rz(theta) Tz(d) Tx(a) Rx(alpha), or None when T is no such row:
    theta = atan2(T10, T00), alpha = atan2(T21, T22), d = T23, a = T03 cos(theta) + T13 sin(theta)."""
    theta, alpha = math.atan2(T[1, 0], T[0, 0]), math.atan2(T[2, 1], T[2, 2])
    a, d = T[0, 3] * math.cos(theta) + T[1, 3] * math.sin(theta), T[2, 3]
    if (
        abs(T[2, 0]) > _DH_TOLERANCE
        or abs(T[1, 3] * math.cos(theta) - T[0, 3] * math.sin(theta)) > _DH_TOLERANCE
    ):
        return None
    return a, d, alpha, theta


def _modified_row(T: np.ndarray) -> tuple[float, float, float, float] | None:
    """(a, d, alpha, theta) of T = Rx(alpha) Tx(a) Rz(theta) Tz(d), or None when T is no such row:
    alpha = atan2(-T12, T22), theta = atan2(-T01, T00), a = T03, d = -T13 sin(alpha) + T23 cos(alpha)."""
    alpha, theta = math.atan2(-T[1, 2], T[2, 2]), math.atan2(-T[0, 1], T[0, 0])
    sa, ca = math.sin(alpha), math.cos(alpha)
    a, d = T[0, 3], -T[1, 3] * sa + T[2, 3] * ca
    if abs(T[0, 2]) > _DH_TOLERANCE or abs(T[1, 3] * ca + T[2, 3] * sa) > _DH_TOLERANCE:
        return None
    return a, d, alpha, theta


def scene_function(robot, params=None) -> Callable[[object], Scene]:
    """q -> Scene of `robot` with its free parameters' values `params` (Robot.param_values), the
    constant numbers computed once (for the frames of an animation).

    Raises:
        SymdynError: missing parameter values, a robot that is not a symdyn Robot.
    """
    if not all(hasattr(robot, a) for a in ("links", "numeric", "nq")):
        raise SymdynError(f"draw: robot must be a symdyn Robot, got {type(robot).__name__}")
    robot.param_values(params, "draw")  # refuses missing or extra values, naming them
    return _Geometry(robot, params).scene


def scene(robot, q=None, params=None) -> Scene:
    """The drawing of `robot` at q (None: `default_configuration`), world frame (module docstring).

    Raises:
        SymdynError: q of the wrong length or not finite, missing parameter values.
    """
    make = scene_function(robot, params)
    return make(default_configuration(robot) if q is None else q)
