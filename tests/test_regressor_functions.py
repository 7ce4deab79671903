"""The generated regressor and base_regressor (symdyn.codegen.regressor_functions) in C, NumPy and CasADi.

Compiled C (warnings as errors) called through ctypes, the NumPy module (one state and a batch) and
the CasADi functions must equal the oracle's numeric regressor symdyn.oracle.regressor (Y, and its
columns of the base parameters for Y_b), and Y_b pi_b with pi_b = K pi must equal tau of the numeric
RNEA, on a robot with a prismatic joint (SCARA), a tree with a mimic joint and a robot with free
parameters. The C header defines NAME_NSTD and NAME_NBASE and names every column.
"""

from __future__ import annotations

import ctypes
import types

import numpy as np
import pytest
import sympy as sp
from cbuild import compile_shared, header_macros, write_files
from robots import assert_close, derived, derived_robot, random_params, random_state, tree_robot

import symdyn
from symdyn.codegen import render
from symdyn.model.parameters import numeric_parameters
from symdyn.model.robot import Mimic
from symdyn.oracle.regressor import regressor as oracle_regressor

TOL = 1e-10


def _mimic_tree():
    mimic = {3: Mimic(1, sp.Float(1.5), sp.Float(-0.2))}
    joints = ("revolute", "prismatic", "revolute", "revolute", "prismatic", "revolute")
    return tree_robot("tree6", (-1, 0, 0, 2, -1, 4), joints, seed=7, mimic=mimic)


CASES = {
    "scara": lambda: derived("scara", "newton-euler"),
    "tree6": lambda: derived_robot(_mimic_tree(), "newton-euler"),
    "roger_arm": lambda: derived("roger_arm", "newton-euler"),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request, tmp_path_factory):
    dyn = CASES[request.param]()
    files = render(dyn.robot, targets=("c", "python", "casadi"))
    out = tmp_path_factory.mktemp(request.param)
    write_files(files, out)
    return dyn, files, out


def _expected(dyn, seed: int, count: int = 3):
    robot = dyn.robot
    rng = np.random.default_rng(seed)
    params = random_params(robot, rng) if robot.params else None
    base = dyn.linear_compact()[1]
    K = base.matrix(dict(zip(robot.params, params, strict=True)) if params is not None else None)
    pi_b = K @ numeric_parameters(robot, params)
    states = [random_state(robot, rng) for _ in range(count)]
    return params, list(base.columns), pi_b, states


def test_c(case):
    dyn, files, out = case
    name = dyn.robot.name
    robot = dyn.robot
    header = (out / f"{name}_dynamics.h").read_text()
    macros = header_macros(header)
    base = dyn.linear_compact()[1]
    assert int(macros[f"{name}_NSTD"]) == 13 * robot.nb
    assert int(macros[f"{name}_NBASE"]) == len(base.names)
    for k, (col, expr) in enumerate(dyn.base_parameters):
        assert f" {k:3d}  {col.ljust(max(map(len, base.names)))}  {expr}" in header
    lib = ctypes.CDLL(str(compile_shared([out / f"{name}_dynamics.c"], out / "lib.so")))
    ptr = ctypes.POINTER(ctypes.c_double)
    params, cols, pi_b, states = _expected(dyn, seed=1)
    p = np.ascontiguousarray(params if params is not None else np.zeros(1))
    for q, qd, qdd in states:
        args = [np.ascontiguousarray(v).ctypes.data_as(ptr) for v in (q, qd, qdd)] + [p.ctypes.data_as(ptr)]
        Y = np.full((robot.n, 13 * robot.nb), np.nan)
        Yb = np.full((robot.n, len(cols)), np.nan)
        getattr(lib, f"{name}_regressor")(*args, Y.ctypes.data_as(ptr))
        getattr(lib, f"{name}_base_regressor")(*args, Yb.ctypes.data_as(ptr))
        want = oracle_regressor(robot, q, qd, qdd, params)
        assert_close(Y, want, TOL, name)
        assert_close(Yb, want[:, cols], TOL, name)
        assert_close(Yb @ pi_b, symdyn.rnea(robot, q, qd, qdd, params), TOL, name)


def test_numpy_batch_and_casadi(case):
    dyn, files, _ = case
    robot, name = dyn.robot, dyn.robot.name
    module = types.ModuleType("gen")
    exec(compile(files[f"{name}_numpy.py"], "gen", "exec"), module.__dict__)  # symdyn's own output
    casadi_module = types.ModuleType("gen_casadi")
    exec(compile(files[f"{name}_casadi.py"], "gen_casadi", "exec"), casadi_module.__dict__)
    ca_f = casadi_module.functions()
    params, cols, pi_b, states = _expected(dyn, seed=2)
    p = list(params) if params is not None else []
    q, qd, qdd = (np.array([s[k] for s in states]) for k in range(3))
    Yb_batch = module.base_regressor(q, qd, qdd, p or None)
    assert Yb_batch.shape == (len(states), robot.n, len(cols))
    for k, (qk, qdk, qddk) in enumerate(states):
        want = oracle_regressor(robot, qk, qdk, qddk, params)
        assert_close(module.regressor(qk, qdk, qddk, p or None), want, TOL, name)
        assert_close(Yb_batch[k], want[:, cols], TOL, name)
        assert_close(np.array(ca_f["regressor"](qk, qdk, qddk, p)), want, TOL, name)
        assert_close(
            np.array(ca_f["base_regressor"](qk, qdk, qddk, p)) @ pi_b,
            want @ numeric_parameters(robot, params),
            TOL,
        )
