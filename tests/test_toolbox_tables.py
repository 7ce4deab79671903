"""A Robotics Toolbox model translated into a robot file gives the toolbox's dynamics.

tests/data/toolbox/puma560_toolbox.yaml is the Robotics Toolbox for Python's PUMA 560 written as
a robot file by the rules of docs/robot-files.md ("Friction and rotor inertia across formats"):
the toolbox's motor-side B, Tc and Jm with its gear ratios G become symdyn's joint-side friction
(G**2 B, |G| Tc+ and |G| |Tc-|) and motor (Jm, G). tests/data/toolbox/puma560_toolbox.json holds
the toolbox's own rne, inertia, gravload and coriolis @ qd at fixed states, computed by the
script beside it (puma560_toolbox.py) with roboticstoolbox-python 1.5.0, which symdyn's test
extra does not install. symdyn's numeric oracle must agree to 1e-12.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import symdyn
from symdyn.rnea import bias_torque, gravity_torque, mass_matrix
from tests.robots import assert_close

DATA = Path(__file__).resolve().parent / "data" / "toolbox"
REFERENCE = json.loads((DATA / "puma560_toolbox.json").read_text())
TOL = 1e-12


@pytest.fixture(scope="module")
def puma():
    with warnings.catch_warnings():  # the toolbox's published inertias: link 1's and link 3's
        warnings.simplefilter("ignore", symdyn.SymdynWarning)  # break the triangle inequality
        return symdyn.load_robot(DATA / "puma560_toolbox.yaml")


@pytest.mark.parametrize("k", range(len(REFERENCE["states"])))
def test_the_toolbox_puma_560_as_a_robot_file(puma, k):
    state = REFERENCE["states"][k]
    q, qd, qdd = (np.array(state[key]) for key in ("q", "qd", "qdd"))
    assert_close(symdyn.rnea(puma, q, qd, qdd), state["rne"], TOL, "rne (friction and motors included)")
    assert_close(mass_matrix(puma, q), state["inertia"], TOL, "inertia")
    assert_close(gravity_torque(puma, q), state["gravload"], TOL, "gravload")
    assert_close(bias_torque(puma, q, qd), state["coriolis_qd"], TOL, "C qd")
