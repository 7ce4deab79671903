"""symdyn.symbolic.cse: temporaries that rebuild the input exactly, sharing of x and -x, common arguments,
deterministic names, and operation counts no worse than sympy.cse."""

from __future__ import annotations

import random

import numpy as np
import pytest
import sympy as sp
from robots import example_context

from symdyn.symbolic.cse import fast_cse
from symdyn.symbolic.simplify import count_ops, eliminate_many

x, y, z, u, v, w = sp.symbols("x y z u v w")


def _canonical(e: sp.Expr) -> sp.Expr:
    """e rebuilt through the SymPy constructors (fast_cse keeps argument order as it was)."""
    return e if e.is_Atom else e.func(*[_canonical(a) for a in e.args])


def _substituted(replacements, reduced):
    full: dict = {}
    for sym, e in replacements:
        full[sym] = e.xreplace(full)
    return [e.xreplace(full) for e in reduced]


def _random_exprs(seed: int, count: int = 12) -> list[sp.Expr]:
    rnd = random.Random(seed)
    atoms = [x, y, z, u, v, w, sp.Rational(3, 2), sp.Float(-0.25), sp.S(2)]
    pool: list[sp.Expr] = list(atoms)
    for _ in range(60):
        a, b = rnd.choice(pool), rnd.choice(pool)
        op = rnd.choice(["add", "sub", "mul", "neg", "sin", "cos", "add3"])
        if op == "add":
            e = a + b
        elif op == "sub":
            e = a - b
        elif op == "mul":
            e = a * b
        elif op == "neg":
            e = -a * b
        elif op == "add3":
            e = a - b - rnd.choice(pool)
        else:
            e = getattr(sp, op)(a)
        pool.append(e)
    return rnd.sample(pool[len(atoms) :], count)


@pytest.mark.parametrize("seed", range(20))
def test_temporaries_rebuild_the_expressions(seed):
    exprs = _random_exprs(seed)
    repl, reduced = fast_cse(exprs, "t")
    for got, want in zip(_substituted(repl, reduced), exprs, strict=True):
        assert sp.expand(got - want) == 0, (got, want)
    names = [s for s, _ in repl]
    assert names == [sp.Symbol(f"t{k}") for k in range(len(names))]
    for k, (_, e) in enumerate(repl):  # each temporary uses earlier ones only
        assert not (e.free_symbols & set(names[k:]))


def test_a_sum_and_its_negation_share_one_temporary():
    s = x + y - z
    repl, reduced = fast_cse([u * s, v * (z - x - y)], "t")
    assert len(repl) == 1 and sp.expand(repl[0][1] - s) == 0
    assert [_canonical(e) for e in reduced] == [u * repl[0][0], -v * repl[0][0]]


def test_common_arguments_of_sums_become_a_temporary():
    repl, reduced = fast_cse([x + y + z, x + y + w, sp.sin(x + y + u)], "t")
    assert [e for _, e in repl] == [x + y]
    t = repl[0][0]
    assert [_canonical(e) for e in reduced] == [t + z, t + w, sp.sin(t + u)]


def test_same_input_same_output():
    exprs = _random_exprs(99, count=30)
    assert fast_cse(exprs, "t") == fast_cse(list(exprs), "t")


@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_operation_counts_match_sympy_cse(name):
    """Over everything the seven generated functions compute: within 1 % of sympy.cse."""
    functions = example_context(name).functions  # build_functions(derived(name, ...)), session-cached
    outputs = [e for f in functions for e in f.outputs]
    steps = [a for f in functions for a in f.temporaries]
    exprs = [e for _, e in steps]
    ours = count_ops(*fast_cse(exprs + outputs, "t"))
    theirs = count_ops(*sp.cse(exprs + outputs, symbols=sp.numbered_symbols("t"), order="none"))
    assert ours.total <= 1.01 * theirs.total, (ours, theirs)


def test_leads_lay_out_intermediates_first_in_their_order():
    a, b, c = sp.symbols("_a _b _c")
    x, y, z = sp.symbols("x y z")
    steps = [(a, sp.sin(x) * y), (b, sp.cos(y) * z), (c, a * b + x)]
    plain = eliminate_many(steps, {"f": [c * z]})["f"]
    led = eliminate_many(steps, {"f": [c * z]}, leads={"f": [b, a]})["f"]
    assert [e.has(sp.sin) for _, e in plain.temporaries] == [True, False, False]  # a, b, c
    assert [e.has(sp.cos) for _, e in led.temporaries] == [True, False, False]  # b, a, c
    values = {x: 0.3, y: -1.2, z: 0.7}
    for got in (plain, led):  # the same function either way
        env = dict(values)
        for t, e in got.temporaries:
            env[t] = float(e.xreplace(env))
        assert float(got.outputs[0].xreplace(env)) == pytest.approx(
            (np.sin(0.3) * -1.2 * np.cos(-1.2) * 0.7 + 0.3) * 0.7
        )
