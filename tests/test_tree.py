"""Dynamics of kinematic trees: derive (both routes) against the numeric oracle and identities.

Expected values come from the numeric spatial RNEA/CRBA of symdyn.rnea (which shares no
code with the symbolic routes), from the other derivation method, from finite differences
(dM/dt), from the parent arrays (which joints lie on different branches) and from serial
chains cut out of the tree (the force each branch carries into the torso adds up).
"""

from __future__ import annotations

import importlib.util
import re
import time
import warnings
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from robots import (
    Y_JOINTS,
    Y_PARENTS,
    assert_close,
    branch_pairs,
    derived_robot,
    ev,
    random_state,
    solo_robot,
    tree_parents,
    tree_robot,
    y_robot,
)
from timebound import refused, within

import symdyn
from symdyn.cli.main import main
from symdyn.codegen import render
from symdyn.codegen.derivative_functions import DERIVATIVE_FUNCTION_NAMES
from symdyn.codegen.functions import FUNCTION_NAMES, build_functions
from symdyn.dynamics import METHODS, derive
from symdyn.errors import SymdynError, SymdynWarning
from symdyn.model.robot import Motor, Robot
from symdyn.model.topology import Mimic
from symdyn.rnea import (
    bias_torque,
    forward_dynamics,
    friction_torque,
    gravity_torque,
    mass_matrix,
    rnea,
)

TREES = {"ytree": y_robot(), "solo": solo_robot()}
ZERO33 = sp.ImmutableMatrix(sp.zeros(3, 3))


def check_against_oracle(robot: Robot, dyn, rng, states: int = 4) -> None:
    """tau, M, V, G, F, bias of the derivation = the numeric RNEA/CRBA; C qd = V."""
    for _ in range(states):
        q, qd, qdd = random_state(robot, rng)
        what = f"{robot.name} {dyn.method} q={q} qd={qd} qdd={qdd}"
        assert_close(dyn.evaluate("tau", q, qd, qdd), rnea(robot, q, qd, qdd), what=what)
        assert_close(ev(dyn, "M", q), mass_matrix(robot, q), what=what)
        V = bias_torque(robot, q, qd)
        assert_close(dyn.evaluate("V", q, qd), V, what=what)
        assert_close(ev(dyn, "C", q, qd) @ qd, V, what=what)
        assert_close(dyn.evaluate("G", q), gravity_torque(robot, q), what=what)
        assert_close(dyn.evaluate("F", q, qd), friction_torque(robot, qd), what=what)
        assert_close(dyn.evaluate("bias", q, qd), rnea(robot, q, qd, np.zeros_like(q)), what=what)


def check_skew(robot: Robot, dyn, rng, states: int = 3) -> None:
    """dM/dt - 2C is skew-symmetric, dM/dt by central differences of the oracle's M along qd
    (step h: error about eps |M| / h, so 1e-7 of the largest entry); M symmetric positive
    definite."""
    h = 1e-6
    for _ in range(states):
        q, qd, _ = random_state(robot, rng)
        M = ev(dyn, "M", q)
        dM = (mass_matrix(robot, q + h * qd) - mass_matrix(robot, q - h * qd)) / (2 * h)
        N = dM - 2 * ev(dyn, "C", q, qd)
        scale = max(1.0, np.abs(M).max(), np.abs(N).max())
        np.testing.assert_allclose(N + N.T, 0.0, atol=1e-7 * scale, err_msg=robot.name)
        np.testing.assert_array_equal(M, M.T)
        assert np.linalg.eigvalsh(M).min() > 0


def check_branches_decouple(robot: Robot, dyn) -> None:
    """M and C entries of joints on different branches are SymPy's exact zero."""
    pairs = branch_pairs(robot.parents)
    for name in ("M", "C"):
        compact = dyn.compact[name]
        for i, j in pairs:
            assert compact[i, j] is sp.S.Zero and compact[j, i] is sp.S.Zero, (name, i, j, compact[i, j])


# --------------------------------------------------------------------------- the Y tree and the solo legs


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", TREES)
def test_derive_equals_rnea(name, method):
    robot = TREES[name]
    dyn = derived_robot(robot, method)
    assert dyn.n == robot.nb and dyn.params == ()
    check_against_oracle(robot, dyn, np.random.default_rng(len(name)))


@pytest.mark.parametrize("name", TREES)
def test_lagrange_equals_newton_euler(name):
    robot = TREES[name]
    ne, la = derived_robot(robot, "newton-euler"), derived_robot(robot, "lagrange")
    rng = np.random.default_rng(3)
    for _ in range(4):
        q, qd, qdd = random_state(robot, rng)
        for quantity in ("M", "C", "V", "G", "F", "tau", "bias"):
            assert_close(la.evaluate(quantity, q, qd, qdd), ne.evaluate(quantity, q, qd, qdd), what=quantity)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", TREES)
def test_branches_decouple_exactly(name, method):
    robot = TREES[name]
    dyn = derived_robot(robot, method)
    check_branches_decouple(robot, dyn)
    assert len(branch_pairs(robot.parents)) == (4 if name == "ytree" else 54)
    if name == "ytree":  # the closed forms too
        M = dyn.M
        assert all(M[i, j] == 0 for i, j in branch_pairs(robot.parents))


@pytest.mark.parametrize("name", TREES)
def test_skew_symmetry_and_positive_definite(name):
    robot = TREES[name]
    check_skew(robot, derived_robot(robot, "newton-euler"), np.random.default_rng(5))


@pytest.mark.parametrize("name", TREES)
def test_gravity_is_rnea_at_rest(name):
    robot = TREES[name]
    dyn = derived_robot(robot, "newton-euler")
    rng = np.random.default_rng(9)
    for _ in range(3):
        q, _, _ = random_state(robot, rng)
        zero = np.zeros_like(q)
        assert_close(dyn.evaluate("G", q), rnea(robot, q, zero, zero, friction=False))


def _chain(robot: Robot, indices, name: str) -> Robot:
    """The links `indices` of a tree as a serial chain (each on the previous one)."""
    return replace(robot, name=name, links=tuple(replace(robot.links[i], parent=None) for i in indices))


def test_branches_add_up_in_the_torso():
    """The Y tree against serial chains cut out of it: each arm's joints see only their arm
    (tau, M rows as in the chain torso + arm), and the torso joint carries both arms, so
    tau_0 = tau_0(torso + left) + tau_0(torso + right) - tau_0(torso alone); M[0, 0] alike."""
    robot = y_robot()
    tree = derived_robot(robot, "newton-euler")
    left, right, torso = (
        derived_robot(_chain(robot, idx, nm), "newton-euler")
        for idx, nm in (((0, 1, 2), "left"), ((0, 3, 4), "right"), ((0,), "torso"))
    )
    rng = np.random.default_rng(11)
    for _ in range(4):
        q, qd, qdd = random_state(robot, rng)
        L, R, T = [0, 1, 2], [0, 3, 4], [0]
        tau_l = left.evaluate("tau", q[L], qd[L], qdd[L])
        tau_r = right.evaluate("tau", q[R], qd[R], qdd[R])
        tau_t = torso.evaluate("tau", q[T], qd[T], qdd[T])
        tau = tree.evaluate("tau", q, qd, qdd)
        assert_close(tau[1:3], tau_l[1:])
        assert_close(tau[3:], tau_r[1:])
        assert_close(tau[0], tau_l[0] + tau_r[0] - tau_t[0])
        M = ev(tree, "M", q)
        M_l, M_r, M_t = ev(left, "M", q[L]), ev(right, "M", q[R]), ev(torso, "M", q[T])
        assert_close(M[np.ix_(L, L)][1:, :], M_l[1:, :])
        assert_close(M[np.ix_(R, R)][1:, :], M_r[1:, :])
        assert_close(M[0, 0], M_l[0, 0] + M_r[0, 0] - M_t[0, 0])


def test_a_tree_with_one_branch_is_the_chain():
    """Parents written out (-1, 0, 1, ...) and parents left to default give the same program."""
    chain = _chain(y_robot(), range(5), "line")
    explicit = replace(chain, links=tuple(replace(lk, parent=i - 1) for i, lk in enumerate(chain.links)))
    assert explicit.parents == chain.parents and explicit.links != chain.links
    a, b = derive(chain, simplify=False), derive(explicit, simplify=False)
    assert a.program.assignments == b.program.assignments
    assert all(a.compact[k] == b.compact[k] for k in a.compact)


def test_solo_derives_in_seconds():
    """A 12-joint tree: all quantities (both routes) in seconds, not minutes."""
    robot = solo_robot()
    for method in METHODS:
        start = time.perf_counter()
        derive(robot, method=method)
        assert time.perf_counter() - start < 60, method


def pendulums_file(path, count: int) -> None:
    """A robot file of `count` independent pendulums: every link hangs from the base."""
    lines = ["name: pendulums", "convention: modified", "links:"]
    for i in range(count):
        lines += [f"  - name: p{i}", "    parent: null", "    joint: revolute", "    alpha: pi/2"]
        lines += [f"    a: {0.1 * (i % 7 + 1):.1f}", "    mass: 1.5", "    com: [0.3, 0, 0]"]
    path.write_text("\n".join(lines) + "\n")


def test_a_hundred_independent_pendulums_derive_in_seconds(tmp_path, capsys):
    """Issue 34 item 5: `derive` of 100 pendulums gave no answer in 120 s (every B entry rebuilt
    the n(n-1)/2 pair columns, n^5 in all); now about 2 s of CPU. Each pendulum's M and G are its
    own (the oracle's), and no Christoffel symbol couples two of them: B and Csq are zero."""
    path = tmp_path / "pendulums.yaml"
    pendulums_file(path, 100)
    capsys.readouterr()
    with within(60):
        assert main(["derive", str(path)]) == 0
    out = capsys.readouterr().out
    assert "# B = 0" in out and "# Csq = 0" in out
    entries = dict(line.split(" = ", 1) for line in out.splitlines() if line[:2] in ("M[", "G["))
    robot = symdyn.load_robot(path)
    q = np.random.default_rng(5).uniform(-np.pi, np.pi, 100)
    M, G = np.zeros((100, 100)), np.zeros(100)
    for label, text in entries.items():
        e = sp.sympify(text)
        value = float(e.subs({s: q[int(str(s)[1:]) - 1] for s in e.free_symbols}))
        if label[0] == "G":
            G[int(label[2:-1]) - 1] = value
        else:
            i, j = (int(k) - 1 for k in label[2:-1].split(","))
            M[i, j] = M[j, i] = value
    np.testing.assert_allclose(M, mass_matrix(robot, q), atol=1e-12)
    np.testing.assert_allclose(G, gravity_torque(robot, q), atol=1e-12)


# --------------------------------------------------------------------------- size limits


def chain_urdf(path, joints: int) -> None:
    """A URDF chain of `joints` revolute joints."""
    parts = ['<robot name="chain">', '<link name="l0"/>']
    for i in range(1, joints + 1):
        inertial = (
            '<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
        )
        parts.append(f'<link name="l{i}">{inertial}</link>')
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            '<origin xyz="0.1 0 0"/><axis xyz="0 0 1"/></joint>'
        )
    path.write_text("\n".join([*parts, "</robot>"]))


def mjcf_bodies(path, bodies: int, nested: bool) -> None:
    """An MJCF file of `bodies` hinged bodies, side by side or each inside the one before."""
    one = '<body name="b{i}" pos="0.1 0 0"><joint name="j{i}" axis="0 1 0"/><geom size="0.01" mass="1"/>'
    if nested:
        tree = "".join(one.format(i=i) for i in range(bodies)) + "</body>" * bodies
    else:
        tree = "".join(one.format(i=i) + "</body>" for i in range(bodies))
    path.write_text(f'<mujoco model="many"><worldbody>{tree}</worldbody></mujoco>')


LIMIT = "symdyn reads models of at most 1,000 links (MAX_LINKS)"


def test_ten_thousand_links_are_refused_when_loaded(tmp_path, capsys):
    """Issue 34 item 5: a 10,000-joint URDF chain loaded in 20 s of CPU (and could never be
    derived); an MJCF file of 10,000 bodies side by side took 7 s in MuJoCo's compiler and 24 s
    in all. Now one line at load time, in about a second, before any link is read. (10,000
    bodies nested MuJoCo refuses itself: its XML reader's depth limit.)"""
    urdf = tmp_path / "chain.urdf"
    chain_urdf(urdf, 10_000)
    assert refused(capsys, "derive", urdf, seconds=30) == (
        f"symdyn: error: {urdf}: 10,001 <link> elements: {LIMIT}"
    )
    pytest.importorskip("mujoco")
    for nested in (False, True):
        mjcf = tmp_path / f"bodies{nested}.xml"
        mjcf_bodies(mjcf, 10_000, nested)
        assert refused(capsys, "derive", mjcf, seconds=30) == (
            f"symdyn: error: {mjcf}: 10,000 bodies: {LIMIT}"
        )


def test_more_than_max_links_are_refused_in_every_format(tmp_path, capsys):
    """MAX_LINKS + 1 links: a robot file's, and an MJCF body that <replicate> makes 1,001 bodies
    (counted before MuJoCo compiles it, each body times the replicates around it)."""
    path = tmp_path / "pendulums.yaml"
    pendulums_file(path, 1001)
    assert refused(capsys, "derive", path, seconds=30) == f"symdyn: error: {path}: 1,001 links: {LIMIT}"
    pytest.importorskip("mujoco")
    mjcf = tmp_path / "replicated.xml"
    body = '<body name="b"><joint name="j" axis="0 1 0"/><geom size="0.01" mass="1"/></body>'
    mjcf.write_text(
        f'<mujoco><worldbody><replicate count="1001" offset="0.1 0 0">{body}</replicate></worldbody></mujoco>'
    )
    assert refused(capsys, "derive", mjcf, seconds=30) == (f"symdyn: error: {mjcf}: 1,001 bodies: {LIMIT}")


def test_the_limit_lets_max_links_through(tmp_path, monkeypatch):
    """At most MAX_LINKS links load (here the limit lowered to 3, so the files stay small)."""
    monkeypatch.setattr("symdyn.parsers.source.MAX_LINKS", 3)
    for count, ok in ((3, True), (4, False)):
        yaml_path, urdf = tmp_path / f"p{count}.yaml", tmp_path / f"c{count}.urdf"
        pendulums_file(yaml_path, count)
        chain_urdf(urdf, count - 1)  # count <link> elements
        for path in (yaml_path, urdf):
            if ok:
                assert symdyn.load_robot(path).nb == (count if path == yaml_path else count - 1)
            else:
                with pytest.raises(SymdynError, match="at most 3 links"):
                    symdyn.load_robot(path)


# --------------------------------------------------------------------------- random trees


@st.composite
def random_trees(draw, max_bodies: int = 7):
    parents = draw(tree_parents(2, max_bodies))
    joints = draw(
        st.lists(st.sampled_from(("revolute", "prismatic")), min_size=len(parents), max_size=len(parents))
    )
    seed = draw(st.integers(0, 2**32 - 1))
    return tree_robot(f"tree{seed}", parents, tuple(joints), seed)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_trees(max_bodies=6))
def test_random_trees_against_the_oracle(robot):
    """Up to six bodies (a seventh doubled an example's cost): branches off any link of the path,
    several at one link, depth three with a side branch. The larger tree, the 12-link quadruped
    of TREES, goes through the same checks (test_derive_equals_rnea, test_skew_symmetry_and_
    positive_definite, test_branches_decouple_exactly)."""
    dyn = derive(robot, simplify=False)
    rng = np.random.default_rng(0)
    check_against_oracle(robot, dyn, rng, states=2)
    check_skew(robot, dyn, rng, states=1)
    check_branches_decouple(robot, dyn)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_trees(max_bodies=5))
def test_random_trees_lagrange_equals_newton_euler(robot):
    ne, la = derive(robot, simplify=False), derive(robot, method="lagrange", simplify=False)
    check_branches_decouple(robot, la)
    q, qd, qdd = random_state(robot, np.random.default_rng(1))
    for quantity in ("M", "C", "G", "tau"):
        assert_close(la.evaluate(quantity, q, qd, qdd), ne.evaluate(quantity, q, qd, qdd), what=quantity)


# --------------------------------------------------------------------------- massless subtrees


def massless_arm(motor_on: int | None = None) -> Robot:
    """The Y tree with a right arm (links 4 and 5) of zero mass and inertia and no rotors."""
    robot = y_robot()
    links = list(robot.links)
    for i in (3, 4):
        motor = Motor(sp.Float(1e-4), sp.Float(10)) if i == motor_on else Motor()
        links[i] = replace(links[i], mass=sp.S.Zero, inertia=ZERO33, motor=motor)
    return replace(robot, name="yarm", links=tuple(links))


MASSLESS = "moves no mass or inertia (its subtree has neither, and the joint no rotor inertia)"
IDLE5 = f"the joint of link 'ytree5' (link 5) {MASSLESS}"
IDLE = f"the joint of link 'ytree4' (link 4) {MASSLESS}; {IDLE5}"


def test_derive_warns_about_a_massless_subtree():
    with pytest.warns(SymdynWarning) as record:
        dyn = derive(massless_arm())
    assert [str(w.message) for w in record] == [
        f"robot 'yarm': M(q) is singular: {IDLE}; forward dynamics is undefined"
    ]
    q = np.full(5, 0.4)
    M = ev(dyn, "M", q)
    assert np.all(M[3:, :] == 0) and np.all(M[:, 3:] == 0)
    with pytest.warns(SymdynWarning, match=re.escape(f"robot 'yarm': M(q) is singular: {IDLE5}; forward")):
        derive(massless_arm(motor_on=3))


def test_no_warning_without_idle_joints_or_with_symbolic_masses():
    m = sp.Symbol("m")
    robot = massless_arm()
    symbolic = replace(robot, links=(*robot.links[:4], replace(robot.links[4], mass=m)), params=(m,))
    with warnings.catch_warnings():
        warnings.simplefilter("error", SymdynWarning)
        derive(y_robot())
        derive(symbolic)  # m may be anything: undecided, no warning


def test_oracle_forward_dynamics_names_the_idle_joints():
    robot = massless_arm()
    q = np.full(5, 0.3)
    message = f"forward_dynamics: robot 'yarm': M(q) is singular: {IDLE}"
    with pytest.raises(SymdynError, match="^" + re.escape(message) + "$"):
        forward_dynamics(robot, q, q, q)
    with pytest.raises(SymdynError, match=re.escape(f"M(q) is singular: {IDLE5}") + "$"):
        forward_dynamics(massless_arm(motor_on=3), q, q, q)
    m = sp.Symbol("m")
    symbolic = replace(robot, links=(*robot.links[:4], replace(robot.links[4], mass=m)), params=(m,))
    with pytest.raises(SymdynError, match=re.escape(IDLE)):
        forward_dynamics(symbolic, q, q, q, params=[0.0])  # the value given makes it idle
    tau = rnea(symbolic, q, q, q, params=[1.5])
    assert_close(forward_dynamics(symbolic, q, q, tau, params=[1.5]), q)


def test_generated_code_leaves_out_forward_dynamics_for_idle_joints():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)
        dyn = derive(massless_arm(), simplify=False)
    message = (
        f"robot 'yarm': M(q) is singular: {IDLE}; so forward_dynamics, forward_dynamics_derivatives, "
        "mass_matrix_inverse and linearize are not generated (the other functions are)"
    )
    with pytest.warns(SymdynWarning) as record:
        specs = build_functions(dyn)
    assert [str(w.message) for w in record] == [message]
    with pytest.warns(SymdynWarning) as record:
        build_functions(dyn, ["dynamics"])
    assert [str(w.message) for w in record] == [
        message.replace(
            "forward_dynamics, forward_dynamics_derivatives, mass_matrix_inverse and linearize are",
            "forward_dynamics is",
        )
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("error", SymdynWarning)
        build_functions(dyn, ["regressor"])  # nothing that inverts M asked for: nothing to say
    kept = [n for n in FUNCTION_NAMES if n != "forward_dynamics"] + ["inverse_dynamics_derivatives"]
    assert [s.name for s in specs] == kept  # the functions that invert M are left out too
    everything = [*FUNCTION_NAMES, *DERIVATIVE_FUNCTION_NAMES]
    assert [s.name for s in build_functions(derive(y_robot(), simplify=False))] == everything


def test_the_y_tree_is_what_its_name_says():
    robot = y_robot()
    assert robot.parents == Y_PARENTS
    assert tuple(lk.joint for lk in robot.links) == Y_JOINTS
    assert all(any(lk.inertia[r, c] != 0 for r in range(3) for c in range(3) if r != c) for lk in robot.links)


# --------------------------------------------------------------------------- generated code of a tree


@pytest.mark.parametrize("which", ["ytree", "solo", "mimic"])
def test_generated_numpy_module_of_a_tree(which, tmp_path):
    """The NumPy target of a tree (the LDL^T of forward_dynamics eliminating leaves first) and
    of a tree with a mimic joint, against the oracle."""
    if which == "mimic":
        robot = tree_robot("gripmimic", (-1, 0, 1, 1), ("revolute",) * 2 + ("prismatic",) * 2, 7)
        links = (*robot.links[:3], replace(robot.links[3], mimic=Mimic(2, sp.Float(-1), sp.Float(0.02))))
        robot = replace(robot, links=links)
    else:
        robot = TREES[which]
    ((name, text),) = render(robot, targets=("python",)).items()
    path = tmp_path / name
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rng = np.random.default_rng(21)
    for _ in range(3):
        q, qd, qdd = random_state(robot, rng)
        tau = rnea(robot, q, qd, qdd)
        assert_close(module.inverse_dynamics(q, qd, qdd), tau)
        assert_close(module.mass_matrix(q).reshape(robot.n, robot.n), mass_matrix(robot, q))
        assert_close(module.forward_dynamics(q, qd, tau), qdd, rtol=1e-8)
