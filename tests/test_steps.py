"""The derivation step by step (symdyn.apps.checking.steps, `symdyn derive --steps`, `symdyn check` steps).

Expected values come from an independent route: the numeric oracle's spatial recursion
(Featherstone's spatial vectors at the body origin, symdyn.oracle.spatial) rerun here so that
its per-link velocities, accelerations and transmitted forces can be read, the oracle's
energies (symdyn.rnea.kinetic_energy, potential_energy) and mass matrix, and Craig's closed
forms for his two-link arm (examples/answers/craig_two_link_answers.yaml, transcribed from
the book).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from robots import assert_close, example

from symdyn import rnea
from symdyn.apps.checking.check import check_answers
from symdyn.apps.checking.steps import derivation_steps
from symdyn.cli.main import main
from symdyn.errors import SymdynError
from symdyn.oracle.inputs import numeric_model
from symdyn.oracle.spatial import crm, joint_poses, motion_transforms, mv, subspaces

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ROBOTS = ("craig_two_link_values", "planar_prismatic_modified", "puma560", "mr_ur5", "scara")


def spatial_internals(robot, q, qd, qdd):
    """Per link (omega, omegadot, classical vdot of the origin, vdot of the centre of mass,
    n, f transmitted from the parent), body frame, by the spatial-vector recursion."""
    mdl = numeric_model(robot.resolved(), ())
    q, qd, qdd = (np.asarray(x, dtype=float)[None, :] for x in (q, qd, qdd))
    X, S = motion_transforms(joint_poses(mdl, q)), subspaces(mdl)
    a0 = np.zeros((1, 6))
    a0[:, 3:] = -mdl.gravity
    vs, accs, forces, out = [], [], [], []
    for i in range(mdl.nb):
        p = mdl.parent[i]
        v_p, a_p = (np.zeros((1, 6)), a0) if p < 0 else (vs[p], accs[p])
        v = mv(X[i], v_p) + S[i] * qd[:, i, None]
        a = mv(X[i], a_p) + S[i] * qdd[:, i, None] + mv(crm(v), S[i]) * qd[:, i, None]
        vs.append(v)
        accs.append(a)
        Iv = mv(mdl.spatial_inertia[i], v)
        forces.append(mv(mdl.spatial_inertia[i], a) - mv(np.swapaxes(crm(v), -1, -2), Iv))
        w, wd, v_o, a_o = v[0, :3], a[0, :3], v[0, 3:], a[0, 3:]
        c = mdl.com[i]
        vdot = a_o + np.cross(w, v_o)  # classical acceleration of the body origin
        vc = v_o + np.cross(w, c)
        vdot_c = a_o + np.cross(wd, c) + np.cross(w, vc)
        out.append({"omega": w, "omegadot": wd, "vdot": vdot, "vdotC": vdot_c})
    for i in reversed(range(mdl.nb)):
        out[i]["n"], out[i]["f"] = forces[i][0, :3], forces[i][0, 3:]
        if mdl.parent[i] >= 0:
            forces[mdl.parent[i]] = forces[mdl.parent[i]] + mv(np.swapaxes(X[i], -1, -2), forces[i])
    return out, mdl


def _robot(name):
    if name == "craig_two_link_values":
        r = example("craig_two_link")
        return r.numeric({"g": 9.81, "m1": 1.5, "l1": 0.7, "m2": 0.9, "l2": 0.4})
    return example(name)


def _numbers(step):
    return np.array([float(x) for x in step.value])


@pytest.mark.parametrize("name", ROBOTS)
def test_newton_euler_steps_equal_the_spatial_recursion(name):
    robot = _robot(name)
    rng = np.random.default_rng(41)
    q, qd, qdd = rng.uniform(-1.5, 1.5, size=(3, robot.n))
    steps = derivation_steps(robot, at={"q": q, "qd": qd, "qdd": qdd})
    want, mdl = spatial_internals(robot, q, qd, qdd)
    for i in range(robot.nb):
        for k in ("omega", "omegadot", "vdot", "vdotC", "n", "f"):
            assert_close(_numbers(steps.get(k, i + 1)), want[i][k], what=f"{k}_{i + 1}")
        assert_close(_numbers(steps.get("F", i + 1)), mdl.mass[i] * want[i]["vdotC"], what=f"F_{i + 1}")
        w, wd, Ic = want[i]["omega"], want[i]["omegadot"], mdl.inertia[i]
        assert_close(_numbers(steps.get("N", i + 1)), Ic @ wd + np.cross(w, Ic @ w), what=f"N_{i + 1}")
    tau = [float(steps.get("tau", i + 1).value[0]) for i in range(robot.n)]
    assert_close(tau, rnea(robot, q, qd, qdd))


@pytest.mark.parametrize("name", ("craig_two_link_values", "planar_prismatic_modified"))
def test_lagrange_steps_equal_the_oracles_energies(name):
    robot = _robot(name)
    rng = np.random.default_rng(5)
    q, qd, qdd = rng.uniform(-1.5, 1.5, size=(3, robot.n))
    steps = derivation_steps(robot, "lagrange", at={"q": q, "qd": qd, "qdd": qdd})
    T = sum(float(steps.get("T", i + 1).value[0]) for i in range(robot.nb))
    U = sum(float(steps.get("U", i + 1).value[0]) for i in range(robot.nb))
    assert_close(T, rnea.kinetic_energy(robot, q, qd))
    # the oracle's potential energy may differ by a constant: compare differences of two states
    q2 = q + 0.3
    U2 = sum(
        float(x.value[0])
        for x in derivation_steps(robot, "lagrange", at={"q": q2, "qd": qd, "qdd": qdd}).steps
        if x.name == "U"
    )
    assert_close(U2 - U, rnea.potential_energy(robot, q2) - rnea.potential_energy(robot, q))
    p = [float(steps.get("dL_dqd", j + 1).value[0]) for j in range(robot.n)]
    assert_close(p, rnea.mass_matrix(robot, q) @ qd)  # dL/dqd = M(q) qd
    tau = [float(steps.get("tau", j + 1).value[0]) for j in range(robot.n)]
    assert_close(tau, rnea(robot, q, qd, qdd))


def test_craig_closed_forms_match_and_a_slip_is_located():
    """Every step of Craig's example 6.6 as the book prints it, then a sign slip in omega_2."""
    robot = example("craig_two_link")
    answers = EXAMPLES / "answers" / "craig_two_link_answers.yaml"
    report = check_answers(robot, answers)
    assert report.ok and report.first_step is None
    assert {r.quantity for r in report.results} >= {"omega_2", "vdotC_2", "f_1", "n_1", "tau"}
    data = __import__("yaml").safe_load(answers.read_text())
    data["steps"][2]["vdot"][0] = "l1*qdd1*sin(q2) + l1*qd1**2*cos(q2) + g*sin(q1 + q2)"
    data["steps"]["link1"]["n"][2] = "0"
    report = check_answers(robot, data)
    assert not report.ok
    assert report.first_step.startswith("vdot_2 (outward iteration, link 2, frame {2}")
    assert {r.label for r in report.differing} >= {"vdot_2[1]", "n_1[3]"}


def test_symbolic_steps_of_the_two_link_arm_are_craigs():
    steps = derivation_steps(example("craig_two_link"))
    q1, q2, qd1, qd2, qdd1, qdd2, l1, l2, g = sp.symbols("q1 q2 qd1 qd2 qdd1 qdd2 l1 l2 g")
    assert list(steps.get("omega", 2).value) == [0, 0, qd1 + qd2]
    want = l1 * qdd1 * sp.cos(q2) + l1 * qd1**2 * sp.sin(q2) + g * sp.cos(q1 + q2)
    assert sp.simplify(steps.get("vdot", 2).value[1] - want) == 0
    assert steps.get("omega", 1).frame.startswith("{1}: Craig's (modified DH) frame 1")


def _run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_formats(capsys):
    robot = str(EXAMPLES / "craig_two_link.yaml")
    at = ["--at", "q=0.1,0.2", "qd=1,2", "qdd=0,1", "g=9.81", "m1=1", "m2=2", "l1=1", "l2=0.5"]
    code, text, _ = _run(capsys, "derive", robot, "--steps", *at)
    assert code == 0 and "## outward iteration, link 1 (frame {1}:" in text and "omega_2 = [0, 0, 3]" in text
    code, out, _ = _run(capsys, "derive", robot, "--steps", *at, "--format", "json")
    doc = json.loads(out)
    tau = [s["value"][0] for s in doc["steps"] if s["quantity"] == "tau"]
    want = rnea(example("craig_two_link").numeric([9.81, 1, 1, 2, 0.5]), [0.1, 0.2], [1, 2], [0, 1])
    assert_close(tau[::-1], want)
    # unsimplified (--simplify no): simplify_entry on symbolic steps, the same for both methods, is
    # checked by test_symbolic_steps_of_the_two_link_arm_are_craigs; trigsimp was 3/4 of this test
    code, out, _ = _run(
        capsys, "derive", robot, "--steps", "--method", "lagrange", "--format", "latex", "--simplify", "no"
    )
    assert code == 0 and "\\frac{d}{dt} \\frac{\\partial L}{\\partial \\dot{q}_{1}}" in out


@pytest.mark.parametrize(
    "extra,message",
    [
        (["--at", "q=0.1,0.2", "qd=1,2"], "give qdd"),
        (["--at", "q=0.1", "qd=1,2", "qdd=0,0"], "q has 1 entry, expected 2"),
        (["--at", "q=0.1,0.2", "qd=1,2", "qdd=0,0", "mass=3"], "unknown name(s) mass"),
        (["--at", "q=a,b"], "must be numbers"),
    ],
)
def test_cli_bad_state_gives_one_line(capsys, extra, message):
    code, out, err = _run(capsys, "derive", str(EXAMPLES / "craig_two_link.yaml"), "--steps", *extra)
    assert code == 1 and out == "" and message in err and len(err.strip().splitlines()) == 1


def test_at_needs_steps_and_mimic_robots_are_refused(capsys):
    code, _, err = _run(capsys, "derive", str(EXAMPLES / "craig_two_link.yaml"), "--at", "q=0,0")
    assert code == 1 and "add --steps" in err
    with pytest.raises(SymdynError, match="newton-euler or lagrange"):
        derivation_steps(example("craig_two_link"), "kane")
