"""Base parameters (symdyn.algorithms.base_parameters, `Dynamics.base_parameters`), judged independently.

The oracle's numeric regressor (symdyn.oracle.regressor), stacked at random states other than the
ones the derivation used, must have the rank the base parameters count (SVD rank); the combinations
K must vanish on its null space (so K pi fixes tau) and be of full rank; Y_b pi_b with pi_b = K pi
must equal tau of the numeric RNEA; and for the lecture's two-link arm with symbolic lengths the
regrouped parameters are the textbook ones (Khalil and Dombre (2002), sec. 12.3.3: Izz1 + Ia1 +
m2 l1^2 and mx1 + m2 l1 for a planar 2R arm).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from robots import (
    EXAMPLE_NAMES,
    assert_close,
    derived,
    derived_robot,
    random_params,
    random_state,
    raw_example,
    y_robot,
)

import symdyn
import symdyn.codegen
from symdyn.errors import SymdynError
from symdyn.model.parameters import numeric_parameters
from symdyn.oracle.regressor import regressor as oracle_regressor

STATES = 40


def stacked(robot, params, seed: int):
    rng = np.random.default_rng(seed)
    states = [random_state(robot, rng) for _ in range(STATES)]
    W = np.vstack([oracle_regressor(robot, *x, params) for x in states])
    return states, W


def check(dyn, seed: int) -> None:
    robot = dyn.robot
    rng = np.random.default_rng(seed)
    params = random_params(robot, rng) if robot.params else None
    base = dyn.linear_compact()[1]
    states, W = stacked(robot, params, seed)
    s = np.linalg.svd(W, compute_uv=False)
    rank = int(np.sum(s > 1e-9 * s[0]))
    assert len(base.names) == rank == len(dyn.base_parameters), robot.name
    K = base.matrix(dict(zip(robot.params, params, strict=True)) if params is not None else None)
    assert np.linalg.matrix_rank(K) == rank
    null = np.linalg.svd(W)[2][rank:].T  # standard-parameter directions that change no torque
    assert np.abs(K @ null).max() < 1e-8 * max(1.0, np.abs(K).max()), robot.name
    pi = numeric_parameters(robot, params)
    pi_b = K @ pi
    for x in states[:3]:
        Yb = oracle_regressor(robot, *x, params)[:, list(base.columns)]
        assert_close(Yb @ pi_b, symdyn.rnea(robot, *x, params), 1e-10, robot.name)


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_every_example_robot(name):
    check(derived(name, "newton-euler"), seed=100 + len(name))


def test_tree():
    check(derived_robot(y_robot(), "newton-euler"), seed=4)


def test_symbolic_lengths_regroup_as_the_textbook():
    dyn = derived("roger_arm", "newton-euler")
    base = dict(dyn.base_parameters)
    m2, l1, Izz1, Ia1, mx1 = sp.symbols("m2 l1 Izz1 Ia1 mx1")
    assert sp.expand(base["Izz1R"] - (Izz1 + Ia1 + m2 * l1**2)) == 0
    assert sp.expand(base["mx1R"] - (mx1 + m2 * l1)) == 0
    assert all(e == sp.Symbol(k) for k, e in base.items() if not k.endswith("R"))


def test_base_regressor_is_the_kept_columns():
    dyn = derived("scara", "newton-euler")
    base = dyn.linear_compact()[1]
    Yb = dyn.base_regressor
    assert Yb.shape == (4, len(base.names))
    assert Yb == dyn.regressor.extract(list(range(4)), list(base.columns))


def test_mimic_joint_with_a_symbolic_length_is_refused_clearly():
    """q2 = 1.5 q1 and a free length a: the coefficients depend on a, and sin(1.5 q1) has no exact
    rational evaluation, so one SymdynError asks for a value of a; with a value the base
    parameters are found and agree with the oracle. The generated code leaves out base_regressor
    with a SymdynWarning and keeps regressor."""
    robot = symdyn.robot_from_data(MIMIC_SYM, source="test")
    dyn = symdyn.derive(robot, simplify=False)
    with pytest.raises(SymdynError, match="not as cos\\(1.5\\*q1\\).*give the free parameters values"):
        dyn.linear_compact()
    with pytest.warns(symdyn.SymdynWarning, match="base_regressor is not generated"):
        files = symdyn.codegen.render(robot, targets=("python",))
    assert (
        "def regressor(" in files["mimic_sym_numpy.py"]
        and "def base_regressor(" not in files["mimic_sym_numpy.py"]
    )
    valued = symdyn.robot_from_data({**MIMIC_SYM, "parameters": {"a": 0.4}}, source="test")
    check(symdyn.derive(valued, simplify=False), seed=9)


def test_numbers_whose_powers_overflow_are_refused_clearly():
    """A length of 1e140 passes the 1e150 bound on numbers but its powers in the regressor exceed
    double precision: the base parameters are refused with one line (before: an empty column table
    crashed the C target), and generate leaves out base_regressor with a SymdynWarning."""
    data = raw_example("roger_arm")
    data["parameters"] = {"g": 9.81, "m1": 1, "m2": 1, "l1": 1e140, "l2": 1}
    robot = symdyn.robot_from_data(data, source="huge.yaml")
    with pytest.raises(SymdynError, match="the regressor overflows double precision") as info:
        symdyn.derive(robot, simplify=False).linear_compact()
    assert "\n" not in str(info.value)
    with pytest.warns(symdyn.SymdynWarning, match="base_regressor is not generated"):
        files = symdyn.codegen.render(robot, targets=("c",), functions=("regressor",))
    assert "roger_arm_regressor(" in files["roger_arm_dynamics.h"]


_BODY = {"mass": 1, "com": [0.1, 0.02, 0], "inertia": {"ixx": 0.1, "iyy": 0.2, "izz": 0.3}}
MIMIC_SYM = {
    "name": "mimic_sym",
    "parameters": {"a": None},
    "links": [
        {"name": "l1", "joint": "revolute", "a": "a", "alpha": "pi/2", **_BODY},
        {"name": "l2", "joint": "revolute", "a": "a", **_BODY, "mimic": {"joint": "l1", "multiplier": 1.5}},
        {"name": "l3", "joint": "revolute", "a": 0.3, **_BODY},
    ],
}
