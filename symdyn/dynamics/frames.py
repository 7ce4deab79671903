"""The frame and task-space facade of a derivation: poses, Jacobians, centre of mass, operational space.

`Dynamics.frame_pose`, `frame_jacobian`, `com`, `operational_space_inertia` and the others
(symdyn.dynamics.joint_space) come from `FrameFacade`: closed forms over q (and qd) when no state
is given, else numbers at the state, from the frame kinematics over a copy of the derivation's
program (symdyn.algorithms.frame_kinematics; on a floating base symdyn.algorithms.floating_frames
and the centroidal quantities), and the operational-space quantities built on M and the bias
(symdyn.algorithms.operational_space). docs/frames.md.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..algorithms.centroidal import Centroidal
from ..algorithms.floating_frames import FloatingFrames
from ..algorithms.frame_kinematics import FrameKinematics
from ..algorithms.operational_space import operational_space, task_rows
from ..algorithms.tip_wrench import tip_wrench_torque
from ..errors import SymdynError
from ..model.free_flyer import NQ_BASE, NV_BASE
from .numeric import program_function, state_vector
from .quantities import simplify_entry

__all__ = ["FrameFacade"]


class FrameFacade:
    """The frame and task-space methods of `Dynamics` (a mix-in: it reads the derivation's
    fields robot, q, qd, params, program, compact, simplified, n and the caches _compiled and
    _frames)."""

    def tip_wrench_torque(self, F, q=None, params=None):
        """J_b(q)^T F: the joint torques balancing a wrench F = [m; f] that the end effector
        applies to its environment, in the end-effector frame (Modern Robotics' F_tip;
        symdyn.algorithms.tip_wrench). Add it to tau for MR's InverseDynamics.

        On a floating base J_b has the base's six columns too, and the six base rows are the
        wrench the tip wrench puts on the base (force, then moment about the base origin, base
        frame; symdyn.algorithms.tip_wrench).

        Returns:
            With q None: an n x 1 (NV x 1) SymPy matrix over q (and F, if it holds symbols);
            with q (n numbers; NQ on a floating base) and params: an (n,) ((NV,)) array.
        """
        if q is None:
            return tip_wrench_torque(self.robot, F, list(self.q))
        where = "Dynamics.tip_wrench_torque"
        if self.robot.floating:
            q = state_vector(q, self.robot.nq, "q", where)
        else:
            q = self.robot.joint_values(q, "q", where)
        self.robot.param_values(params, where)
        robot = self.robot.numeric(params)
        return np.asarray(tip_wrench_torque(robot, F, [float(x) for x in q]), dtype=float)[:, 0]

    # -- frames and task space (docs/frames.md; symdyn.algorithms.frame_kinematics)
    @property
    def frames(self) -> FrameKinematics | FloatingFrames:
        """The frame quantities over named intermediates of a copy of `program` (intermediates
        `_F...`), shared by the methods below; of a floating robot over q (NQ) and qd (NV), the
        Jacobians 6 x NV with the base's columns (symdyn.algorithms.floating_frames)."""
        if self._frames is None:
            r, q, qd, prog = self.robot, list(self.q), list(self.qd), self.program.copy("F")
            if r.floating:  # the base's coordinates first (symdyn.algorithms.floating_frames)
                joints, rates = q[NQ_BASE:], qd[NV_BASE:]
                cen = Centroidal(r, joints, rates, prog, q[:NQ_BASE], qd[:NV_BASE])
                self._frames = FloatingFrames(FrameKinematics(r, joints, rates, prog), cen)
            else:
                self._frames = FrameKinematics(r, q, qd, prog)
        return self._frames

    def _frame_value(self, key: tuple, m: sp.Matrix, q, qd, params, where: str):
        """m's closed form (q None) or its numbers at (q, qd, params) (lambdified once per key)."""
        if q is None:
            entries = self.frames.program.expand(list(m))
            if self.simplified:
                entries = [simplify_entry(e) for e in entries]
            return sp.ImmutableMatrix(m.rows, m.cols, entries)
        f = self._compiled.get(key)
        if f is None:
            steps = self.frames.program.needed(list(m))
            args = [list(self.q), list(self.qd), list(self.params)]
            f = self._compiled[key] = program_function(self._compiled, args, m, steps)
        if self.robot.floating:
            vq = state_vector(q, self.robot.nq, "q", where)
            vqd = state_vector(qd, self.robot.nv, "qd", where)
        else:
            vq = self.robot.joint_values(q, "q", where)
            vqd = self.robot.joint_values(qd, "qd", where)
        values = self.robot.param_values(params, where)
        out = np.asarray(f(vq, vqd, [values[s] for s in self.params]), dtype=float).reshape(m.shape)
        return out[:, 0] if m.cols == 1 else out

    def frame_pose(self, frame: str, q=None, params=None):
        """world_T_F (4 x 4) of frame `frame` (a link's or one of Robot.frames): closed form over
        q with q None, else an array at q."""
        m = self.frames.pose(frame)
        return self._frame_value(("pose", frame), m, q, None, params, "Dynamics.frame_pose")

    def frame_jacobian(self, frame: str, reference: str = "world", q=None, params=None):
        """J (6 x n), rows v_x v_y v_z w_x w_y w_z, of F's origin: world-aligned ("world",
        Pinocchio's LOCAL_WORLD_ALIGNED) or in F's own axes ("local", LOCAL)."""
        if reference not in ("world", "local"):
            raise SymdynError(
                f"Dynamics.frame_jacobian: reference must be 'world' or 'local', got {reference!r}"
            )
        m = self.frames.jacobian(frame, reference)
        return self._frame_value((reference, frame), m, q, None, params, "Dynamics.frame_jacobian")

    def frame_jacobian_dot_qd(self, frame: str, q=None, qd=None, params=None):
        """Jdot qd (6): F's origin's classical acceleration and F's angular acceleration at
        qdd = 0, world-aligned (Pinocchio's getFrameClassicalAcceleration, LOCAL_WORLD_ALIGNED)."""
        m = self.frames.jacobian_dot_qd(frame)
        return self._frame_value(("drift", frame), m, q, qd, params, "Dynamics.frame_jacobian_dot_qd")

    def com(self, q=None, params=None):
        """The centre of mass c(q) (3), world frame."""
        return self._frame_value(("com",), self.frames.com(), q, None, params, "Dynamics.com")

    def com_jacobian(self, q=None, params=None):
        """Jc (3 x n), world frame: dc/dt = Jc qd."""
        return self._frame_value(
            ("Jc",), self.frames.com_jacobian(), q, None, params, "Dynamics.com_jacobian"
        )

    def com_jacobian_dot_qd(self, q=None, qd=None, params=None):
        """Jc_dot qd (3), world frame: the centre of mass's acceleration at qdd = 0."""
        m = self.frames.com_jacobian_dot_qd()
        return self._frame_value(("Jcd",), m, q, qd, params, "Dynamics.com_jacobian_dot_qd")

    def _operational(self, frame: str, axes, where: str):
        rows = task_rows(axes, where)
        key = ("os", frame, rows)
        if key not in self._compiled:
            fk = self.frames
            J = fk.jacobian(frame, "world")
            os = operational_space(
                self.compact["M"],
                J.extract(list(rows), list(range(self.n))),
                self.compact["bias"],
                fk.jacobian_dot_qd(frame).extract(list(rows), [0]),
                self.robot.is_chain and not self.robot.floating,
                fk.program,
            )
            self._compiled[key] = os
        return key, self._compiled[key]

    def operational_space_inertia(self, frame: str, q, axes=None, params=None) -> np.ndarray:
        """Lambda = (J M^-1 J^T)^-1 (k x k) at q, J the world-aligned Jacobian's rows `axes`
        (any of x, y, z, rx, ry, rz; default all six); symdyn.algorithms.operational_space."""
        key, os = self._operational(frame, axes, "Dynamics.operational_space_inertia")
        return self._frame_value(
            (*key, "L"), os.inertia, q, None, params, "Dynamics.operational_space_inertia"
        )

    def operational_space_bias(self, frame: str, q, qd=None, axes=None, params=None) -> np.ndarray:
        """mu + p = Lambda (J M^-1 (V + G + F) - Jdot qd) (k) at (q, qd)."""
        key, os = self._operational(frame, axes, "Dynamics.operational_space_bias")
        return self._frame_value((*key, "b"), os.bias, q, qd, params, "Dynamics.operational_space_bias")

    def dynamically_consistent_inverse(self, frame: str, q, axes=None, params=None) -> np.ndarray:
        """Jbar = M^-1 J^T Lambda (n x k) at q."""
        key, os = self._operational(frame, axes, "Dynamics.dynamically_consistent_inverse")
        return self._frame_value(
            (*key, "B"), os.inverse, q, None, params, "Dynamics.dynamically_consistent_inverse"
        )
