"""`derive` and `Dynamics`: the equations of motion tau = M(q) qdd + V(q, qd) + G(q) + F(qd).

The floor between the algorithms and code generation, by concern: the joint-space model
(`joint_space`: `derive` by either route and `Dynamics`, its compact and closed forms, the
regressor and the base parameters; the quantities' names in `quantities`), the frame and
task-space facade (`frames`: poses, Jacobians, centre of mass, operational space) and numeric
evaluation (`numeric`: `Dynamics.evaluate`). `symdyn.dynamics` keeps every public name of the one module
it was, so that user code and pickles keep working.
"""

from .joint_space import (
    ALL_QUANTITIES,
    AUTO_SIMPLIFY_MAX_JOINTS,
    METHODS,
    QUANTITIES,
    SINGULAR_M,
    SINGULAR_SAMPLES,
    SINGULAR_SEED,
    Dynamics,
    derive,
    friction_vector,
    simplify_entry,
    singular_message,
    state_symbols,
)

__all__ = [
    "ALL_QUANTITIES",
    "AUTO_SIMPLIFY_MAX_JOINTS",
    "METHODS",
    "QUANTITIES",
    "SINGULAR_M",
    "SINGULAR_SAMPLES",
    "SINGULAR_SEED",
    "Dynamics",
    "derive",
    "friction_vector",
    "simplify_entry",
    "singular_message",
    "state_symbols",
]
