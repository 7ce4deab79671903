"""One robot's results in bench/run.py, and the names of what is timed.

A `Row` collects, for one robot, the generation time, the operation counts, the ns per
call of symdyn's C, of the CasADi route's C (bench/casadi_route.py) and of Pinocchio's
C++, the Python-side timings, and the largest relative error of every check against
symdyn.rnea. bench/report.py turns a list of rows into the table.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi_route

from symdyn.codegen import FUNCTION_NAMES

__all__ = ["Row", "FUNCTIONS", "SHORT", "CASADI_FUNCTIONS", "PINOCCHIO", "PINOCCHIO_NAMES"]

FUNCTIONS = FUNCTION_NAMES
SHORT = {
    "inverse_dynamics": "tau",
    "mass_matrix": "M",
    "coriolis_matrix": "C",
    "coriolis": "V",
    "gravity": "G",
    "friction": "F",
    "forward_dynamics": "FD",
    "regressor": "Y",
    "base_regressor": "Yb",
}
CASADI_FUNCTIONS = casadi_route.FUNCTIONS  # inverse_dynamics, mass_matrix, gravity
PINOCCHIO = {  # symdyn function -> the Pinocchio algorithm timed against it
    "inverse_dynamics": "rnea",
    "mass_matrix": "crba",
    "gravity": "gravity",
    "coriolis_matrix": "coriolis_matrix",
    "forward_dynamics": "aba",
    "regressor": "regressor",
}
PINOCCHIO_NAMES = {
    "rnea": "rnea",
    "crba": "crba",
    "gravity": "computeGeneralizedGravity",
    "coriolis_matrix": "computeCoriolisMatrix",
    "aba": "aba",
    "regressor": "computeJointTorqueRegressor",
}


@dataclass
class Row:
    """Everything measured on one robot (times in ns or us per call, generation in seconds)."""

    name: str
    n: int = 0
    file: str = ""  # relative to the project, or `package: path inside it`
    gen_wall: float = float("nan")
    gen_cpu: float = float("nan")
    ops: dict = field(default_factory=dict)  # function -> {total, mul, add, div, trig, other}
    casadi_ops: dict = field(default_factory=dict)  # function -> flops() dict
    c_ns: dict = field(default_factory=dict)  # symdyn C: function -> ns/call (median)
    cr_c_ns: dict = field(default_factory=dict)  # CasADi route C
    cr_py_us: dict = field(default_factory=dict)  # casadi.Function called from Python
    pin_ns: dict = field(default_factory=dict)  # Pinocchio algorithm -> ns/call
    numpy_us: float = float("nan")  # symdyn.rnea.rnea single call
    numpy_batch_us: float = float("nan")  # per state, batch of 1000
    checks: dict = field(default_factory=dict)  # what -> max relative error
    samples: dict = field(default_factory=dict)  # harness label -> ns per call of every repetition
    notes: list = field(default_factory=list)
    derivatives: dict = field(default_factory=dict)  # bench/derivatives.py: ns, checks, op counts
