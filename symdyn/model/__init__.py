"""The robot model: `Robot` and `Link` (the general joint model), inertia tensors, the
safe expression parser for robot-file numbers, and the joint symbols q, qd, qdd."""

from ..symbolic import float_zero as _float_zero  # noqa: E402,F401  (SymPy's Float.is_zero, fast)
