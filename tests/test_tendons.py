"""Fixed tendons and joint springs (symdyn.model.tendons, issue 34 item 10a) against MuJoCo.

MuJoCo's fixed tendon has the length L = c^T q and the constant Jacobian c; its armature adds
a c c^T to M, its damping and spring the passive forces -d c c^T qd and -k (L - L_spring) c,
and a joint's own spring -k (q - springref). symdyn's M and tau = M qdd + V + G + F (by the
numeric oracle, both derivation routes and the generated C) are compared with MuJoCo's
mj_fullM and mj_inverse (qfrc_inverse = M qacc + qfrc_bias - qfrc_passive, so the passive
forces are in it), with MuJoCo's constraints disabled (its frictionloss is a constraint).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import symdyn
from symdyn import SymdynError
from symdyn.rnea import gravity_torque, mass_matrix, potential_energy
from tests.robots import assert_close
from tests.test_mjcf import _mujoco, _mujoco_dynamics, _two
from tests.timebound import refused, within

mujoco = pytest.importorskip("mujoco", reason="the test extra installs mujoco")

TOL = 1e-9

#: three hinges (the middle one about another axis, with ref) and a slide, with two tendons that
#: share j2 (coefficients not 1), a tendon's default spring length (its length at springref) and
#: joint springs about springref (degrees: MJCF's default angle unit)
THREE = """<mujoco model="three">
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="a">
      <joint name="j1" axis="0 1 0" damping="0.2" armature="0.1" stiffness="2" springref="10"/>
      <geom size="0.05" pos="0.2 0 0" mass="1"/>
      <body name="b" pos="0.4 0 0">
        <joint name="j2" axis="0 0.6 0.8" ref="15"/>
        <geom size="0.05" pos="0.2 0.1 0" mass="0.5"/>
        <body name="c" pos="0.4 0 0">
          <joint name="j3" axis="1 0 0" springref="-20"/>
          <geom size="0.05" pos="0.2 0.1 0" mass="0.3"/>
          <body name="d" pos="0.3 0 0">
            <joint name="s4" type="slide" axis="1 0 0" stiffness="7" springref="0.05"/>
            <geom size="0.04" pos="0.1 0 0" mass="0.2"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="t" stiffness="20" damping="3" armature="0.5" springlength="0.1">
      <joint joint="j1" coef="1.5"/><joint joint="j2" coef="-0.7"/>
    </fixed>
    <fixed name="u" stiffness="4" damping="1" armature="0.25">
      <joint joint="j2" coef="0.3"/><joint joint="j3" coef="2"/><joint joint="s4" coef="-1.2"/>
    </fixed>
  </tendon>
</mujoco>
"""


def _file(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / f"{name}.xml"
    path.write_text(text)
    return path


def _states(n: int, count: int = 4, seed: int = 3):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield rng.uniform(-1.5, 1.5, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    path = _file(tmp_path_factory.mktemp("tendons"), "three", THREE)
    return path, symdyn.load_mjcf(path)


def test_the_tendons_and_springs_are_read(three):
    path, robot = three
    names = [t.name for t in robot.tendons]
    assert names == ["joint j1 spring", "joint s4 spring", "t", "u"]
    u = robot.tendons[3]
    assert [float(c) for c in u.coefficients] == [0, 0.3, 2, -1.2]
    model, _ = _mujoco(path)
    # u's default spring length: its length at the joints' springref (j3's -20 degrees, s4's 0.05)
    assert float(u.springlength) == pytest.approx(2 * np.deg2rad(-20) - 1.2 * 0.05, abs=1e-15)
    assert float(u.springlength) == pytest.approx(model.tendon_lengthspring[1, 0], abs=1e-15)
    assert float(robot.tendons[0].springlength) == pytest.approx(np.deg2rad(10), abs=1e-15)


def test_the_oracle_agrees_with_mujoco(three):
    path, robot = three
    model, data = _mujoco(path)
    for q, qd, qdd in _states(robot.n):
        tau, M = _mujoco_dynamics(model, data, q, qd, qdd)
        assert_close(symdyn.rnea(robot, q, qd, qdd), tau, TOL, "tau")
        assert_close(mass_matrix(robot, q), M, TOL, "M")


@pytest.mark.parametrize("method", ["newton-euler", "lagrange"])
def test_both_derivations_agree_with_mujoco(three, method):
    path, robot = three
    model, data = _mujoco(path)
    dyn = symdyn.derive(robot, method=method, simplify=False)
    for q, qd, qdd in _states(robot.n, count=3):
        tau, M = _mujoco_dynamics(model, data, q, qd, qdd)
        assert_close(dyn.evaluate("tau", q, qd, qdd), tau, TOL, "tau")
        assert_close(dyn.evaluate("M", q), M, TOL, "M")
        parts = [dyn.evaluate(k, q, qd) for k in ("V", "G", "F")]
        assert_close(dyn.evaluate("M", q) @ qdd + sum(parts), tau, TOL, "M qdd + V + G + F")
        assert_close(dyn.evaluate("bias", q, qd), sum(parts), TOL, "bias")
        # G is the gradient of the potential energy, springs included: RNEA(q, 0, 0)
        assert_close(dyn.evaluate("G", q), gravity_torque(robot, q), TOL, "G")
        Ms = dyn.evaluate("M", q)
        assert np.allclose(Ms, Ms.T, rtol=0, atol=1e-15) and np.linalg.eigvalsh(Ms).min() > 0


def test_g_is_the_gradient_of_the_potential_energy(three):
    """G = dU/dq with U gravity's and the springs' k/2 (L - L0)^2, by central differences."""
    _, robot = three
    h = 1e-6
    for q, _, _ in _states(robot.n, count=2):
        grad = [
            (potential_energy(robot, q + h * e) - potential_energy(robot, q - h * e)) / (2 * h)
            for e in np.eye(robot.n)
        ]
        assert_close(gravity_torque(robot, q), np.array(grad), 1e-7, "dU/dq")


def test_the_generated_c_agrees_with_the_oracle(three):
    """symdyn.compile builds the generated C (no special case: it reads the derivation's M, G, F)."""
    _, robot = three
    fast = symdyn.compile(robot)
    for q, qd, qdd in _states(robot.n, count=3, seed=5):
        tau = symdyn.rnea(robot, q, qd, qdd)
        assert_close(np.asarray(fast.inverse_dynamics(q, qd, qdd)), tau, TOL, "tau")
        assert_close(
            np.asarray(fast.mass_matrix(q)).reshape(robot.n, robot.n), mass_matrix(robot, q), TOL, "M"
        )
        assert_close(np.asarray(fast.gravity(q)), gravity_torque(robot, q), TOL, "G")
        assert_close(np.asarray(fast.forward_dynamics(q, qd, tau)), qdd, TOL, "qdd")


def test_the_issues_coupling_stiffness_and_damping_enter_tau(tmp_path):
    """The issue: two hinges with <fixed stiffness="20" damping="3"> left tau off by 20 (the spring);
    now symdyn's tau is MuJoCo's."""
    tendon = (
        '<tendon><fixed name="t" stiffness="20" damping="3" springlength="0.1">'
        '<joint joint="j1" coef="1"/><joint joint="j2" coef="-1"/></fixed></tendon>'
    )
    path = _two(tmp_path, "spring", tendon)
    robot = symdyn.load_mjcf(path)
    model, data = _mujoco(path)
    for q, qd, qdd in _states(robot.n):
        tau, _ = _mujoco_dynamics(model, data, q, qd, qdd)
        assert_close(symdyn.rnea(robot, q, qd, qdd), tau, TOL, "tau")


def test_the_issues_coupling_armature_enters_m(tmp_path):
    """The issue: tendon armature="0.5" over j1 - j2 was refused (MuJoCo's M[0, 1] gains a c1 c2 =
    -0.5, which no diagonal rotor inertia gives); now symdyn's M is MuJoCo's."""
    tendon = (
        '<tendon><fixed name="t" armature="0.5">'
        '<joint joint="j1" coef="1"/><joint joint="j2" coef="-1"/></fixed></tendon>'
    )
    path = _two(tmp_path, "coupled", tendon)
    robot = symdyn.load_mjcf(path)
    model, data = _mujoco(path)
    q = np.array([0.3, -0.4])
    M = _mujoco_dynamics(model, data, q, q, q)[1]
    plain = _mujoco(_two(tmp_path, "plain"))
    assert M[0, 1] - _mujoco_dynamics(*plain, q, q, q)[1][0, 1] == pytest.approx(-0.5, abs=1e-12)
    assert_close(mass_matrix(robot, q), M, TOL, "M")
    assert_close(symdyn.derive(robot).evaluate("M", q), M, TOL, "M")


def test_a_dead_band_spring_is_refused(capsys, tmp_path):
    tendon = (
        '<tendon><fixed name="t" stiffness="20" springlength="0.1 0.3">'
        '<joint joint="j1" coef="1"/><joint joint="j2" coef="-1"/></fixed></tendon>'
    )
    path = _two(tmp_path, "band", tendon)
    line = refused(capsys, "derive", path)
    assert line.startswith(
        f"symdyn: error: {path}: field 'tendon(t).springlength': fixed tendon 't' has a spring with a "
        "dead band (springlength 0.1 0.3)"
    ), line


@pytest.mark.parametrize(
    "args, what",
    [
        (("derive", "--lumped"), "derive --lumped"),
        (("derive", "--steps"), "derive --steps"),
        (("generate", "--target", "python", "--functions", "regressor"), "the regressor"),
    ],
)
def test_what_cannot_take_tendons_refuses_them(capsys, tmp_path, three, args, what):
    path, _ = three
    extra = ("--out", str(tmp_path / "out")) if args[0] == "generate" else ()
    line = refused(capsys, args[0], path, *args[1:], *extra, seconds=60)
    assert (
        line.startswith(f"symdyn: error: {path}: robot 'three': {what}")
        and "does not take fixed tendons or joint springs ('joint j1 spring' (and 3 more))" in line
    ), line
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_a_floating_base_refuses_tendons(three):
    import dataclasses

    _, robot = three
    with (
        within(10),
        pytest.raises(
            SymdynError, match="fixed tendons and joint springs .'joint j1 spring'. on a floating base"
        ),
    ):
        dataclasses.replace(robot, floating=True)
