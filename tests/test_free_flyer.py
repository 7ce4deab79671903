"""The free flyer's rotation against Pinocchio's quaternion and the Robot's nq, nv."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import sympy as sp
from robots import example

from symdyn.errors import SymdynError
from symdyn.model.free_flyer import base_symbols, quaternion_rotation
from symdyn.spatial.transform import Transform

pin = pytest.importorskip("pinocchio")


def test_rotation_is_pinocchios_at_random_unit_quaternions():
    rng = np.random.default_rng(7)
    for _ in range(20):
        x = rng.normal(size=4)
        x /= np.linalg.norm(x)
        R = np.array(quaternion_rotation(*x).evalf(), dtype=float)
        expected = pin.Quaternion(x[3], x[0], x[1], x[2]).toRotationMatrix()
        np.testing.assert_allclose(R, expected, atol=1e-14)


def test_rotation_is_orthonormal_on_the_unit_sphere():
    qb, _, _ = base_symbols()
    R = quaternion_rotation(*qb[3:7])
    unit = {qb[6]: sp.sqrt(1 - qb[3] ** 2 - qb[4] ** 2 - qb[5] ** 2)}
    assert sp.simplify((R.T * R - sp.eye(3)).xreplace(unit)) == sp.zeros(3)


def test_sizes_and_no_fixed_placement():
    puma = example("puma560")
    floating = dataclasses.replace(puma, floating=True)
    assert (puma.nq, puma.nv) == (6, 6)
    assert (floating.nq, floating.nv) == (13, 12)
    with pytest.raises(SymdynError, match="floating base has no fixed placement"):
        dataclasses.replace(puma, floating=True, base=Transform.from_translation([1, 0, 0]))
