"""symdyn.codegen.functions: function families with several outputs of any shape, in every target.

A test family (added to FAMILIES for the test only) has a function with two outputs, M and G
in one call, and one with a 2n x n output S = [M; 2 M] (size names "2n" and "n"). Rendered by
the C target (compiled with warnings as errors and called through ctypes), the NumPy target
and the CasADi target, their values must equal the independent numeric CRBA and gravity of
symdyn.rnea, and the generated files of the robot's seven functions must not change.
"""

from __future__ import annotations

import ctypes
import importlib
import types

import numpy as np
import pytest
import sympy as sp
from cbuild import compile_shared, header_macros, write_files
from robots import derived, example

from symdyn.codegen import functions as fn
from symdyn.codegen import render
from symdyn.symbolic.program import Program

rn = importlib.import_module("symdyn.rnea")
ROBOT = "planar_3r"


def _test_family(dyn, x: fn.Inputs) -> list[fn.FunctionRow]:
    n = dyn.n
    M, G = dyn.compact["M"], dyn.compact["G"]
    both = fn.FunctionRow(
        "mass_and_gravity",
        "M(q) and G(q) in one call",
        (x.q, x.p),
        (fn.joint_matrix_output("M", n, "the mass matrix"), fn.vector_output("G", n, "gravity efforts")),
        (*M, *G),
    )
    stacked = fn.FunctionRow(
        "stacked_mass",
        "S = [M; 2 M]",
        (x.q, x.p),
        (fn.Output("S", 2 * n, n, "M over 2 M", ("2n", "n")),),
        (*M, *(2 * M)),
    )
    return [both, stacked]


@pytest.fixture(scope="module")
def files():
    dyn = derived(ROBOT, "newton-euler")
    plain = render(dyn.robot, targets=("c", "python", "casadi"))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(fn, "FAMILIES", (*fn.FAMILIES, _test_family))
        extended = render(dyn.robot, targets=("c", "python", "casadi"))
    return dyn, plain, extended


def _states(robot, count=5):
    rng = np.random.default_rng(7)
    return rng.uniform(-np.pi, np.pi, (count, robot.n))


def test_seven_functions_unchanged_by_an_added_family(files):
    """Adding a family never changes the existing functions' code (the CSE needs are fixed)."""
    _, plain, extended = files
    name = f"{ROBOT}_dynamics.c"
    for fname in ("inverse_dynamics", "mass_matrix", "forward_dynamics"):
        body = plain[name].split(f"void {ROBOT}_{fname}(")[1].split("\n}\n")[0]
        assert body in extended[name]


def test_c_several_outputs_and_non_square(files, tmp_path):
    dyn, _, extended = files
    robot = dyn.robot
    n = robot.n
    write_files({k: v for k, v in extended.items() if k.startswith(f"{ROBOT}_dynamics.")}, tmp_path)
    header = (tmp_path / f"{ROBOT}_dynamics.h").read_text()
    assert "double M[], double G[]);" in header
    assert f"S  M over 2 M, (2*{ROBOT}_NDOF)*{ROBOT}_NDOF values, row-major" in header
    assert int(header_macros(header)[f"{ROBOT}_NDOF"]) == n
    lib = ctypes.CDLL(str(compile_shared([tmp_path / f"{ROBOT}_dynamics.c"], tmp_path / "lib.so")))
    ptr = ctypes.POINTER(ctypes.c_double)
    for q in _states(robot):
        qa = np.ascontiguousarray(q)
        M = np.full((n, n), np.nan)
        G = np.full(n, np.nan)
        S = np.full((2 * n, n), np.nan)
        getattr(lib, f"{ROBOT}_mass_and_gravity")(
            qa.ctypes.data_as(ptr), None, M.ctypes.data_as(ptr), G.ctypes.data_as(ptr)
        )
        getattr(lib, f"{ROBOT}_stacked_mass")(qa.ctypes.data_as(ptr), None, S.ctypes.data_as(ptr))
        np.testing.assert_allclose(M, rn.mass_matrix(robot, q), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(G, rn.gravity_torque(robot, q), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(S, np.vstack([M, 2 * M]), rtol=1e-15, atol=0)


def test_numpy_and_casadi_several_outputs(files):
    dyn, _, extended = files
    robot = dyn.robot
    module = types.ModuleType("gen")
    exec(compile(extended[f"{ROBOT}_numpy.py"], "gen", "exec"), module.__dict__)  # symdyn's own output
    casadi_module = types.ModuleType("gen_casadi")
    exec(compile(extended[f"{ROBOT}_casadi.py"], "gen_casadi", "exec"), casadi_module.__dict__)
    ca_f = casadi_module.functions()
    qs = _states(robot)
    M_batch, G_batch = module.mass_and_gravity(qs)
    assert M_batch.shape == (len(qs), robot.n, robot.n) and G_batch.shape == (len(qs), robot.n)
    assert module.stacked_mass(qs).shape == (len(qs), 2 * robot.n, robot.n)
    assert ca_f["mass_and_gravity"].name_out() == ["M", "G"]
    for k, q in enumerate(qs):
        M_want, G_want = rn.mass_matrix(robot, q), rn.gravity_torque(robot, q)
        M, G = module.mass_and_gravity(q)
        np.testing.assert_allclose(M, M_want, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(G, G_want, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(M_batch[k], M_want, rtol=1e-12, atol=1e-12)
        Mc, Gc = ca_f["mass_and_gravity"](q, [])
        np.testing.assert_allclose(np.array(Mc), M_want, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(np.array(Gc).ravel(), G_want, rtol=1e-12, atol=1e-12)
        Sc = np.array(ca_f["stacked_mass"](q, []))
        np.testing.assert_allclose(Sc, np.vstack([M_want, 2 * M_want]), rtol=1e-12, atol=1e-12)


def test_duplicate_function_names_are_refused():
    dyn = derived(ROBOT, "newton-euler")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(fn, "FAMILIES", (*fn.FAMILIES, fn.dynamics_rows))
        with pytest.raises(AssertionError, match="duplicate"):
            fn.build_functions(dyn)


def test_output_entries_are_the_slices_of_the_code(files):
    dyn = derived(ROBOT, "newton-euler")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(fn, "FAMILIES", (*fn.FAMILIES, _test_family))
        specs = {s.name: s for s in fn.build_functions(dyn)}
    both = specs["mass_and_gravity"]
    M_out, G_out = both.results
    assert (M_out.matrix, G_out.matrix) == (True, False)
    assert len(both.entries(M_out)) == dyn.n**2 and len(both.entries(G_out)) == dyn.n
    assert both.entries(M_out) + both.entries(G_out) == list(both.outputs)
    with pytest.raises(KeyError):
        both.entries(specs["stacked_mass"].results[0])
    assert example(ROBOT).n == dyn.n


def test_groups_select_families_with_unchanged_code():
    """generate --functions dynamics: the seven functions, each with the code of a full build."""
    from symdyn.errors import SymdynError

    robot = derived(ROBOT, "newton-euler").robot
    full = render(robot, targets=("c",))
    seven = render(robot, targets=("c",), functions=("dynamics",))
    header = seven[f"{ROBOT}_dynamics.h"]
    names = ("inverse_dynamics", "mass_matrix", "coriolis_matrix", "coriolis", "gravity", "friction")
    names += ("forward_dynamics",)
    assert header.count("\nvoid ") == len(names) and "_regressor(" not in header
    source, full_source = seven[f"{ROBOT}_dynamics.c"], full[f"{ROBOT}_dynamics.c"]
    for name in names:
        body = source.split(f"void {ROBOT}_{name}(")[1].split("\n}\n")[0]
        assert body in full_source, name
    with pytest.raises(SymdynError, match="unknown function group"):
        render(robot, targets=("c",), functions=("dynamic",))


def _solved(M: sp.Matrix, b: list, order: list[int], values: dict) -> np.ndarray:
    """x of ldlt_column_solve for M x = b eliminated in `order`, at `values`; and checks that its
    layout lists every intermediate, each after those it reads."""
    prog = Program()
    x, layout = fn.ldlt_column_solve(M.extract(order, order), [b[i] for i in order], prog)
    laid_out = [s for s in dict.fromkeys(layout) if prog.is_intermediate(s)]  # and M's own symbols
    assert sorted(laid_out, key=str) == sorted((s for s, _ in prog.assignments), key=str)
    done: set = set()
    for s in laid_out:
        assert not {t for t in dict(prog.assignments)[s].free_symbols if prog.is_intermediate(t)} - done
        done.add(s)
    got = np.array([float(e.xreplace(values)) for e in prog.expand(x)])
    return got[np.argsort(order)]


@pytest.mark.parametrize("seed", [1, 2])
def test_ldlt_column_solve_with_fill_in_matches_numpy(seed):
    # a star: coordinate 0 coupled to every other, the others to none; eliminated first to last,
    # coordinate 0 fills in every zero; diagonally dominant, so M is positive definite
    n = 5
    off = {(i, 0): sp.Symbol(f"m{i}") for i in range(1, n)}
    M = sp.Matrix(n, n, lambda i, j: 5 + sp.Symbol(f"d{i}") if i == j else off.get((max(i, j), min(i, j)), 0))
    b = list(sp.symbols(f"b0:{n}"))
    symbols = sorted(M.free_symbols | set(b), key=str)
    values = dict(zip(symbols, np.random.default_rng(seed).uniform(-1, 1, len(symbols)), strict=True))
    Mn, bn = np.array(M.xreplace(values), dtype=float), np.array([values[s] for s in b])
    for order in (list(range(n)), list(reversed(range(n)))):  # with fill-in, and without
        assert np.allclose(_solved(M, b, order, values), np.linalg.solve(Mn, bn), rtol=1e-13, atol=0)


def test_ldlt_column_solve_of_a_tree_keeps_its_zeros():
    # a root (0) and two branches (1, 2), eliminated last to first (the module docstring): no
    # fill-in, so no coordinate of one branch is ever multiplied by one of the other
    m = dict(zip(("m00", "m01", "m02", "m11", "m22"), sp.symbols("m00 m01 m02 m11 m22"), strict=True))
    M = sp.Matrix([[m["m00"], m["m01"], m["m02"]], [m["m01"], m["m11"], 0], [m["m02"], 0, m["m22"]]])
    b = list(sp.symbols("b0:3"))
    prog = Program()
    fn.ldlt_column_solve(M.extract([2, 1, 0], [2, 1, 0]), b[::-1], prog)
    updates = [e for s, e in prog.assignments if s.name.startswith("_fdH")]
    assert len(updates) == 2  # the root's pivot, once from each branch; nothing between them
    values = {m["m00"]: 3.0, m["m01"]: 0.4, m["m02"]: -0.7, m["m11"]: 2.0, m["m22"]: 1.5}
    values |= dict(zip(b, (0.3, -1.1, 0.8), strict=True))
    Mn, bn = np.array(M.xreplace(values), dtype=float), np.array([values[s] for s in b])
    assert np.allclose(_solved(M, b, [2, 1, 0], values), np.linalg.solve(Mn, bn), rtol=1e-13, atol=0)
