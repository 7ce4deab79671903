"""Baumgarte's functions (symdyn.codegen.contact_baumgarte, group contact_baumgarte) in every
target, built alone (`symdyn generate --functions contact_baumgarte`), on a planar two-link arm with
a 6d contact and a point contact at its tip (the dynamics with the point held: the 6d contact's six
rows on two joints are a redundant set, solved damped): the C (strict flags, its NCONTACT,
NLAMBDA and NANCHOR macros) and NumPy values against the oracle (symdyn.oracle.contact_baumgarte),
the orientation error sin(theta) u against a rotation of known angle, the group absent by
default, and the other targets' files naming both functions (LaTeX: the stabilised constraint).
The xArm 7 and Solo-12 are checked in tests/test_contact_functions.py.
"""

from __future__ import annotations

import ctypes

import numpy as np
import pytest
import yaml
from cbuild import compilers, header_macros, load_c_and_numpy
from test_contacts import TWO

import symdyn
from symdyn.algorithms.contact_dynamics import DAMPING
from symdyn.cli.main import main
from symdyn.codegen import context, render
from symdyn.errors import SymdynError
from symdyn.oracle.contact_baumgarte import contact_error, contact_forward_dynamics_baumgarte
from symdyn.oracle.contact_kinematics import contact_poses, contact_rows

TARGETS = ("c", "python", "casadi", "jax", "matlab", "torch", "latex")


@pytest.fixture(scope="module")
def two():
    robot = symdyn.robot_from_data(yaml.safe_load(TWO))
    return symdyn.robot_from_data(
        yaml.safe_load(TWO)
        | {"contacts": [{"frame": "tip", "type": "6d"}, {"name": "point", "frame": "tip"}]}
    ), robot


def _rotation(axis, angle) -> np.ndarray:
    u = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def test_every_target_has_the_group_and_c_and_numpy_agree_with_the_oracle(two, tmp_path):
    robot, _ = two
    files = render(robot, targets=TARGETS, functions=("contact_baumgarte",))
    for name, text in files.items():
        if name.endswith((".h", ".py", ".m", ".tex")) and "contact" in text:
            assert "contact_error" in text.replace("\\_", "_"), name
    assert any("contact_forward_dynamics_baumgarte" in t for n, t in files.items() if n.endswith(".m"))
    tex = files["two_dynamics.tex"]
    assert "J_c \\ddot{q} + \\gamma = -K_d\\, J_c \\dot{q} - K_p\\, e(q)" in tex and "a_{1,4}" in tex
    macros = header_macros(files["two_dynamics.h"])
    assert (macros["two_NCONTACT"], macros["two_NLAMBDA"], macros["two_NANCHOR"]) == (
        "2",
        "9",
        "(two_NCONTACT*12)",
    )
    if not compilers():
        pytest.skip("no C compiler")
    lib, module = load_c_and_numpy(files, tmp_path, "two")
    ptr = ctypes.POINTER(ctypes.c_double)

    def c_call(name, sizes, *args):
        outs = [np.full(n, np.nan) for n in sizes]
        arrays = [np.ascontiguousarray(a, dtype=float) for a in args] + [np.zeros(1)] + outs
        getattr(lib, f"two_{name}")(*[a.ctypes.data_as(ptr) for a in arrays])
        return outs

    q, v, tau = np.array([0.4, -0.7]), np.array([0.3, 0.9]), np.array([0.2, -0.1])
    T = contact_poses(robot, contact_rows(robot, robot.contacts), q[None])[0]
    turn = _rotation([0.2, -0.3, 1.0], 0.3)
    anchor = np.r_[T[0, :3, 3] + [0.01, -0.02, 0.005], (T[0, :3, :3] @ turn.T).reshape(-1)]
    anchor = np.r_[anchor, T[1, :3, 3] - [0.0, 0.01, 0.0], np.eye(3).reshape(-1)]  # z: the arm's plane
    err = contact_error(robot, None, q, anchor)
    # the 6d contact's orientation error: R_a^T R = turn, sin(0.3) about its axis
    assert np.allclose(err[3:6], np.sin(0.3) * np.array([0.2, -0.3, 1.0]) / np.linalg.norm([0.2, -0.3, 1.0]))
    assert np.allclose(err[6:], [0.0, 0.01, 0.0])
    for got in (module.contact_error(q, anchor), c_call("contact_error", [9], q, anchor)[0]):
        assert np.allclose(got, err, rtol=0, atol=1e-14)
    for active in ([0.0, 1.0], [0.0, 0.0]):
        want = contact_forward_dynamics_baumgarte(
            robot, None, q, v, tau, active, anchor, (50.0, 5.0), damping=float(DAMPING)
        )
        for qdd, lam in (
            module.contact_forward_dynamics_baumgarte(q, v, tau, active, anchor, [50.0, 5.0]),
            c_call("contact_forward_dynamics_baumgarte", [2, 9], q, v, tau, active, anchor, [50.0, 5.0]),
        ):
            assert np.allclose(qdd, want[0], rtol=1e-9, atol=1e-9) and np.allclose(
                lam, want[1], rtol=1e-9, atol=1e-9
            )


def test_the_group_is_named_only(two, tmp_path, capsys):
    robot, plain = two
    assert not {"contact_error", "contact_forward_dynamics_baumgarte"} & {
        f.name for f in context(robot).functions
    }
    assert not context(plain, functions=("contact_baumgarte",)).functions  # no contacts: none
    path = tmp_path / "two.yaml"
    path.write_text(TWO)
    args = ["generate", str(path), "--out", str(tmp_path / "o"), "--contacts", "tip:6d", "l1"]
    assert main([*args, "--functions", "contacts", "contact_baumgarte", "--target", "c"]) == 0
    header = (tmp_path / "o" / "two_dynamics.h").read_text()
    assert "void two_contact_error(" in header and "#define two_NANCHOR (two_NCONTACT*12)" in header


def test_the_oracle_refuses_bad_anchors_and_gains(two):
    robot, _ = two
    q = np.zeros(2)
    good = np.tile(np.r_[np.zeros(3), np.eye(3).reshape(-1)], 2)
    assert np.array_equal(
        contact_error(robot, None, q, good), contact_error(robot, None, q, good.reshape(2, 12))
    )
    for anchor, message in (
        (good[:12], "anchor must be 2 x 12"),
        (good.reshape(4, 6), "anchor must be 2 x 12"),
        (np.where(np.arange(24) == 3, np.nan, good), "not finite"),
        ("ab", "anchor must hold numbers"),
    ):
        with pytest.raises(SymdynError, match=message):
            contact_error(robot, None, q, anchor)
    for gains, message in (
        ((-1.0, 0.0), "Kp must be in"),
        ((1.0, np.nan), "Kd must be"),
        ((1.0,), "gains must be"),
    ):
        with pytest.raises(SymdynError, match=message):
            contact_forward_dynamics_baumgarte(robot, None, q, q, q, [0, 1], good, gains)
