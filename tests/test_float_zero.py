"""symdyn.symbolic.float_zero: SymPy's Float.is_zero answered by SymPy's own handler, installed
by importing symdyn's symbolic floor or the robot model, equal to SymPy's property on every kind
of Float, and leaving the other facts to SymPy's deduction."""

from __future__ import annotations

import subprocess
import sys

import sympy as sp

import symdyn.model.robot  # noqa: F401  (installs it)
from symdyn.symbolic import float_zero

#: Floats of every kind: zeros of several precisions, subnormal, tiny beyond double, huge,
#: negative, and made by arithmetic (new objects, as in a derivation)
VALUES = [
    lambda: sp.Float(0.0),
    lambda: sp.Float(-0.0),
    lambda: sp.Float(0, 30),
    lambda: sp.Float("0.000"),
    lambda: sp.Float(5e-324),
    lambda: sp.Float("1e-5000"),
    lambda: sp.Float("-3.5e400"),
    lambda: sp.Float(1.5707963267948966),
    lambda: sp.Float(0.316) * sp.Float(-0.088),
    lambda: sp.Float(0.5) - sp.Float(0.5),
    lambda: sp.Float(1e308) * sp.Float(10.0),
]

FACTS = ("zero", "nonzero", "positive", "negative", "extended_negative", "integer", "rational", "finite")


def test_installed_on_import_and_idempotent():
    assert sp.Float.__dict__["is_zero"].fget is float_zero._is_zero
    assert float_zero.original_is_zero is not None
    assert float_zero.original_is_zero.fget is not float_zero._is_zero
    float_zero.install()
    assert sp.Float.__dict__["is_zero"].fget is float_zero._is_zero


def test_same_answer_as_sympys_property_for_every_kind_of_float():
    for make in VALUES:
        ours, theirs = make(), make()
        if not isinstance(ours, sp.Float):  # 0.5 - 0.5 is S.Zero, 1e309 oo: other classes, untouched
            assert (
                not isinstance(type(ours).__dict__.get("is_zero"), property)
                or type(ours).__dict__["is_zero"].fget is not float_zero._is_zero
            )
            continue
        assert ours.is_zero is float_zero.original_is_zero.fget(theirs), ours
        assert ours.is_zero is float_zero.original_is_zero.fget(theirs), ours  # asked again
        # every other fact, asked after is_zero, is what SymPy deduces with its own property
        assert [getattr(ours, f"is_{f}") for f in FACTS] == [getattr(theirs, f"is_{f}") for f in FACTS], ours


def test_a_known_fact_comes_first():
    x = sp.Float(2.0)
    x._assumptions["zero"] = False  # as SymPy's deduction would record it
    assert x.is_zero is False


def test_a_process_importing_symdyn_derives_the_same_expressions_as_plain_sympy():
    """The same derivation's text with SymPy's own property restored (a process of its own)."""
    code = """
import sys, sympy as sp
from symdyn.symbolic import float_zero
from symdyn.parsers import robot_from_data
from symdyn.dynamics import derive
if sys.argv[1] == "sympy":
    sp.Float.is_zero = float_zero.original_is_zero
inertia = {"ixx": 0.01, "iyy": 0.02, "izz": 0.015}
link = {"joint": "revolute", "theta": 0, "com": [0.1, 0.05, -0.03], "inertia": inertia}
robot = robot_from_data({"name": "arm", "convention": "standard", "links": [
    {**link, "name": "l1", "a": 0.316, "alpha": 1.5707963267948966, "d": 0.0, "mass": 1.2},
    {**link, "name": "l2", "a": 0.0825, "alpha": -1.5707963267948966, "d": 0.384, "mass": 0.7}]})
dyn = derive(robot, simplify=False)
print(sp.srepr(dyn.tau), sp.srepr(dyn.M))
"""
    texts = [
        subprocess.run([sys.executable, "-c", code, route], capture_output=True, text=True, check=True).stdout
        for route in ("sympy", "symdyn")
    ]
    assert texts[0] == texts[1] and len(texts[0]) > 1000
