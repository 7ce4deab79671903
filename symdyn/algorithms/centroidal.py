"""Centroidal quantities, symbolic: the total mass, the centre of mass with its Jacobian, the
centroidal momentum matrix A_g and its drift Adot_g v, for a floating or a fixed base.

The centroidal momentum h_g = A_g v (6, Pinocchio's computeCentroidalMap) is the linear
momentum of the whole robot, then its angular momentum about the centre of mass c, both in
world-aligned axes (Orin, Goswami and Lee, Centroidal dynamics of a humanoid robot, Auton.
Robots 35 (2013)). v is the velocity of symdyn.model.free_flyer on a floating base (base twist
in the base frame, then the joint rates: NV columns), the joint rates on a fixed one (n).

Everything is computed in the base frame (body i's frame at base_T_i(q), forward_kinematics),
then turned into the world by world_R_base (the base quaternion's quaternion_rotation on a
floating base, Robot.base's rotation on a fixed one):

1. Per body (the links, and the base body of a floating robot): mass m_i, centre of mass c_i
   and rotational inertia I_i about c_i in base axes (R_i I_i R_i^T).
2. Composite sums over each subtree s(i) from the leaves (Featherstone (2008), sec. 6.2, on the
   moments instead of the 6 x 6 inertia): m_s, the first moment h_s = sum m_k c_k and the
   rotational inertia about the base origin J_s = sum I_k - m_k [c_k]x^2; their totals over the
   whole robot m, h and J, and c_b = h / m.
3. The momentum of a unit rate of each coordinate, about the base origin in base axes: a
   revolute joint of axis z through o moves its subtree with angular velocity z about o,

       P = z x (h_s - m_s o),   L_O = J_s z - h_s x (z x o);

   a prismatic joint: P = m_s z, L_O = h_s x z; the base's linear velocity e_k: P = m e_k,
   L_O = h x e_k; its angular velocity e_k: P = e_k x h, L_O = J e_k. About the centre of mass,
   L_G = L_O - c_b x P; a mimic joint's column adds to its coordinate's (A = A_body S).
   A_g does not use steps 1 and 2: (P, L_O) of joint j is the spatial force I^c_j S_j of its
   subtree's composite inertia, built in the links' own frames (symdyn.algorithms.crba), and
   (m, h, J) the whole robot's composite about the base origin (A_g is M[0:6] moved to the
   centre of mass: Orin, Goswami and Lee (2013)). Each column goes in one step from link j's
   frame to the centre of mass with world axes, through link j's world-aligned frame composed
   from the base (`Centroidal.momentum_matrix`).
4. A_g = blockdiag(R, R) [P; L_G] (world_R_base R), c = p_base + R c_b, and the centre of
   mass's Jacobian Jc = A_g[0:3] / m (linear momentum = m dc/dt).

The drift Adot_g v (the rate of h_g at vdot = 0, Pinocchio's dAg v) is computed in the inertial
frame that coincides with the base frame at this instant: the base has angular velocity w_b,
origin velocity v_b, classical origin acceleration w_b x v_b and no angular acceleration
(vdot = 0 is a constant body twist); then for each body, d = o_i - o_parent, z its joint axis,

    w_i = w_p + z qd_i,  wd_i = wd_p + w_p x z qd_i,  v_i = v_p + w_p x d      (revolute)
    w_i = w_p,  wd_i = wd_p,  v_i = v_p + w_p x d + z qd_i                     (prismatic)
    a_i = a_p + wd_p x d + w_p x (w_p x d)  [+ 2 w_p x z qd_i, prismatic]
    a_ci = a_i + wd_i x r_i + w_i x (w_i x r_i),   r_i = c_i - o_i,

    Adot_g v = blockdiag(R, R) sum_i [m_i a_ci; (c_i - c_b) x m_i a_ci + w_i x I_i w_i + I_i wd_i]

(the rate of sum (c_i - c) x m_i v_ci + I_i w_i: the terms (v_ci - dc/dt) x m_i v_ci sum to 0).
Every vector and matrix entry is a named intermediate of the given Program.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.free_flyer import quaternion_rotation
from ..model.robot import Robot
from ..spatial import vectors as v3
from ..spatial.inertia import SpatialInertia, apply_inertia, body_inertia
from ..symbolic.program import Program
from .crba import composite_inertias, link_subspace, shift_inertia
from .frames import joint_frames
from .kinematics import forward_kinematics

__all__ = ["Centroidal"]


def _rows(M) -> v3.Mat:
    return tuple(tuple(M[i, j] for j in range(3)) for i in range(3))  # type: ignore[return-value]


def _transpose(M: v3.Mat) -> v3.Mat:
    return tuple(tuple(M[j][i] for j in range(3)) for i in range(3))  # type: ignore[return-value]


def _matmul(A: v3.Mat, B: v3.Mat) -> v3.Mat:
    Bt = _transpose(B)
    return tuple(tuple(v3.dot(A[i], Bt[j]) for j in range(3)) for i in range(3))  # type: ignore[return-value]


def _about_origin(m, c: v3.Vec, I: v3.Mat) -> v3.Mat:
    """I - m [c]x^2 = I + m (|c|^2 1 - c c^T): the rotational inertia about the origin."""
    cc = v3.dot(c, c)
    return tuple(
        tuple(I[i][j] + m * ((cc if i == j else 0) - c[i] * c[j]) for j in range(3)) for i in range(3)
    )  # type: ignore[return-value]


class Centroidal:
    """The centroidal quantities of one robot over one Program (module docstring).

    Args:
        robot: the model with its valued parameters substituted (Robot.resolved()).
        q, qd: the n joint positions and rates (symbols or numbers).
        program: receives the named intermediates.
        base_q, base_v: on a floating robot the base's 7 configuration and 6 velocity
            coordinates (symdyn.model.free_flyer.base_symbols); None on a fixed base.
    """

    def __init__(
        self,
        robot: Robot,
        q: Sequence,
        qd: Sequence,
        program: Program,
        base_q: Sequence | None = None,
        base_v: Sequence | None = None,
    ) -> None:
        assert (base_q is not None) == robot.floating == (base_v is not None)
        self.robot, self.program = robot, program
        self.q, self.qd = list(q), list(qd)
        self.base_q = list(base_q) if base_q is not None else None
        self.base_v = list(base_v) if base_v is not None else None
        let = program.let_vector
        self.poses = forward_kinematics(robot, self.q, program)
        # 1. bodies in the base frame: (mass, c, I about c); the base body first when floating
        self.bodies: list[tuple[sp.Expr, v3.Vec, v3.Mat]] = []
        for i, (T, link) in enumerate(zip(self.poses, robot.links, strict=True)):
            R = _rows(T.R)
            c = let(T.apply(list(link.com)), f"cc{i + 1}_")
            inertia = _matmul(_matmul(R, _rows(link.inertia)), _transpose(R))
            I = program.let_symmetric(inertia, f"cI{i + 1}_")
            self.bodies.append((link.mass, c, I))
        b = robot.base_body
        self.base = (b.mass, v3.vec(list(b.com)), _rows(b.inertia)) if robot.floating else None
        # 2. composite moments, from the leaves
        nb = robot.nb
        m_s = [sp.S.Zero] * nb
        h_s: list[v3.Vec] = [v3.ZERO3] * nb
        J_s: list[v3.Mat] = [v3.ZERO33] * nb
        for i in reversed(range(nb)):
            m, c, I = self.bodies[i]
            ms, hs, Js = m_s[i] + m, v3.add(h_s[i], v3.scale(m, c)), _add33(J_s[i], _about_origin(m, c, I))
            m_s[i], h_s[i] = program.let(ms, f"cm{i + 1}_"), let(hs, f"ch{i + 1}_")
            J_s[i] = program.let_symmetric(Js, f"cJ{i + 1}_")
            p = robot.parents[i]
            if p >= 0:
                m_s[p], h_s[p], J_s[p] = m_s[p] + m_s[i], v3.add(h_s[p], h_s[i]), _add33(J_s[p], J_s[i])
        m, h, J = sp.S.Zero, v3.ZERO3, v3.ZERO33
        for i in (i for i in range(nb) if robot.parents[i] < 0):
            m, h, J = m + m_s[i], v3.add(h, h_s[i]), _add33(J, J_s[i])
        if self.base is not None:
            mb, cb, Ib = self.base
            m, h, J = m + mb, v3.add(h, v3.scale(mb, cb)), _add33(J, _about_origin(mb, cb, Ib))
        self.m_s, self.h_s, self.J_s = m_s, h_s, J_s
        self.mass = program.let(m, "cmt")
        self.h = let(h, "cht")
        self.J = program.let_symmetric(J, "cJt")
        inv = program.let(1 / self.mass, "cim")
        self.c_base = let(v3.scale(inv, self.h), "ccb")
        self._cache: dict[str, object] = {}

    # -- the rotation and the columns ------------------------------------------------------------

    @property
    def rotation(self) -> v3.Mat:
        """world_R_base (named entries on a floating base)."""
        if "R" not in self._cache:
            if self.base_q is None:
                R = self.robot.base.R
            else:
                R = quaternion_rotation(*self.base_q[3:7]).applyfunc(lambda x: self.program.let(x, "cR"))
            self._cache["R"] = sp.Matrix(R)
        return _rows(self._cache["R"])

    def composite(self) -> SpatialInertia:
        """The whole robot's composite inertia (m, h, J) about the base origin, base axes, by the
        local-frame recursion of symdyn.algorithms.crba (each link's composite in its own frame,
        moved once into its parent's), the base body included on a floating robot (memoised;
        the links' composites are kept for `momentum_matrix`)."""
        if "whole" not in self._cache:
            robot, program = self.robot, self.program
            frames = joint_frames(robot, robot.body_positions(self.q))
            composites = composite_inertias(robot, frames, program)
            if self.base is not None:
                mb, cb, Ib = self.base
                own = body_inertia(mb, cb, Ib)
                own = SpatialInertia(
                    own.mass,
                    program.let_vector(own.first_moment, "h"),
                    program.let_symmetric(own.inertia, "Io"),
                )
            else:
                own = SpatialInertia(sp.S.Zero, v3.ZERO3, v3.ZERO33)
            for child in (i for i in range(robot.nb) if robot.parents[i] < 0):
                own = shift_inertia(frames[child], composites[child], own, program, "c")
            self._cache["whole"], self._cache["links"] = own, (frames, composites)
        return self._cache["whole"]

    def _world_frames(self, frames) -> list[tuple[v3.Mat, v3.Vec]]:
        """(world_R_i, o_i) per link: its axes in the world and its origin from the base origin in
        world axes, composed from the root (world_R_base R_i on the base, then world_R_p R_i and
        o_p + world_R_p p_i: one joint rotation per link)."""
        let, R_wb = self.program.let, self.rotation
        out: list[tuple[v3.Mat, v3.Vec]] = []
        for i, frame in enumerate(frames):
            p = self.robot.parents[i]
            R_p, o_p = out[p] if p >= 0 else (R_wb, v3.ZERO3)
            R = _matmul(R_p, frame.R)
            R = tuple(tuple(let(x, "cRw") for x in row) for row in R)
            o = self.program.let_vector(v3.add(o_p, v3.mul(R_p, frame.p)), "cow")
            out.append((R, o))  # type: ignore[arg-type]
        return out

    def momentum_matrix(self) -> sp.Matrix:
        """A_g (6 x NV): h_g = A_g v, linear then angular momentum about c, world-aligned.

        Joint j's column is its composite's spatial force I^c_j S_j (symdyn.algorithms.crba, in
        frame j: n = I^c a, f = a x h^c for a revolute axis a, n = h^c x a, f = m^c a for a
        prismatic one) moved in one step to the centre of mass in world axes:
        P = world_R_j f, L_G = world_R_j n + (o_j - c) x P, with c - o_base = world_R_base c_b,
        c_b = h / m of the whole composite (Orin, Goswami and Lee (2013): A_g is the base rows of
        M moved to the centre of mass). The base's columns are the whole composite's: a unit
        linear velocity u = world_R_base e_k gives (m u, 0); a unit angular velocity gives
        P = world_R_base (e_k x h), L_G = world_R_base J_G e_k, J_G = J - m (|c_b|^2 1 - c_b c_b^T)
        the rotational inertia about the centre of mass (base axes). A mimic joint's column adds
        to its coordinate's (A = A_body S)."""
        if "Ag" not in self._cache:
            program, let_vector = self.program, self.program.let_vector
            whole = self.composite()
            frames, composites = self._cache["links"]  # type: ignore[misc]
            m, h, J = whole.mass, whole.first_moment, whole.inertia
            c_b = let_vector(v3.scale(program.let(1 / m, "cim"), h), "ccb")
            R_wb = self.rotation
            c_w = let_vector(v3.mul(R_wb, c_b), "ccw")
            body = []
            for (R, o), link, comp in zip(
                self._world_frames(frames), self.robot.links, composites, strict=True
            ):
                force = apply_inertia(comp, link_subspace(link))
                P = let_vector(v3.mul(R, force.linear), "cP")
                arm = v3.sub(o, c_w)
                body.append([*P, *v3.add(v3.mul(R, force.angular), v3.cross(arm, P))])
            S = self.robot.selection()
            cols = [
                [sum((S[i, j] * body[i][r] for i in range(self.robot.nb)), sp.S.Zero) for r in range(6)]
                for j in range(self.robot.n)
            ]
            if self.base is not None:
                J_G = _about_origin(-m, c_b, J)  # J - m (|c|^2 1 - c c^T)
                Rt = _transpose(R_wb)  # rows: the columns world_R_base e_k
                base_lin = [[*v3.scale(m, Rt[k]), 0, 0, 0] for k in range(3)]
                e = [tuple(sp.S.One if r == k else sp.S.Zero for r in range(3)) for k in range(3)]
                base_ang = [
                    [*v3.mul(R_wb, v3.cross(e[k], h)), *v3.mul(R_wb, tuple(J_G[r][k] for r in range(3)))]
                    for k in range(3)
                ]
                cols = base_lin + base_ang + cols
            self._cache["Ag"] = sp.Matrix(6, len(cols), lambda r, j: program.let(cols[j][r], "cAg"))
        return self._cache["Ag"]

    def _to_world(self, six: Sequence, hint: str) -> sp.Matrix:
        R = self.rotation
        out = [*v3.mul(R, tuple(six[:3])), *v3.mul(R, tuple(six[3:]))]
        return sp.Matrix(6, 1, [self.program.let(x, hint) for x in out])

    def com(self) -> sp.Matrix:
        """c (3 x 1), world frame: p_base + R c_b (Robot.base's origin on a fixed base)."""
        if "c" not in self._cache:
            p = self.base_q[:3] if self.base_q is not None else list(self.robot.base.p)
            Rc = v3.mul(self.rotation, self.c_base)
            self._cache["c"] = sp.Matrix(3, 1, [self.program.let(p[i] + Rc[i], "cc") for i in range(3)])
        return self._cache["c"]

    def com_jacobian(self) -> sp.Matrix:
        """Jc (3 x NV), world frame: dc/dt = Jc v (the linear rows of A_g over m)."""
        if "Jc" not in self._cache:
            inv = self.program.let(1 / self.mass, "cim")
            A = self.momentum_matrix()
            self._cache["Jc"] = A[:3, :].applyfunc(lambda x: self.program.let(x * inv, "cJc"))
        return self._cache["Jc"]

    # -- the drift -------------------------------------------------------------------------------

    def motions(self) -> list[tuple[v3.Vec, v3.Vec, v3.Vec, v3.Vec]]:
        """(w, wd, v, a) of every link's origin at vdot = 0, instantaneous base axes (memoised;
        `root` holds the base's)."""
        if "motions" in self._cache:
            return self._cache["motions"]
        let = self.program.let_vector
        if self.base_v is None:
            root = (v3.ZERO3, v3.ZERO3, v3.ZERO3, v3.ZERO3)
        else:
            v_b, w_b = tuple(self.base_v[:3]), tuple(self.base_v[3:])
            root = (w_b, v3.ZERO3, v_b, let(v3.cross(w_b, v_b), "cab"))
        rates = self.robot.body_rates(self.qd)
        out: list[tuple[v3.Vec, v3.Vec, v3.Vec, v3.Vec]] = []
        for i, (T, link) in enumerate(zip(self.poses, self.robot.links, strict=True)):
            p = self.robot.parents[i]
            w_p, wd_p, v_p, a_p = out[p] if p >= 0 else root
            o_p = v3.vec(list(self.poses[p].p)) if p >= 0 else v3.ZERO3
            d = v3.sub(v3.vec(list(T.p)), o_p)
            z = v3.mul(_rows(T.R), v3.vec(list(link.axis)))
            zq = v3.scale(rates[i], z)
            v = v3.add(v_p, v3.cross(w_p, d))
            a = v3.add(a_p, v3.cross(wd_p, d), v3.cross(w_p, v3.cross(w_p, d)))
            if link.joint == "revolute":
                w, wd = v3.add(w_p, zq), v3.add(wd_p, v3.cross(w_p, zq))
            else:
                w, wd = w_p, wd_p
                v, a = v3.add(v, zq), v3.add(a, v3.scale(2, v3.cross(w_p, zq)))
            tag = f"{i + 1}_"
            out.append((let(w, f"cw{tag}"), let(wd, f"cwd{tag}"), let(v, f"cv{tag}"), let(a, f"ca{tag}")))
        self.root = root
        self._cache["motions"] = out
        return out

    def drift(self) -> sp.Matrix:
        """Adot_g v (6 x 1), world-aligned: the rate of h_g at vdot = 0 (module docstring)."""
        if "drift" not in self._cache:
            motions = self.motions()
            origins = [v3.vec(list(T.p)) for T in self.poses]
            terms = list(zip(self.bodies, motions, origins, strict=True))
            if self.base is not None:
                terms.append((self.base, self.root, v3.ZERO3))
            lin, ang = v3.ZERO3, v3.ZERO3
            for (m, c, I), (w, wd, _, a), o in terms:
                if m == 0 and all(x == 0 for row in I for x in row):
                    continue
                r = v3.sub(c, o)
                a_c = v3.add(a, v3.cross(wd, r), v3.cross(w, v3.cross(w, r)))
                ma = self.program.let_vector(v3.scale(m, a_c), "cma")
                spin = v3.add(v3.cross(w, v3.mul(I, w)), v3.mul(I, wd))
                lin = v3.add(lin, ma)
                ang = v3.add(ang, v3.cross(v3.sub(c, self.c_base), ma), spin)
            self._cache["drift"] = self._to_world([*lin, *ang], "cdr")
        return self._cache["drift"]


def _add33(A: v3.Mat, B: v3.Mat) -> v3.Mat:
    return tuple(tuple(A[i][j] + B[i][j] for j in range(3)) for i in range(3))  # type: ignore[return-value]
