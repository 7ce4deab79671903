"""`derive` against the lecture, against the numeric oracle and against the identities of M, C, V, G, F.

Expected values never come from symdyn's own derivation: they are the lecture's
closed forms (slides 17-18), the numeric spatial RNEA/CRBA of `symdyn.rnea`
(which shares no code with the symbolic routes), the raw YAML values, finite
differences, or the other derivation method.
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest
import sympy as sp
from robots import (
    EXAMPLE_NAMES,
    QUANTITIES,
    assert_close,
    assert_matrix_zero,
    derived,
    derived_robot,
    ev,
    example,
    g,
    l1,
    l2,
    m1,
    m2,
    q1,
    q2,
    qd1,
    qd2,
    random_params,
    random_state,
    rational_example,
    raw_example,
    raw_value,
    roger_arm_lecture,
    roger_arm_robot,
    roger_eye_lecture,
    roger_eye_robot,
    sym3_data,
    without_motors,
)

from symdyn.dynamics import METHODS, derive, friction_vector
from symdyn.errors import SymdynError
from symdyn.model.robot import Motor
from symdyn.parsers.robot_file import robot_from_data
from symdyn.rnea import bias_torque, friction_torque, gravity_torque, mass_matrix, rnea

SYM3 = {conv: robot_from_data(sym3_data(conv)) for conv in ("standard", "modified")}
PLANAR_3R_RATIONAL = rational_example("planar_3r")


def _zero(A: sp.Matrix) -> bool:
    return sp.simplify(A) == sp.zeros(*A.shape)


# --------------------------------------------------------------------------- 1. the lecture


@pytest.mark.parametrize("simplify", [None, False], ids=["simplified", "raw"])
@pytest.mark.parametrize("source", ["file", "robot"])
@pytest.mark.parametrize("method", METHODS)
def test_roger_eye_is_slide_17(method, source, simplify):
    robot = example("roger_eye") if source == "file" else roger_eye_robot()
    dyn = derive(robot, method=method, simplify=simplify)
    M, V, G = roger_eye_lecture()
    assert dyn.q == sp.Matrix([q1])
    assert _zero(dyn.M - M)
    assert _zero(dyn.V - V)
    assert _zero(dyn.G - G)
    assert _zero(dyn.C)
    assert sp.zeros(1, 1) == dyn.F
    assert _zero(dyn.tau - (M * dyn.qdd + V + G))


@pytest.mark.parametrize("simplify", [None, False], ids=["simplified", "raw"])
@pytest.mark.parametrize("source", ["file", "robot"])
@pytest.mark.parametrize("method", METHODS)
def test_roger_arm_is_slide_18(method, source, simplify):
    robot = example("roger_arm") if source == "file" else roger_arm_robot()
    dyn = derive(robot, method=method, simplify=simplify)
    M, V, G = roger_arm_lecture()
    assert dyn.q == sp.Matrix([q1, q2])
    assert dyn.qd == sp.Matrix([qd1, qd2])
    assert set(dyn.params) == {m1, m2, l1, l2, g}
    assert _zero(dyn.M - M)
    assert _zero(dyn.V - V)
    assert _zero(dyn.G - G)
    assert sp.zeros(2, 1) == dyn.F
    if simplify is False:  # the closed-form tau of the unsimplified result is cheap to check
        assert _zero(dyn.tau - (M * dyn.qdd + V + G))


def test_roger_arm_file_parameter_order():
    """docs/python-api.md: free parameters in order of first appearance (gravity, then link by link)."""
    robot = example("roger_arm")
    assert robot.params == sp.symbols("g l1 m1 l2 m2")
    for method in METHODS:
        assert derived("roger_arm", method).params == robot.params


# ---------------------------------------------------------------- 2. Lagrange = Newton-Euler, numerically


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_lagrange_equals_newton_euler_numerically(name):
    ne, la = derived(name, "newton-euler"), derived(name, "lagrange")
    robot = example(name)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    for _ in range(20):
        q, qd, qdd = random_state(robot, rng)
        p = random_params(robot, rng) if robot.params else None
        for quantity in QUANTITIES:
            assert_close(
                la.evaluate(quantity, q, qd, qdd, p),
                ne.evaluate(quantity, q, qd, qdd, p),
                what=f"{name} {quantity} at q={q}, qd={qd}, qdd={qdd}, p={p}",
            )


# --------------------------------------------------------------------------- 3. derive = numeric RNEA


def _check_against_rnea(robot, dyn, params, rng, states: int = 8) -> None:
    for _ in range(states):
        q, qd, qdd = random_state(robot, rng)
        what = f"{robot.name} {dyn.method} q={q} qd={qd} qdd={qdd} params={params}"
        assert_close(dyn.evaluate("tau", q, qd, qdd, params), rnea(robot, q, qd, qdd, params), what=what)
        assert_close(ev(dyn, "M", q, params=params), mass_matrix(robot, q, params), what=what)
        assert_close(dyn.evaluate("G", q, params=params), gravity_torque(robot, q, params), what=what)
        assert_close(dyn.evaluate("V", q, qd, params=params), bias_torque(robot, q, qd, params), what=what)
        assert_close(dyn.evaluate("F", q, qd, params=params), friction_torque(robot, qd, params), what=what)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_derive_equals_rnea_on_examples(name, method):
    robot = example(name)
    dyn = derived(name, method)
    assert dyn.params == robot.params
    rng = np.random.default_rng(7 + zlib.crc32(name.encode()))
    if not robot.params:
        _check_against_rnea(robot, dyn, None, rng)
        return
    for _ in range(3):
        values = random_params(robot, rng)
        _check_against_rnea(robot, dyn, values, rng, states=4)  # dyn.params order
        named = {str(p): v for p, v in zip(robot.params, values, strict=True)}
        _check_against_rnea(robot, dyn, named, rng, states=4)  # name -> value


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_derive_equals_rnea_symbolic_rpr_arm(convention, method):
    """Both DH conventions, a prismatic joint, pi/2 twists, friction and motor all symbolic."""
    robot = SYM3[convention]
    assert robot.convention == convention
    assert {lk.joint for lk in robot.links} == {"revolute", "prismatic"}
    dyn = derived_robot(robot, method)
    assert dyn.params == robot.params and len(robot.params) == 24
    rng = np.random.default_rng(11)
    for _ in range(3):
        values = random_params(robot, rng)
        _check_against_rnea(robot, dyn, values, rng, states=3)
        named = dict(zip((str(p) for p in robot.params), values, strict=True))
        _check_against_rnea(robot, dyn, named, rng, states=3)
        by_symbol = dict(zip(robot.params, values, strict=True))
        _check_against_rnea(robot, dyn, by_symbol, rng, states=1)  # symbol -> value
        shuffled = dict(reversed(list(named.items())))  # a mapping's order does not matter
        q, qd, qdd = random_state(robot, rng)
        assert_close(dyn.evaluate("tau", q, qd, qdd, shuffled), dyn.evaluate("tau", q, qd, qdd, values))


@pytest.mark.parametrize("name", ["roger_eye", "roger_arm", "planar_3r"])
def test_evaluate_shapes(name):
    """M and C are n x n (as rnea.mass_matrix), V, G, F and tau vectors of length n."""
    dyn = derived(name, "newton-euler")
    n = dyn.n
    p = np.ones(len(dyn.params)) if dyn.params else None
    q = np.full(n, 0.3)
    for quantity, shape in (
        ("M", (n, n)),
        ("C", (n, n)),
        ("V", (n,)),
        ("G", (n,)),
        ("F", (n,)),
        ("tau", (n,)),
    ):
        assert dyn.evaluate(quantity, q, q, q, p).shape == shape, quantity
    assert mass_matrix(example(name), q, p).shape == (n, n)


def test_evaluate_needs_the_free_parameters():
    dyn = derived("roger_arm", "newton-euler")
    with pytest.raises(SymdynError):
        ev(dyn, "M", [0.1, 0.2])
    with pytest.raises(SymdynError):
        ev(dyn, "M", [0.1, 0.2], params=[1.0, 2.0])  # too few
    with pytest.raises(SymdynError):
        ev(dyn, "M", [0.1, 0.2], params={"g": 9.81})  # names missing


def test_unknown_method_and_quantity_are_errors():
    with pytest.raises(SymdynError):
        derive(example("roger_eye"), method="kane")
    with pytest.raises(SymdynError):
        derived("roger_eye", "lagrange").closed_form("K")


ARM_PARAMS = [9.81, 0.5, 1.2, 0.3, 0.8]  # g, l1, m1, l2, m2 of examples/roger_arm.yaml
ARM_FREE = "g, l1, m1, l2, m2"
BOUNDARY_ERRORS = {
    "q too long": (
        lambda d: d.evaluate("tau", [0, 0, 0], params=ARM_PARAMS),
        "Dynamics.evaluate: q has 3 entries, expected 2 (one per joint)",
    ),
    "qd too short": (
        lambda d: d.evaluate("V", [0, 0], [1], params=ARM_PARAMS),
        "Dynamics.evaluate: qd has 1 entry, expected 2 (one per joint)",
    ),
    "qdd a batch": (
        lambda d: d.evaluate("tau", [0, 0], [0, 0], [[0, 0]], params=ARM_PARAMS),
        r"Dynamics.evaluate: qdd has shape (1, 2), expected (2,) (one per joint)",
    ),
    "q not numbers": (
        lambda d: d.evaluate("G", ["a", 0], params=ARM_PARAMS),
        "Dynamics.evaluate: q must hold numbers, got ['a', 0]",
    ),
    "unknown quantity": (
        lambda d: d.evaluate("X", [0, 0], params=ARM_PARAMS),
        "Dynamics.evaluate: unknown quantity 'X' (one of M, C, V, G, F, tau, bias)",
    ),
    "unknown closed form": (
        lambda d: d.closed_form("K"),
        "Dynamics.closed_form: unknown quantity 'K' (one of M, C, V, G, F, tau, bias)",
    ),
    "unknown assignment": (
        lambda d: d.assignments(("M", "Q")),
        "Dynamics.assignments: unknown quantity 'Q' (one of M, C, V, G, F, tau, bias)",
    ),
    "assignments of a bare name": (
        lambda d: d.assignments("M"),
        "Dynamics.assignments: names must be a sequence of names, got 'M'",
    ),
    "no params": (
        lambda d: d.evaluate("M", [0, 0]),
        f"Dynamics.evaluate: robot 'roger_arm' has free parameters ({ARM_FREE}); give their values",
    ),
    "too few params": (
        lambda d: d.evaluate("M", [0, 0], params=ARM_PARAMS[:2]),
        f"Dynamics.evaluate: params has 2 values, expected 5 (one per free parameter: {ARM_FREE})",
    ),
    "unknown param": (
        lambda d: d.evaluate(
            "M", [0, 0], params={"g": 9.81, "l1": 0.5, "m1": 1, "l2": 0.3, "m2": 1, "l3": 1}
        ),
        f"Dynamics.evaluate: unknown parameter(s) l3 (free parameters of robot 'roger_arm': {ARM_FREE})",
    ),
    "missing param": (
        lambda d: d.evaluate("M", [0, 0], params={"g": 9.81}),
        "Dynamics.evaluate: no value for parameter(s) l1, m1, l2, m2",
    ),
    "param not a number": (
        lambda d: d.evaluate("M", [0, 0], params=["x", *ARM_PARAMS[1:]]),
        "Dynamics.evaluate: parameter g must be a number, got 'x'",
    ),
    "params a bare number": (
        lambda d: d.evaluate("M", [0, 0], params=9.81),
        "Dynamics.evaluate: params must be a sequence of numbers or a name -> number map, got 9.81",
    ),
    "derive a non-robot": (
        lambda d: derive([1, 2]),
        "derive: robot must be a symdyn Robot (from load_robot or load_urdf), got list",
    ),
    "derive by an unknown method": (
        lambda d: derive(d.robot, method="kane"),
        "derive: unknown method 'kane' (use newton-euler or lagrange)",
    ),
    "friction of too few joints": (
        lambda d: friction_vector(d.robot, [1]),
        "friction_vector: qd has length 1, expected 2 (one per joint)",
    ),
    "derive with a bad simplify": (
        lambda d: derive(d.robot, simplify="yes"),
        "derive: simplify must be True, False or None, got 'yes'",
    ),
}


@pytest.mark.parametrize("case", list(BOUNDARY_ERRORS))
def test_bad_arguments_say_what_was_expected_and_what_came(case):
    call, message = BOUNDARY_ERRORS[case]
    with pytest.raises(SymdynError) as err:
        call(derived("roger_arm", "newton-euler"))
    assert str(err.value) == message


def test_params_for_a_robot_without_free_parameters():
    dyn = derived("roger_arm_values", "newton-euler")
    q = [0.1, 0.2]
    assert_close(dyn.evaluate("G", q, params=[]), dyn.evaluate("G", q))
    with pytest.raises(
        SymdynError, match=r"params has 1 values, expected 0 \(one per free parameter: none\)"
    ):
        dyn.evaluate("G", q, params=[1.0])
    with pytest.raises(SymdynError, match=r"unknown parameter\(s\) g \(free parameters of robot"):
        dyn.evaluate("G", q, params={"g": 9.81})


@pytest.mark.parametrize("method", METHODS)
def test_bias_is_public_and_the_same_in_every_form(method):
    """bias = V + G + F: its closed form against the other closed forms (an identity), its value
    against the numeric oracle's tau at qdd = 0, through evaluate, closed_form and the property."""
    dyn = derived("roger_arm", method)
    assert _zero(dyn.bias - (dyn.V + dyn.G + dyn.F))
    assert dyn.closed_form("bias") == dyn.bias
    robot = example("roger_arm")
    q, qd = np.array([0.4, -1.1]), np.array([0.7, -0.3])
    assert_close(dyn.evaluate("bias", q, qd, params=ARM_PARAMS), rnea(robot, q, qd, np.zeros(2), ARM_PARAMS))
    assert dyn.evaluate("bias", q, qd, params=ARM_PARAMS).shape == (2,)


# --------------------------------------------------------------------------- 4. identities, numeric


def _fd_mass_matrix_derivatives(robot, q, params, h: float = 1e-5) -> np.ndarray:
    """dM/dq_i (n, n, n) by central differences of the CRBA mass matrix."""
    out = []
    for i in range(robot.n):
        e = np.zeros(robot.n)
        e[i] = h
        out.append((mass_matrix(robot, q + e, params) - mass_matrix(robot, q - e, params)) / (2 * h))
    return np.array(out)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_identities_numeric(name, method):
    robot = example(name)
    dyn = derived(name, method)
    n = robot.n
    rng = np.random.default_rng(3 + zlib.crc32(name.encode()))
    for _ in range(5):
        q, qd, qdd = random_state(robot, rng)
        p = random_params(robot, rng) if robot.params else None
        M = ev(dyn, "M", q, params=p)
        # symmetric positive definite
        assert_close(M, M.T)
        assert np.all(np.linalg.eigvalsh((M + M.T) / 2) > 0), f"M not positive definite: {M}"
        # columns: inverse dynamics with unit accelerations, no gravity, no velocity, no friction
        for j in range(n):
            col = rnea(robot, q, np.zeros(n), np.eye(n)[j], p, gravity=False, friction=False)
            assert_close(M[:, j], col, what=f"column {j}")
        # G = rnea(q, 0, 0) without friction
        z = np.zeros(n)
        assert_close(dyn.evaluate("G", q, params=p), rnea(robot, q, z, z, p, friction=False))
        # C qd = V
        C = ev(dyn, "C", q, qd, params=p)
        assert_close(C @ qd, dyn.evaluate("V", q, qd, params=p))
        # C is the Christoffel-symbol matrix of M
        dM = _fd_mass_matrix_derivatives(robot, q, p)
        christoffel = 0.5 * (
            np.einsum("ikj,i->kj", dM, qd) + np.einsum("jki,i->kj", dM, qd) - np.einsum("kij,i->kj", dM, qd)
        )
        assert_close(C, christoffel, rtol=1e-6, what="Christoffel")
        # dM/dt - 2C is skew-symmetric, dM/dt by central differences along qd
        h = 1e-5
        Mdot = (ev(dyn, "M", q + h * qd, params=p) - ev(dyn, "M", q - h * qd, params=p)) / (2 * h)
        # N = dM/dt - 2C, N + N^T = 0  <=>  dM/dt = C + C^T
        assert_close(C + C.T, Mdot, rtol=1e-6, what="dM/dt - 2C not skew-symmetric")
        # tau = M qdd + V + G + F
        tau = dyn.evaluate("tau", q, qd, qdd, p)
        parts = M @ qdd + C @ qd + dyn.evaluate("G", q, params=p) + dyn.evaluate("F", q, qd, params=p)
        assert_close(tau, parts)


def _raw_link_extras(name: str):
    """(viscous, coulomb, reflected inertia) per link, straight from the YAML text."""
    raw = raw_example(name)
    params = raw.get("parameters") or {}
    out = []
    for link in raw["links"]:
        fr = link.get("friction") or {}
        mo = link.get("motor") or {}
        viscous = float(raw_value(fr.get("viscous", 0), params))
        coulomb = float(raw_value(fr.get("coulomb", 0), params))
        reflected = float(
            raw_value(mo.get("gear_ratio", 1), params) ** 2 * raw_value(mo.get("inertia", 0), params)
        )
        out.append((viscous, coulomb, reflected))
    return np.array(out).reshape(-1, 3)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_friction_is_viscous_plus_coulomb(name, method):
    robot = example(name)
    dyn = derived(name, method)
    viscous, coulomb, _ = _raw_link_extras(name).T
    rng = np.random.default_rng(5)
    p = random_params(robot, rng) if robot.params else None
    for qd in (rng.uniform(-2, 2, robot.n), -rng.uniform(0.1, 2, robot.n), np.zeros(robot.n)):
        qd = qd.copy()
        qd[0] = 0.0  # sign(0) = 0: no Coulomb term at rest
        want = viscous * qd + coulomb * np.sign(qd)
        assert_close(dyn.evaluate("F", qd=qd, params=p), want)
        q, _, qdd = random_state(robot, rng)
        with_f = dyn.evaluate("tau", q, qd, qdd, p)
        assert_close(with_f - rnea(robot, q, qd, qdd, p, friction=False), want)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_motor_inertia_only_on_the_diagonal(name, method):
    robot = example(name)
    dyn = derived(name, method)
    bare = without_motors(robot)
    _, _, reflected = _raw_link_extras(name).T
    rng = np.random.default_rng(9)
    for _ in range(3):
        q, qd, qdd = random_state(robot, rng)
        p = random_params(robot, rng) if robot.params else None
        assert_close(ev(dyn, "M", q, params=p) - mass_matrix(bare, q, p), np.diag(reflected))
        assert_close(dyn.evaluate("V", q, qd, params=p), bias_torque(bare, q, qd, p))
        assert_close(dyn.evaluate("G", q, params=p), gravity_torque(bare, q, p))
        tau_bare = rnea(bare, q, qd, qdd, p)
        assert_close(dyn.evaluate("tau", q, qd, qdd, p) - tau_bare, reflected * qdd, rtol=1e-8)


# --------------------------------------------------------------------------- 4. identities, symbolic


@pytest.mark.parametrize("method", METHODS)
def test_roger_arm_identities_symbolic(method):
    dyn = derived("roger_arm", method)
    n, q, qd, qdd = 2, dyn.q, dyn.qd, dyn.qdd
    M, C, V, G = dyn.M, dyn.C, dyn.V, dyn.G
    # symmetric, and positive definite by Sylvester's criterion:
    # M22 = m2 l2^2 and det M = m2 l1^2 l2^2 (m1 + m2 sin^2 q2), both > 0 for positive masses, lengths
    assert _zero(M - M.T)
    assert _zero(sp.Matrix([M[1, 1] - m2 * l2**2]))
    assert _zero(sp.Matrix([M.det() - m2 * l1**2 * l2**2 * (m1 + m2 * sp.sin(q2) ** 2)]))
    pos = {s: sp.Symbol(s.name, positive=True) for s in (m1, m2, l1, l2)}
    real = {q[1]: sp.Symbol("q2", real=True)}
    det = (m2 * l1**2 * l2**2 * (m1 + m2 * sp.sin(q2) ** 2)).xreplace(pos).xreplace(real)
    assert det.is_positive
    # columns of M: tau with unit accelerations, qd = 0, gravity off (no friction here)
    rest = {s: 0 for s in qd} | {g: 0}
    for j in range(n):
        unit = {s: int(k == j) for k, s in enumerate(qdd)}
        assert _zero(dyn.tau.xreplace(rest | unit) - M[:, j])
    # G = tau(q, 0, 0)
    assert _zero(dyn.tau.xreplace({s: 0 for s in (*qd, *qdd)}) - G)
    # C qd = V, and V = tau(q, qd, 0) without gravity
    assert _zero(C * qd - V)
    assert _zero(dyn.tau.xreplace({g: 0} | {s: 0 for s in qdd}) - V)
    # dM/dt - 2C skew-symmetric, dM/dt = sum_i dM/dq_i qd_i
    Mdot = sum((M.diff(q[i]) * qd[i] for i in range(n)), sp.zeros(n, n))
    N = Mdot - 2 * C
    assert _zero(N + N.T)


SMALL_SYMBOLIC = {
    "roger_arm": lambda: example("roger_arm"),
    "planar_3r": lambda: PLANAR_3R_RATIONAL,
    "sym3_standard": lambda: SYM3["standard"],
}


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", list(SMALL_SYMBOLIC))
def test_skew_symmetry_symbolic(name, method):
    """dM/dt - 2C is skew-symmetric and C qd = V, exactly, for arms of up to 3 joints."""
    robot = SMALL_SYMBOLIC[name]()
    dyn = derived_robot(robot, method)
    n, q, qd = robot.n, dyn.q, dyn.qd
    M, C = dyn.M, dyn.C
    assert_matrix_zero(M - M.T, n, "M - M^T")
    Mdot = sum((M.diff(q[i]) * qd[i] for i in range(n)), sp.zeros(n, n))
    N = Mdot - 2 * C
    assert_matrix_zero(N + N.T, n, "N + N^T")
    assert_matrix_zero(C * qd - dyn.V, n, "C qd - V")


@pytest.mark.parametrize("method", METHODS)
def test_symbolic_motor_inertia_and_friction(method):
    J1, J2, r1, r2 = sp.symbols("J1 J2 r1 r2")
    geared = roger_arm_robot((Motor(J1, r1), Motor(J2, r2)))
    plain = roger_arm_robot()
    dg, dp = derived_robot(geared, method), derived_robot(plain, method)
    assert _zero(dg.M - dp.M - sp.diag(r1**2 * J1, r2**2 * J2))
    for quantity in ("C", "V", "G"):
        assert _zero(dg.closed_form(quantity) - dp.closed_form(quantity))
    assert _zero(dg.tau - dp.tau - sp.Matrix([r1**2 * J1 * dg.qdd[0], r2**2 * J2 * dg.qdd[1]]))
    # the symbolic RPR arm: friction on the slide, a motor on the wrist (sym3_data)
    dyn = derived_robot(SYM3["standard"], method)
    b2, k2, J3, n3 = sp.symbols("b2 k2 J3 n3")
    qd = dyn.qd
    assert sp.Matrix([0, b2 * qd[1] + k2 * sp.sign(qd[1]), 0]) == dyn.F
    bare = derived_robot(without_motors(SYM3["standard"]), method)
    assert_matrix_zero(dyn.M - bare.M - sp.diag(0, 0, n3**2 * J3), 3, "motor")
