"""Significance pruning (symdyn.algorithms.pruning): the stated bounds hold on random states."""

from __future__ import annotations

import math

import numpy as np
import pytest
from robots import example

from symdyn.algorithms.configuration_space import pair_columns
from symdyn.algorithms.pruning import prune, trig_bound
from symdyn.dynamics import derive
from symdyn.errors import SymdynError


@pytest.mark.parametrize("kind", [0, 1])
def test_trig_bound_is_the_maximum_over_the_interval(kind):
    rng = np.random.default_rng(3)
    f = np.cos if kind == 0 else np.sin
    for _ in range(200):
        lo = rng.uniform(-7, 7)
        hi = lo + rng.uniform(0, 4)
        dense = np.abs(f(np.linspace(lo, hi, 20001))).max()
        assert dense <= trig_bound(lo, hi, kind) + 1e-12
        assert trig_bound(lo, hi, kind) <= dense + 1e-6


def _values(cs, name, r, c, q):
    return cs.ring.numeric(cs.poly(name, r, c))(q)


@pytest.mark.parametrize(("robot", "rel", "limits"), [("puma560", 0.01, None), ("stanford", 0.05, "half")])
def test_error_within_the_stated_bound(robot, rel, limits):
    dyn = derive(example(robot), simplify=False)
    n = dyn.n
    box = None if limits is None else [(-math.pi / 2, math.pi / 2)] * n
    pr = prune(dyn.configuration_space, rel, limits=box)
    assert pr.terms_after < pr.terms_before
    full, cut = dyn.configuration_space, pr.configuration
    lo, hi = np.array(box or [(-math.pi, math.pi)] * n).T
    q = np.random.default_rng(5).uniform(lo, hi, (3000, n))
    entries = [("M", i, j) for i in range(n) for j in range(i, n)] + [("G", k, 0) for k in range(n)]
    entries += [("B", k, c) for k in range(n) for c in range(len(pair_columns(n)))]
    entries += [("Csq", k, i) for k in range(n) for i in range(n)]
    for key in entries:
        err = np.abs(_values(full, *key, q) - _values(cut, *key, q)).max()
        assert err <= pr.bounds.get(key, 0.0) * (1 + 1e-9) + 1e-12, (key, err, pr.bounds.get(key))


def test_prune_needs_numbers_and_a_threshold():
    dyn = derive(example("roger_arm"), simplify=False)
    with pytest.raises(SymdynError, match="free parameters"):
        prune(dyn.configuration_space, 0.01)
    with pytest.raises(SymdynError, match="between 0 and 1"):
        prune(derive(example("planar_3r")).configuration_space, 2.0)


def test_generated_code_from_the_pruned_model_states_and_keeps_its_bound():
    from symdyn import rnea
    from symdyn.codegen import context
    from symdyn.codegen.render import header_lines

    robot = example("puma560")
    ctx = context(robot, prune=0.01)
    assert any("Pruned model (--prune 0.01)" in line for line in header_lines(ctx))
    pr = prune(derive(robot, simplify=False).configuration_space, 0.01)
    rng = np.random.default_rng(8)
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, 6)
        M, G = ctx.dynamics.evaluate("M", q), ctx.dynamics.evaluate("G", q)
        M_true, G_true = rnea.mass_matrix(ctx.robot, q), rnea.gravity_torque(ctx.robot, q)
        for i in range(6):
            assert abs(G[i] - G_true[i]) <= pr.bounds.get(("G", i, 0), 0.0) + 1e-9
            for j in range(i, 6):
                assert abs(M[i, j] - M_true[i, j]) <= pr.bounds.get(("M", i, j), 0.0) + 1e-9
