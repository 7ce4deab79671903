"""The product form (symdyn.algorithms.product_form, `derive --form product`): the configuration
form over c_i, s_i, c_23, s_23, factored and shared. Checked by substituting the atoms and shared
quantities back (the configuration form's polynomials, exactly for exact data), between the two
routes, and by value against the numeric oracle symdyn.rnea and Pinocchio."""

from __future__ import annotations

import json
import shutil
import subprocess

import numpy as np
import pytest
import sympy as sp
from robots import (
    EXAMPLE_NAMES,
    EXAMPLES_DIR,
    derived,
    derived_rational,
    derived_robot,
    example,
    random_state,
    trig_zero,
)

from symdyn import rnea
from symdyn.algorithms.configuration_space import pair_columns
from symdyn.algorithms.product_form import parallel_groups
from symdyn.cli.main import main
from symdyn.dynamics import derive

SMALL = [n for n in EXAMPLE_NAMES if n != "panda"]  # the Panda's configuration form is 228,647 terms


def _rational(name: str, method: str):
    return derived_rational(name, method)  # once per session, shared with test_configuration_space


def _texts(pf) -> list[str]:
    return [f"{s} = {sp.sstr(e)}" for s, e in [*pf.atoms, *pf.shared]] + [
        f"{lab} = {sp.sstr(e)}" for items in pf.entries.values() for lab, e in items
    ]


@pytest.mark.parametrize("name", SMALL)
def test_exact_product_form_is_the_configuration_form_both_routes(name):
    """Atoms and shared quantities substituted back give the configuration form's polynomials
    exactly; both routes print the same product form."""
    a, b = _rational(name, "newton-euler"), _rational(name, "lagrange")
    a.product_form().check(a.configuration_space, rel=0.0)
    b.product_form().check(b.configuration_space, rel=0.0)
    assert _texts(a.product_form()) == _texts(b.product_form())


@pytest.mark.parametrize("name", SMALL)
def test_float_product_form_is_the_configuration_form(name):
    """Float data: equal within 1e-12 of each entry's largest coefficient, either route."""
    for method in ("newton-euler", "lagrange"):
        dyn = derived(name, method)
        dyn.product_form().check(dyn.configuration_space, rel=1e-12)


def test_parallel_groups_from_the_kinematics():
    assert parallel_groups(example("puma560")) == [(1, 2)]
    assert parallel_groups(example("planar_3r")) == [(0, 1, 2)]
    assert parallel_groups(example("roger_arm")) == [(0, 1)]
    assert parallel_groups(example("stanford")) == []


def _values(pf, q, params: dict) -> dict:
    """Atoms, then shared quantities in order, then the entries, evaluated as printed."""
    values = dict(params)
    values.update(q)
    out = {}
    for s, e in pf.atoms:
        out[s] = float(e.xreplace(values))
    values.update(out)
    for s, e in pf.shared:
        values[s] = float(e.xreplace(values))
    for items in pf.entries.values():
        for lab, e in items:
            out[lab] = float(sp.sympify(e).xreplace(values))
    return out


def _tau(dyn, q, qd, qdd) -> np.ndarray:
    """tau = M qdd + B [qd qd] + Csq [qd^2] + G + F, from the product form's printed entries."""
    pf = dyn.product_form()
    n = dyn.n
    subs = {s: x for s, x in zip(dyn.q, q, strict=True)}
    subs.update({s: x for s, x in zip(dyn.qd, qd, strict=True)})
    v = _values(pf, subs, {})
    M = np.array([[v[f"M[{min(i, j) + 1},{max(i, j) + 1}]"] for j in range(n)] for i in range(n)])
    tau = M @ qdd
    for k in range(n):
        for i, j in pair_columns(n):
            tau[k] += v.get(f"B[{k + 1},({i + 1},{j + 1})]", 0.0) * qd[i] * qd[j]
        tau[k] += sum(v.get(f"Csq[{k + 1},{i + 1}]", 0.0) * qd[i] ** 2 for i in range(n))
        tau[k] += v[f"G[{k + 1}]"] + v[f"F[{k + 1}]"]
    return M, tau, np.array([v[f"F[{k + 1}]"] for k in range(n)])


#: the Panda's product form (about 20 s, built once: Dynamics caches it) is checked numerically
#: only: its configuration form of 228,647 terms is too large to compare entry by entry here
AGAINST_ORACLES = ["puma560", "stanford", "panda"]


@pytest.mark.parametrize("name", AGAINST_ORACLES)
def test_product_form_agrees_with_the_oracle(name):
    dyn = derived(name, "newton-euler")
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd, qdd = random_state(dyn.robot, rng)
        M, tau, _ = _tau(dyn, q, qd, qdd)
        np.testing.assert_allclose(M, rnea.mass_matrix(dyn.robot, q), rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(tau, rnea.rnea(dyn.robot, q, qd, qdd), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", AGAINST_ORACLES)
def test_product_form_agrees_with_pinocchio(name):
    """Pinocchio's rnea, plus the motors' reflected inertia and the friction it does not model."""
    pin = pytest.importorskip("pinocchio")
    from test_frame_kinematics import pinocchio_model

    dyn = derived(name, "newton-euler")
    model = pinocchio_model(pin, dyn.robot)
    data = model.createData()
    rng = np.random.default_rng(8)
    for _ in range(3):
        q, qd, qdd = random_state(dyn.robot, rng)
        _, tau, F = _tau(dyn, q, qd, qdd)
        motors = np.array([float(lk.motor.reflected_inertia) for lk in dyn.robot.links]) * qdd
        want = pin.rnea(model, data, q, qd, qdd) + motors + F
        np.testing.assert_allclose(tau, want, rtol=1e-9, atol=1e-9)


def test_puma_size_within_the_bound():
    """Operations over every string of atoms, shared, M, B, Csq and G (issue 27: <= 1,500;
    Armstrong, Khatib and Burdick's explicit model: 1,165)."""
    pf = derived("puma560", "newton-euler").product_form()
    strings = [sp.sstr(e) for _, e in [*pf.atoms, *pf.shared]]
    strings += [sp.sstr(e) for k in ("M", "B", "Csq", "G") for _, e in pf.entries[k]]
    assert sum(sp.count_ops(sp.sympify(s)) for s in strings) <= 1500
    assert {"c23", "s23"} <= {str(s) for s, _ in pf.atoms}
    assert not any(s.count("cos(") or s.count("sin(") for s in strings[len(pf.atoms) :])


def test_roger_arm_cli_text_json_latex(capsys):
    """The two-link arm in product form: c_2 in M, s_1 and s_12 in G as on the lecture's slide
    18; JSON strings parse and substitute back to the configuration form's values."""
    path = str(EXAMPLES_DIR / "roger_arm.yaml")
    assert main(["derive", path, "--form", "product"]) == 0
    text = capsys.readouterr().out
    assert "c12 = cos(q1 + q2)" not in text  # only the atoms used
    assert "s12 = sin(q1 + q2)" in text and "c2 = cos(q2)" in text
    assert main(["derive", path, "--form", "product", "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["form"] == "product" and set(doc) >= {"atoms", "shared", "M", "B", "Csq", "G", "F"}
    sub = {sp.Symbol(k): sp.sympify(v) for k, v in doc["atoms"].items()}
    for k, v in doc["shared"].items():
        sub[sp.Symbol(k)] = sp.sympify(v).xreplace(sub)
    dyn = derived("roger_arm", "newton-euler")
    for i in range(2):
        for j in range(2):
            got = sp.sympify(doc["M"][i][j]).xreplace(sub)
            assert sp.simplify(got - dyn.M[i, j]) == 0
        assert sp.simplify(sp.sympify(doc["G"][i]).xreplace(sub) - dyn.G[i]) == 0
    assert main(["derive", path, "--form", "product", "--format", "latex"]) == 0
    tex = capsys.readouterr().out
    assert "s_{12} &= \\sin{\\left(q_{1} + q_{2} \\right)}" in tex and "M_{1,1} &=" in tex


def _json(capsys, *argv) -> dict:
    assert main(["derive", *argv, "--format", "json"]) == 0
    return json.loads(capsys.readouterr().out)


def _entries_back(doc: dict) -> dict[str, sp.Expr]:
    """Every entry of a product-form JSON with the standard parameters, base parameters, lumped
    constants, atoms and shared quantities substituted back (innermost first)."""
    sub: dict = {}
    for key in ("standard_parameters", "base_parameters", "lumped", "atoms", "shared"):
        for k, v in doc.get(key, {}).items():
            sub[sp.Symbol(k)] = sp.sympify(v).xreplace(sub)
    out = {f"G[{k + 1}]": sp.sympify(e).xreplace(sub) for k, e in enumerate(doc["G"])}
    for name in ("M", "B", "Csq"):
        for k, row in enumerate(doc[name]):
            out.update({f"{name}[{k + 1},{c + 1}]": sp.sympify(e).xreplace(sub) for c, e in enumerate(row)})
    return out


def test_roger_arm_lumped_product_form_is_the_product_form(capsys):
    """`--form product --lumped`: the coefficients are derive --lumped's constants (the same
    names and definitions, over the base parameters: the arm's data is symbolic), and with them
    substituted back every entry is exactly the product form's without lumping."""
    path = str(EXAMPLES_DIR / "roger_arm.yaml")
    lumped = _json(capsys, path, "--form", "product", "--lumped")
    plain = _json(capsys, path, "--form", "product")
    configuration = _json(capsys, path, "--lumped")
    for key in ("lumped", "base_parameters", "standard_parameters"):
        assert lumped[key] == configuration[key], key
    assert lumped["M"][0][0] == "I1 + I2*c2" and lumped["G"][0] == "g1*s1 + g2*s12"
    want, got = _entries_back(plain), _entries_back(lumped)
    assert set(want) == set(got)
    for label, e in got.items():
        assert trig_zero(e - want[label], 2), label
    assert main(["derive", path, "--form", "product", "--lumped", "--format", "latex"]) == 0
    tex = capsys.readouterr().out
    assert "I_{1} &= \\mathrm{Izz}_{1R} + \\mathrm{Izz}_{2}" in tex
    assert "M_{1,1} &= I_{1} + I_{2} c_{2}" in tex


def test_lumped_product_form_of_the_puma(capsys):
    """The PUMA 560: numeric data (constants named by value) within 1e-12; its first four links
    with symbolic inertial parameters (exact base parameters): the lumped product form with the
    constants' values substituted is exactly the configuration form, as the product form is."""
    from test_lumped import _puma

    from symdyn.lumped import lumped_product_form

    dyn = derived("puma560", "newton-euler")
    pf, lc = lumped_product_form(dyn)
    assert lc.base is None and len(lc.definitions()) > 20
    pf.check(dyn.configuration_space, rel=1e-12, constants=lc.values())
    dyn = derive(_puma(4, True), simplify=False)
    pf, lc = lumped_product_form(dyn)
    assert lc.base is not None and not lc.notes()
    assert {str(s) for s in lc.values()} >= {"I1", "Izz1R"}
    pf.check(dyn.configuration_space, rel=0.0, constants=lc.values())
    dyn.product_form().check(dyn.configuration_space, rel=0.0)


def test_product_form_refuses_prune(capsys):
    path = str(EXAMPLES_DIR / "roger_arm.yaml")
    assert main(["derive", path, "--form", "product", "--prune", "0.01"]) == 1
    err = capsys.readouterr().err
    assert "--form product" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("name", SMALL)
def test_json_strings_read_back_exactly(name):
    """Every string of the JSON keys parses with sympy.sympify to the expression it was written
    from (exact data)."""
    from symdyn.cli.derive_product import product_json

    dyn = _rational(name, "newton-euler")
    pf = dyn.product_form()
    doc = product_json(dyn)

    def same(text: str, e: sp.Expr) -> bool:
        """Equal, floats (a decimal left in the data: SCARA's 0.12*pi**2) up to their 15 printed digits."""
        d = sp.expand(sp.sympify(text) - e)
        return d.xreplace({f: 0 for f in d.atoms(sp.Float) if abs(f) < 1e-15}) == 0

    assert list(doc["atoms"]) == [str(s) for s, _ in pf.atoms]
    assert all(same(v, e) for v, (_, e) in zip(doc["atoms"].values(), pf.atoms, strict=True))
    assert list(doc["shared"]) == [str(s) for s, _ in pf.shared]
    assert all(same(v, e) for v, (_, e) in zip(doc["shared"].values(), pf.shared, strict=True))
    for label, e in pf.entries["M"]:
        i, j = (int(x) - 1 for x in label[2:-1].split(","))
        assert same(doc["M"][i][j], e) and same(doc["M"][j][i], e), label
    assert all(same(v, e) for v, (_, e) in zip(doc["G"], pf.entries["G"], strict=True))


@pytest.mark.parametrize("case", ["chain", "gripper", "ytree"])
def test_mimic_joints_and_trees(case):
    """Mimic joints (multiples -2 q_1 + 0.3, 0.5 q_4: constant angles as number factors, a
    fractional multiple as its own atom) and kinematic trees: still the configuration form."""
    from test_mimic import CASES as MIMIC_CASES

    dyn = derived_robot(MIMIC_CASES[case][0], "newton-euler")  # test_mimic's, test_configuration_space's
    dyn.product_form().check(dyn.configuration_space, rel=1e-12)


def test_check_catches_a_wrong_entry():
    """The check is not vacuous: a changed coefficient of a shared quantity fails it."""
    import dataclasses

    dyn = _rational("roger_arm", "newton-euler")
    pf = dyn.product_form()
    (name, e), *rest = pf.shared
    wrong = dataclasses.replace(pf, shared=[(name, e + sp.Rational(1, 10**9)), *rest])
    with pytest.raises(AssertionError):
        wrong.check(dyn.configuration_space, rel=0.0)


@pytest.mark.skipif(not shutil.which("pdflatex"), reason="no pdflatex")
def test_puma_latex_compiles(tmp_path):
    from symdyn.cli.derive_product import product_latex

    tex = product_latex(derived("puma560", "newton-euler"))
    assert "c_{23} &= \\cos{\\left(q_{2} + q_{3} \\right)}" in tex and "C^{\\mathrm{sq}}_{" in tex
    (tmp_path / "puma.tex").write_text(tex)
    (tmp_path / "doc.tex").write_text(
        "\\documentclass{article}\n\\usepackage{amsmath}\n\\begin{document}\n\\input{puma.tex}\n\\end{document}\n"
    )
    cmd = ["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "doc.tex"]
    proc = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout[-3000:]
    assert "Undefined control sequence" not in proc.stdout


def _dh_chain(n: int) -> dict:
    """A numeric standard-DH chain of n revolute joints, every other twist pi/2."""
    link = {"joint": "revolute", "a": 0.3, "d": 0.1, "theta": 0, "mass": 1.0, "com": [0.1, 0.02, 0.01],
            "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015, "ixy": 0, "ixz": 0, "iyz": 0}}  # fmt: skip
    links = [{**link, "name": f"l{i + 1}", "alpha": "pi/2" if i % 2 == 0 else 0} for i in range(n)]
    return {"name": f"arm{n}", "convention": "standard", "gravity": [0, 0, -9.81], "links": links}


def test_a_12_joint_arm_is_refused_within_seconds_pointing_to_compact(tmp_path, capsys):
    """It ended in an internal MemoryError after 131 s; the limit is checked before anything is built."""
    import yaml
    from timebound import refused, within

    from symdyn.algorithms.product_form import MAX_PRODUCT_JOINTS
    from symdyn.errors import SymdynError
    from symdyn.parsers.robot_file import robot_from_data

    path = tmp_path / "arm12.yaml"
    path.write_text(yaml.safe_dump(_dh_chain(12)))
    for extra in ([], ["--lumped", "--format", "json"], ["--format", "latex"]):
        line = refused(capsys, "derive", path, "--form", "product", *extra, seconds=10)
        assert line == (
            f"symdyn: error: the product form is limited to chains of {MAX_PRODUCT_JOINTS} joints and "
            "robot 'arm12' has one of 12 (it grows about threefold with each joint); use --form compact "
            "(the dynamics as named intermediates)"
        )
    dyn = derive(robot_from_data(_dh_chain(12), "arm12.yaml"))
    with within(5), pytest.raises(SymdynError, match="limited to chains of 10 joints"):
        dyn.product_form()


def test_a_configuration_form_beyond_the_terms_bound_is_refused(monkeypatch):
    """Under the joint limit, a form larger than MAX_PRODUCT_TERMS is refused once its size is known."""
    from symdyn.algorithms import product_form as module
    from symdyn.errors import SymdynError

    dyn = derived("puma560", "newton-euler")
    terms = dyn.configuration_space.terms
    assert terms == 1198  # docs/speed.md; the bound is checked against it
    module.check_product_size(dyn.robot, dyn.configuration_space)
    monkeypatch.setattr(module, "MAX_PRODUCT_TERMS", terms - 1)
    with pytest.raises(SymdynError, match=f"limited to configuration forms of {terms - 1:,} terms"):
        module.product_form(dyn.robot, dyn.configuration_space, dyn.closed_form("F"))
