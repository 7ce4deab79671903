"""The configuration-space form tau = M qdd + B [qd qd] + Csq [qd^2] + G + F
(symdyn.algorithms.configuration_space): the same canonical closed forms from both routes,
and values equal to the numeric oracle symdyn.rnea."""

from __future__ import annotations

import math
from fractions import Fraction
from functools import cache

import numpy as np
import pytest
import sympy as sp
import yaml
from robots import (
    EXAMPLE_NAMES,
    derived,
    derived_rational,
    derived_robot,
    example,
    random_params,
    random_state,
    solo_robot,
    tree_robot,
    y_robot,
)
from test_mimic import CASES as MIMIC_CASES
from timebound import within

from symdyn import rnea
from symdyn.algorithms.configuration_space import pair_column, pair_columns
from symdyn.dynamics import derive
from symdyn.symbolic.simplify import count_ops
from symdyn.symbolic.trig_polynomial import add_into, chop, largest

NAMES = ("M", "B", "Csq", "G")


def _both(robot):
    """Both routes' derivations of a hand-built robot, session-cached (robots.derived_robot: the
    trees' are test_tree's and test_mimic's too, and each carries its configuration form)."""
    return [derived_robot(robot, m) for m in ("newton-euler", "lagrange")]


def _entries(dyn, name):
    cs = dyn.configuration_space
    rows, cols = cs.shape(name)
    return [cs.ring.named(cs.poly(name, r, c)) for r in range(rows) for c in range(cols)]


def _assert_same_terms(a, b, exact: bool, what: str) -> None:
    for name in NAMES:
        for k, (ta, tb) in enumerate(zip(_entries(a, name), _entries(b, name), strict=True)):
            assert ta.keys() == tb.keys(), f"{what} {name}[{k}]: different terms"
            for key, ca in ta.items():
                cb = tb[key]
                if exact:
                    assert not isinstance(ca, float) and ca == cb, f"{what} {name}[{k}] {key}: {ca} != {cb}"
                else:
                    assert math.isclose(float(ca), float(cb), rel_tol=1e-12), f"{what} {name}[{k}] {key}"


def _texts(dyn) -> list[str]:
    cs = dyn.configuration_space
    return [cs.text(q, r, c) for q in NAMES for r in range(cs.shape(q)[0]) for c in range(cs.shape(q)[1])]


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_routes_give_identical_strings_exact_data(name):
    """The Panda too (228,647 terms; the Lagrange route writes its Jacobians in body frames)."""
    a, b = (derived_rational(name, m) for m in ("newton-euler", "lagrange"))  # session-cached
    _assert_same_terms(a, b, exact=True, what=name)
    assert _texts(a) == _texts(b), name
    if a.configuration_space.readable:
        for q in NAMES:
            assert [sp.sstr(e) for e in getattr(a, q)] == [sp.sstr(e) for e in getattr(b, q)], (name, q)


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_routes_agree_float_data(name):
    a, b = (derived(name, m) for m in ("newton-euler", "lagrange"))  # example(name), session-cached
    _assert_same_terms(a, b, exact=False, what=name)


def forest_robot():
    """Four independent double pendulums (every other link on the base): a wide tree whose M is
    block diagonal, so most of its n^3 / 2 Christoffel symbols are structurally zero."""
    parents = tuple(p for k in range(4) for p in (-1, 2 * k))
    return tree_robot("forest", parents, ("revolute",) * len(parents), seed=34)


TREES = {
    "ytree": y_robot,
    "solo": solo_robot,
    **{f"mimic_{k}": (lambda v=v: v[0]) for k, v in MIMIC_CASES.items()},
}
#: trees checked against the oracle and the dense Christoffel sum only (not both routes)
ROBOTS = {**TREES, "forest": forest_robot}


@cache
def _derived(name: str):
    """The Newton-Euler derivation of an example or of a robot of ROBOTS (cached)."""
    return derived_robot(ROBOTS[name](), "newton-euler") if name in ROBOTS else derived(name, "newton-euler")


@pytest.mark.parametrize("case", sorted(TREES))
def test_trees_and_mimic_joints(case):
    robot = TREES[case]()
    a, b = _both(robot)
    _assert_same_terms(a, b, exact=False, what=case)
    # structural zeros of a tree's M stay exact zeros
    for i in range(a.n):
        for j in range(a.n):
            if a.compact["M"][i, j] == 0:
                assert a.M[i, j] == 0


def _value(dyn, name: str, q, values) -> np.ndarray:
    """Entries of M, B, Csq or G at q, from their polynomials (lambdify would overflow
    Python's compiler on the Panda's longest entries)."""
    cs = dyn.configuration_space
    rows, cols = cs.shape(name)
    out = [cs.ring.numeric(cs.poly(name, r, c), values)(q) for r in range(rows) for c in range(cols)]
    return np.array(out, dtype=float).reshape(rows, cols)


@pytest.mark.parametrize("name", [*EXAMPLE_NAMES, "ytree", "forest", "mimic_chain"])
def test_values_equal_the_oracle(name):
    dyn = _derived(name)
    small = dyn.configuration_space.readable  # the Panda: V and C would be the recursion expanded
    if small:
        args = [list(dyn.q), list(dyn.qd), list(dyn.params)]
        V_f, C_f = (sp.lambdify(args, getattr(dyn, k), "numpy") for k in ("V", "C"))
    rng = np.random.default_rng(11)
    pairs = pair_columns(dyn.n)
    for _ in range(3):
        p = random_params(dyn.robot, rng)
        q, qd, _ = random_state(dyn.robot, rng)
        values = dict(zip(dyn.params, p, strict=True))
        M, G = rnea.mass_matrix(dyn.robot, q, values), rnea.gravity_torque(dyn.robot, q, values)
        V = rnea.bias_torque(dyn.robot, q, qd, values)
        tol_m = 1e-9 * (1 + np.abs(M).max())
        tol_v = tol_m * (1 + np.abs(qd).max() ** 2)
        np.testing.assert_allclose(_value(dyn, "M", q, values), M, atol=tol_m)
        np.testing.assert_allclose(_value(dyn, "G", q, values).ravel(), G, atol=1e-9 * (1 + np.abs(G).max()))
        qdqd = np.array([qd[i] * qd[j] for i, j in pairs])
        V_cs = (_value(dyn, "B", q, values) @ qdqd if pairs else 0) + _value(dyn, "Csq", q, values) @ qd**2
        np.testing.assert_allclose(V_cs, V, atol=tol_v)
        if small:
            np.testing.assert_allclose(np.asarray(V_f(q, qd, p), dtype=float).ravel(), V, atol=tol_v)
            np.testing.assert_allclose(np.asarray(C_f(q, qd, p), dtype=float) @ qd, V, atol=tol_v)


def test_christoffel_symbols_of_a_two_link_arm():
    """Craig (2005), eq. 6.59: the planar two-link arm with point masses at the link tips has
    V = (-m2 l1 l2 s2 (2 qd1 qd2 + qd2^2), m2 l1 l2 s2 qd1^2): B = (-2 m2 l1 l2 s2, 0),
    Csq = [[0, -m2 l1 l2 s2], [m2 l1 l2 s2, 0]]."""
    m1, m2, l1, l2 = sp.symbols("m1 m2 l1 l2", positive=True)
    from symdyn.parsers.robot_file import robot_from_data

    links = [
        {
            "name": f"l{i}",
            "joint": "revolute",
            "a": f"l{i}",
            "alpha": 0,
            "d": 0,
            "theta": 0,
            "mass": f"m{i}",
            "com": [0, 0, 0],
            "inertia": {"ixx": 0, "iyy": 0, "izz": 0},
        }
        for i in (1, 2)
    ]
    robot = robot_from_data(
        {
            "name": "craig2",
            "convention": "standard",
            "gravity": [0, -9.81, 0],
            "parameters": {"m1": None, "m2": None, "l1": None, "l2": None},
            "links": links,
        }
    )
    for dyn in _both(robot):
        s2 = sp.sin(dyn.q[1])
        m2, l1, l2 = (sp.Symbol(n) for n in ("m2", "l1", "l2"))
        assert sp.expand(dyn.B[0, 0] + 2 * m2 * l1 * l2 * s2) == 0
        assert dyn.B[1, 0] == 0
        assert sp.expand(dyn.Csq[0, 1] + m2 * l1 * l2 * s2) == 0
        assert sp.expand(dyn.Csq[1, 0] - m2 * l1 * l2 * s2) == 0
        assert dyn.Csq[0, 0] == 0 and dyn.Csq[1, 1] == 0
        assert set(dyn.christoffel) == {(0, 0, 1), (0, 1, 1), (1, 0, 0)}


def test_puma_velocity_terms_are_compact():
    """V of the PUMA 560 (exact data) from the Christoffel symbols: within 2x their size."""
    dyn = derived_rational("puma560", "newton-euler")
    gamma = count_ops([], list(dyn.christoffel.values())).total
    assert len(dyn.christoffel) == 84
    assert count_ops([], list(dyn.V)).total <= 2 * gamma
    assert all(isinstance(c, Fraction) for p in dyn.configuration_space.gamma.values() for c in p.values())


def _dense_christoffel(cs) -> dict:
    """Gamma^k_ij = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k) summed for every k and i <= j
    (all n^3 / 2 of them, as configuration_space did before it skipped the (k, i, j) that no
    nonzero derivative of M enters), zeros and float residues dropped as it drops them."""
    ring, M, n = cs.ring, cs.M, cs.n
    big = largest(M[i][j] for i in range(n) for j in range(i, n))
    half = Fraction(1, 2)
    gamma = {}
    for k in range(n):
        for i in range(n):
            for j in range(i, n):
                acc: dict = {}
                for (a, b, x), f in (((k, j, i), half), ((k, i, j), half), ((i, j, k), -half)):
                    add_into(acc, ring.diff(M[min(a, b)][max(a, b)], x), f)
                acc = chop(acc, big)
                if acc:
                    gamma[(k, i, j)] = acc
    return gamma


@pytest.mark.parametrize("name", ["puma560", "stanford", "ytree", "solo", "forest"])
def test_sparse_christoffel_symbols_equal_the_dense_sum(name):
    """The Christoffel symbols summed only where a derivative of M enters are the full sum's,
    coefficient for coefficient and in the same order (so `derive` prints the same bytes); B's
    and Csq's nonzero entries (`ConfigurationSpace.nonzero`) are those whose polynomial is not
    zero, in row-major order."""
    dyn = _derived(name)
    cs = dyn.configuration_space
    assert list(cs.gamma.items()) == list(_dense_christoffel(cs).items())
    for which in ("B", "Csq"):
        rows, cols = cs.shape(which)
        every = [(k, c) for k in range(rows) for c in range(cols) if cs.poly(which, k, c)]
        assert list(cs.nonzero(which)) == every, which
    if name == "forest":  # the pendulums do not couple: no symbol joins two of them
        assert all(k // 2 == i // 2 == j // 2 for k, i, j in cs.gamma)


def test_pair_column_inverts_pair_columns():
    for n in (2, 3, 7, 40):
        assert [pair_column(n, i, j) for i, j in pair_columns(n)] == list(range(n * (n - 1) // 2))
    assert pair_columns(0) == pair_columns(1) == ()


def _long_chain_data(n: int) -> list[dict]:
    """A spatial n-joint arm's links (axes turning by +-90 degrees): its form grows exponentially."""
    return [
        {
            "joint": "revolute",
            "a": 0.3,
            "alpha": [1.5707963267948966, 0, -1.5707963267948966][i % 3],
            "d": 0.1 * (i % 2),
            "mass": 1.0,
            "com": [0.15, 0, 0],
            "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.03},
        }
        for i in range(n)
    ]


def test_a_readable_form_is_the_same_built_with_the_budget():
    """readable_configuration_space builds with a budget of READABLE_TERMS terms: a readable form
    is the same as without it."""
    from symdyn.algorithms.configuration_space import READABLE_TERMS

    puma = derive(example("puma560"), simplify=False)
    budgeted = puma.readable_configuration_space()
    assert budgeted is not None and budgeted.terms <= READABLE_TERMS
    assert budgeted.text("M", 1, 2) == derived("puma560", "newton-euler").configuration_space.text("M", 1, 2)


def test_derive_of_a_long_chain_falls_back_to_compact_within_seconds(tmp_path, capsys):
    """A 16-joint arm's default derive gave no answer in minutes, building a form of millions of
    terms before finding it unreadable; the budget stops at the first intermediate past
    READABLE_TERMS and the compact form is printed within seconds."""
    from symdyn.cli.main import main

    path = tmp_path / "chain.yaml"
    path.write_text(yaml.safe_dump({"name": "chain16", "links": _long_chain_data(16)}))
    with within(60):
        assert main(["derive", str(path)]) == 0
    captured = capsys.readouterr()
    assert "has more than 100,000 terms; printing --form compact" in captured.err
    assert captured.out.splitlines()[2].startswith("# tau = M(q) qdd + V(q, qd) + G(q) + F(qd)")
