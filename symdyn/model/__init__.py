"""The robot model: `Robot` and `Link` (the general joint model), inertia tensors, the
safe expression parser for robot-file numbers, and the joint symbols q, qd, qdd."""
