"""Values given at run time pass the robot file's physical checks (symdyn.model.physical).

`simulate --params`, `symdyn.compile(robot, params)` and identify's model parameters
(symdyn.apps.compilation.compiled.with_parameters) used to skip the checks a value in the file gets:
`--params m1=-1` ran and wrote a trajectory. The expected refusals are the loader's own: the
same numbers written into the file are refused by it too.
"""

from __future__ import annotations

import math

import pytest
import sympy as sp
import yaml
from robots import ASYMMETRIC_PARAMS, EXAMPLES_DIR, asymmetric_friction

import symdyn
from symdyn.apps.compilation.compiled import with_parameters
from symdyn.errors import SymdynError
from symdyn.parsers.robot_file import robot_from_data

ROGER = EXAMPLES_DIR / "roger_arm.yaml"
GOOD = {"m1": 1.0, "m2": 0.5, "l1": 0.3, "l2": 0.2, "g": 9.81}


@pytest.fixture(scope="module")
def roger():
    return symdyn.load_robot(ROGER)


def _link(mass, izz=0, viscous=0) -> dict:
    return {
        "joint": "revolute",
        "a": 0.5,
        "alpha": 0,
        "d": 0,
        "theta": 0,
        "mass": mass,
        "com": [-0.25, 0, 0],
        "inertia": {"ixx": izz, "iyy": izz, "izz": izz, "ixy": 0, "ixz": 0, "iyz": 0},
        "friction": {"viscous": viscous},
    }


def _two_link(link2: dict, parameters: dict | None = None) -> dict:
    """A planar two-link arm as a robot file's data (names not in `parameters` are free)."""
    return {
        "name": "two",
        "convention": "standard",
        "parameters": parameters or {},
        "links": [_link(1), link2],
    }


@pytest.mark.parametrize(
    "values,field",
    [
        ({"m1": -1.0}, "mass"),
        ({"m2": -0.5}, "mass"),
    ],
)
def test_with_parameters_refuses_what_the_file_would(roger, values, field):
    with pytest.raises(SymdynError) as info:
        with_parameters(roger, {**GOOD, **values})
    (name,) = values
    assert f"parameter {name} = {values[name]:g}" in str(info.value)
    assert f"field '{field}'" in str(info.value)
    assert "negative" in str(info.value)
    # the loader refuses the same number written into the file
    text = ROGER.read_text().replace("parameters: {}", "parameters: {" + f"{name}: {values[name]}" + "}")
    with pytest.raises(SymdynError, match="negative"):
        robot_from_data(yaml.safe_load(text))


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, "x"])
def test_with_parameters_refuses_non_numbers(roger, bad):
    with pytest.raises(SymdynError, match="parameter m1 must be (finite|a number)"):
        with_parameters(roger, {**GOOD, "m1": bad})


def test_inertia_and_friction_checked_at_run_time():
    robot = robot_from_data(_two_link(_link("m2", izz="Izz2", viscous="b2")))
    ok = with_parameters(robot, {"m2": 1.0, "b2": 0.1, "Izz2": 0.01})
    assert not ok.params
    with pytest.raises(SymdynError, match=r"parameter Izz2 = -0\.01: .*inertia.*not positive semi-definite"):
        with_parameters(robot, {"m2": 1.0, "b2": 0.1, "Izz2": -0.01})
    with pytest.raises(SymdynError, match=r"parameter b2 = -0\.1: .*friction\.viscous.*must not be negative"):
        with_parameters(robot, {"m2": 1.0, "b2": -0.1, "Izz2": 0.01})


def test_direction_dependent_coulomb_magnitudes_checked_at_run_time():
    """Both magnitudes of asymmetric Coulomb friction given at run time pass the file's check:
    a negative c_minus (the Robotics Toolbox's signed Tc-) is refused with its field named."""
    robot = asymmetric_friction()
    assert not with_parameters(robot, ASYMMETRIC_PARAMS).params
    for name, field in (("cp3", "friction.coulomb.plus"), ("cm3", "friction.coulomb.minus")):
        with pytest.raises(SymdynError, match=rf"parameter {name} = -0\.3: .*{field}.*must not be negative"):
            with_parameters(robot, {**ASYMMETRIC_PARAMS, name: -0.3})


@pytest.mark.parametrize("value", [1e300, -1e308, 1.0000001e150])
def test_run_time_values_are_bounded_like_file_numbers(roger, value):
    """A value over 1e150 in size is refused at run time as in a file (it overflows once
    multiplied), naming the parameter, by with_parameters (--params) and by compile."""
    values = {"m1": 1.0, "m2": 1.0, "l1": value, "l2": 1.0, "g": 9.81}
    for bind in (lambda v: with_parameters(roger, v), lambda v: symdyn.compile(roger, v)):
        with pytest.raises(SymdynError, match=r"parameter l1 = .* is too large \(more than 1e\+150"):
            bind(values)


def test_file_values_overridden_at_run_time_are_checked():
    """A parameter the file gave a value for, overridden at run time (--params, --model-params)."""
    robot = robot_from_data(_two_link(_link("m2"), {"m2": 1.0}))
    assert not robot.params
    with pytest.raises(SymdynError, match=r"parameter m2 = -1: link 2 .*mass -1\.0 is negative"):
        with_parameters(robot, {"m2": -1.0})


def test_compile_checks_its_values_before_building(roger, tmp_path, monkeypatch):
    monkeypatch.setenv("SYMDYN_CACHE_DIR", str(tmp_path))
    with pytest.raises(
        SymdynError, match=r"symdyn\.compile: parameter m2 = -2: link 2 .*mass -2\.0 is negative"
    ):
        symdyn.compile(roger, {**GOOD, "m2": -2.0})
    with pytest.raises(SymdynError, match="symdyn.compile: parameter m2 must be finite"):
        symdyn.compile(roger, {**GOOD, "m2": math.inf})
    assert not any(tmp_path.iterdir())  # refused before anything was built


def test_a_run_time_value_that_divides_by_zero_says_so(tmp_path):
    """mass: x/y with y = 0 was reported as "mass zoo is not a real number"; com too."""
    text = (EXAMPLES_DIR / "roger_arm.yaml").read_text()
    robot = symdyn.load_robot(_write(tmp_path / "xy.yaml", text.replace("mass: m2", "mass: x/y")))
    with pytest.raises(SymdynError) as info:
        with_parameters(robot, {"x": 1, "y": 0})
    assert str(info.value) == (
        "parameter y = 0: link 2 (forearm): field 'mass': division by zero: "
        "the values make mass = x/y infinite"
    )
    fine = with_parameters(robot, {"x": 1, "y": 4})
    assert float(sp.sympify(fine.links[1].mass).xreplace(fine.value_map)) == 0.25
    com = text.replace("com: [0, 0, 0]", "com: [x/y, 0, 0]")
    robot = symdyn.load_robot(_write(tmp_path / "com.yaml", com))
    where = r"parameter y = 0: link 1 \(upper_arm\): field 'com': division by zero"
    with pytest.raises(SymdynError, match=where):
        with_parameters(robot, {"x": 1, "y": 0})


def _write(path, text: str):
    path.write_text(text)
    return path
