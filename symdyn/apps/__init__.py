"""The lecture's applications on top of the derived dynamics: simulation, computed-torque
control, inertia ellipsoid / manipulability / acceleration polytope, and answer checking."""
