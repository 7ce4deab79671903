"""A mass matrix singular at run time (symdyn.apps.compilation.singular): an error, not NaN.

`symdyn.compile(robot, {"m2": 0})` passes the physical checks (a zero mass is allowed) but
makes M singular for Roger's arm, whose links are point masses: forward dynamics used to
return NaN without a word. The oracle symdyn.rnea confirms M's smallest eigenvalue is zero.
"""

from __future__ import annotations

import numpy as np
import pytest
from robots import EXAMPLES_DIR

import symdyn
from symdyn import rnea
from symdyn.errors import SymdynError

GOOD = {"m1": 1.0, "m2": 0.5, "l1": 0.3, "l2": 0.2, "g": 9.81}
Q, QD, TAU = np.array([0.3, -0.7]), np.array([0.2, 0.1]), np.array([0.5, -0.2])


@pytest.fixture(scope="module")
def roger():
    return symdyn.load_robot(EXAMPLES_DIR / "roger_arm.yaml")


def test_singular_at_run_time_raises(roger):
    zero = {**GOOD, "m2": 0.0}
    M = rnea.mass_matrix(roger, Q, zero)
    assert abs(np.linalg.eigvalsh(M)[0]) < 1e-12  # the oracle: M is singular with m2 = 0
    plant = symdyn.compile(roger, zero)
    for name, args in [
        ("forward_dynamics", (Q, QD, TAU)),
        ("mass_matrix_inverse", (Q,)),
        ("forward_dynamics_derivatives", (Q, QD, TAU)),
    ]:
        if name not in plant.functions:
            continue
        with pytest.raises(
            SymdynError, match=rf"{name}: the mass matrix M\(q\) is singular at q = \[0\.3, -0\.7\]"
        ):
            getattr(plant, name)(*args)
    batch = np.stack([Q, 2 * Q])
    with pytest.raises(SymdynError, match="m2 = 0 .*smallest eigenvalue is 0"):
        plant.forward_dynamics(batch, np.zeros((2, 2)), np.zeros((2, 2)))


def test_regular_values_unchanged_and_nan_in_is_nan_out(roger):
    plant = symdyn.compile(roger, GOOD)
    expected = rnea.forward_dynamics(roger, Q, QD, TAU, GOOD)
    np.testing.assert_allclose(plant.forward_dynamics(Q, QD, TAU), expected, rtol=1e-12)
    batch = plant.forward_dynamics(np.stack([Q, Q]), np.stack([QD, QD]), np.stack([TAU, TAU]))
    np.testing.assert_allclose(batch, [expected, expected], rtol=1e-12)
    # a NaN input is the caller's: NaN comes back, nothing is said about M
    out = plant.forward_dynamics(np.array([np.nan, 0.0]), QD, TAU)
    assert np.isnan(out).all()
