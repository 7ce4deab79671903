"""The frame methods of `symdyn.compile`'s CompiledDynamics (docs/python-api.md): poses,
Jacobians, drifts, the centre of mass and the operational space of named frames, from the
generated kinematics and operational_space functions (symdyn.codegen.frame_functions).

Each frame (and choice of task axes) has a compiled library of its own, built on first use
and cached like the robot's (CompiledDynamics.frame_functions); the methods here only pick
the generated function: frame F's functions are named after its identifier
(symdyn.codegen.frame_functions.frame_identifiers of F alone, as its library is built).
"""

from __future__ import annotations

from ...errors import SymdynError

__all__ = ["FrameMethods"]


class FrameMethods:
    """Mixed into CompiledDynamics, which provides frame_functions(frame, axes) and frame_names.

    q and qd are joint vectors (n,) or batches (B, n), as for every compiled method; outputs are
    world-aligned unless said otherwise (rows v_x v_y v_z w_x w_y w_z)."""

    def frame_functions(self, frame: str, group: str = "kinematics", axes=None):  # pragma: no cover
        raise NotImplementedError  # CompiledDynamics defines it

    def _function(self, frame: str, suffix: str, axes=None):
        from ...codegen.frame_functions import frame_identifiers  # not at import: a warm run loads no SymPy

        group = "operational_space" if suffix.startswith("operational") else "kinematics"
        ident = frame_identifiers([frame])[frame]
        return self.frame_functions(frame, group, axes).function(f"{ident}_{suffix}")

    def frame_pose(self, frame: str, q):
        """world_T_F, 4 x 4."""
        return self._function(frame, "pose")(q)

    def frame_jacobian(self, frame: str, q, reference: str = "world"):
        """J (6 x n) at F's origin: world-aligned ("world") or in F's own axes ("local")."""
        if reference not in ("world", "local"):
            raise SymdynError(f"frame_jacobian: reference must be 'world' or 'local', got {reference!r}")
        return self._function(frame, "jacobian" if reference == "world" else "jacobian_local")(q)

    def frame_jacobian_dot_qd(self, frame: str, q, qd):
        """Jdot qd (6) at qdd = 0: F's origin's classical acceleration, then F's angular one."""
        return self._function(frame, "jacobian_dot_qd")(q, qd)

    def operational_space_inertia(self, frame: str, q, axes=None):
        """Lambda = (J M^-1 J^T)^-1 (k x k) over the rows `axes` ("x,y,z"; default all six)."""
        return self._function(frame, "operational_space_inertia", axes)(q)

    def operational_space_bias(self, frame: str, q, qd, axes=None):
        """mu + p = Lambda (J M^-1 (V + G + F) - Jdot qd) (k) over the rows `axes`."""
        return self._function(frame, "operational_space_bias", axes)(q, qd)

    def _com(self, name: str):
        """A centre-of-mass function, from the library of the first frame (every one has them)."""
        return self.frame_functions(self.frame_names[0]).function(name)

    def com(self, q):
        """The centre of mass c(q) (3), world frame."""
        return self._com("com")(q)

    def com_jacobian(self, q):
        """Jc (3 x n), world frame: dc/dt = Jc qd."""
        return self._com("com_jacobian")(q)

    def com_jacobian_dot_qd(self, q, qd):
        """Jc_dot qd (3): the centre of mass's acceleration at qdd = 0, world frame."""
        return self._com("com_jacobian_dot_qd")(q, qd)
