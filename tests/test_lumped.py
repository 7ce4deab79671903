"""`derive --lumped` over the base parameters (symdyn.lumped): the printed entries, with the
lumped constants, the base parameters and the standard parameters substituted back as printed,
are the unlumped entries exactly, the lecture's closed forms for Roger's arm, and the numeric
oracle symdyn.rnea at random parameter values."""

from __future__ import annotations

import re
import warnings
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import yaml
from robots import example

from symdyn import rnea, standard_parameters
from symdyn.cli.main import main
from symdyn.dynamics import derive
from symdyn.lumped import lumped_constants, symbolic_inertia
from symdyn.parsers.robot_file import robot_from_data

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SECTIONS = ("lumped constants", "base parameters", "standard parameters")


def _run(capsys, path, *argv) -> str:
    assert main(["derive", str(path), *argv]) == 0
    return capsys.readouterr().out


def _parse(text: str) -> tuple[dict[str, sp.Expr], dict[str, dict[sp.Symbol, sp.Expr]], list[str]]:
    """(entries by label, definitions per section, notes) of `derive` text."""
    entries: dict[str, sp.Expr] = {}
    sections: dict[str, dict[sp.Symbol, sp.Expr]] = {s: {} for s in SECTIONS}
    notes, current = [], None
    for line in text.splitlines():
        if line.startswith("# note: "):
            notes.append(line)
        elif line.startswith("# ") and line[2:] in SECTIONS:
            current = line[2:]
        elif " = " in line and not line.startswith("#"):
            a, b = line.split(" = ", 1)
            if current is None:
                entries[a] = sp.sympify(b)
            else:
                sections[current][sp.Symbol(a)] = sp.sympify(b)
    return entries, sections, notes


def _back(e: sp.Expr, sections) -> sp.Expr:
    """An entry in the robot file's symbols: lumped constants, base and standard parameters
    substituted as printed."""
    for name in SECTIONS:
        e = e.xreplace(sections[name])
    return e


def _symbols(*names) -> set:
    return {sp.Symbol(str(n)) for n in names}


def _check_names(dyn, entries, sections) -> None:
    """Every symbol of an entry is a joint angle, a base parameter or a printed lumped constant;
    the constants are over base parameters and geometry, the base parameters over standard ones."""
    base = _symbols(*(name for name, _ in dyn.base_parameters))
    lumped = set(sections["lumped constants"])
    joints = set(dyn.q)
    for label, e in entries.items():
        if not label.startswith("F"):
            assert e.free_symbols <= joints | base | lumped, (label, e.free_symbols - joints - base - lumped)
    geometry = {s for s in dyn.params if _geometry(dyn.robot, s)}
    for s, d in sections["lumped constants"].items():
        assert re.fullmatch(r"[Ig]\d+", str(s)) and s not in set(dyn.params)
        assert d.free_symbols <= base | geometry, (s, d)
    standard = _symbols(*standard_parameters(dyn.robot)[0])
    assert set(sections["base parameters"]) <= base
    for s, d in sections["base parameters"].items():
        assert d.free_symbols <= standard | geometry, (s, d)
    for s, d in sections["standard parameters"].items():
        assert s in standard and d.free_symbols <= set(dyn.params), (s, d)


def _geometry(robot, s) -> bool:
    """s enters the link placements or gravity (read off the model, not symdyn.lumped)."""
    placed = [link.placement.R.free_symbols | link.placement.p.free_symbols for link in robot.links]
    return s in set().union(*placed) | robot.gravity.free_symbols


def _oracle(dyn, entries, sections, seed: int, tol: float) -> None:
    """M and G of the printed form, substituted back, at random parameters against symdyn.rnea."""
    rng = np.random.default_rng(seed)
    values = {s: float(v) for s, v in zip(dyn.params, rng.uniform(0.5, 2.0, len(dyn.params)), strict=True)}
    q = rng.uniform(-np.pi, np.pi, dyn.n)
    at = {**{sp.Symbol(str(s)): v for s, v in values.items()}, **dict(zip(dyn.q, q, strict=True))}
    M = rnea.mass_matrix(dyn.robot, q, values)
    G = rnea.gravity_torque(dyn.robot, q, values)
    for i in range(dyn.n):
        got = float(_back(entries[f"G[{i + 1}]"], sections).xreplace(at))
        assert got == pytest.approx(G[i], rel=tol, abs=tol)
        for j in range(i, dyn.n):
            got = float(_back(entries[f"M[{i + 1},{j + 1}]"], sections).xreplace(at))
            assert got == pytest.approx(M[i, j], rel=tol, abs=tol)


def test_roger_arm_prints_the_base_parameters_and_the_lectures_model(capsys):
    """Slide 18: M = [[m2 l2^2 + 2 m2 l1 l2 c2 + (m1 + m2) l1^2, m2 l2^2 + m2 l1 l2 c2], [., m2 l2^2]],
    V = [-m2 l1 l2 s2 (qd2^2 + 2 qd1 qd2), m2 l1 l2 s2 qd1^2], G = [(m1 + m2) g l1 s1 + m2 g l2 s12,
    m2 g l2 s12]. With Izz2 = m2 l2^2 (link 2's inertia about joint 2) and mx1R = mx1 + l1 m2 =
    (m1 + m2) l1 (Khalil and Dombre's regrouping), M[2,2] prints as Izz2 and G[1]'s sin(q1)
    coefficient is g mx1R."""
    text = _run(capsys, EXAMPLES / "roger_arm.yaml", "--lumped")
    entries, sections, notes = _parse(text)
    assert not notes and all(sections.values())
    g, l1, l2, m1, m2, q1, q2 = sp.symbols("g l1 l2 m1 m2 q1 q2")
    c2, s2 = sp.cos(q2), sp.sin(q2)
    lecture = {
        "M[1,1]": m2 * l2**2 + 2 * m2 * l1 * l2 * c2 + (m1 + m2) * l1**2,
        "M[1,2]": m2 * l2**2 + m2 * l1 * l2 * c2,
        "M[2,2]": m2 * l2**2,
        "B[1,(1,2)]": -2 * m2 * l1 * l2 * s2,
        "Csq[1,2]": -m2 * l1 * l2 * s2,
        "Csq[2,1]": m2 * l1 * l2 * s2,
        "G[1]": (m1 + m2) * g * l1 * sp.sin(q1) + m2 * g * l2 * sp.sin(q1 + q2),
        "G[2]": m2 * g * l2 * sp.sin(q1 + q2),
    }
    for label, want in lecture.items():
        assert sp.expand(_back(entries[label], sections) - want) == 0, label
    assert entries["M[2,2]"] == sp.Symbol("Izz2")
    assert sp.expand(sp.sympify("g*mx1R") - _back_lumped(entries["G[1]"], sections).coeff(sp.sin(q1))) == 0
    dyn = derive(example("roger_arm"))
    _check_names(dyn, entries, sections)
    _oracle(dyn, entries, sections, 5, 1e-12)


def _back_lumped(e, sections):
    return e.xreplace(sections["lumped constants"])


def test_every_lumped_entry_is_its_unlumped_entry(capsys):
    """Roger's arm, Craig's and Spong's two-link arms (Spong's file names its inertias I1, I2, so
    the lumped constants skip those names): substituted back, exactly the unlumped entries."""
    for name in ("roger_arm", "craig_two_link", "spong_two_link"):
        plain, _, _ = _parse(_run(capsys, EXAMPLES / f"{name}.yaml"))
        entries, sections, notes = _parse(_run(capsys, EXAMPLES / f"{name}.yaml", "--lumped"))
        assert not notes and set(entries) == set(plain)
        for label, e in entries.items():
            assert sp.expand(_back(e, sections) - plain[label]) == 0, (name, label)
        dyn = derive(example(name))
        _check_names(dyn, entries, sections)
        _oracle(dyn, entries, sections, 7, 1e-12)


@cache
def _puma_data(joints: int, exact: bool) -> dict:
    """examples/puma560.yaml's first `joints` links with every inertial parameter symbolic (m_k,
    c_k, the inertia about the centre of mass, the rotor's J_k at gear ratio 1), without friction;
    exact: a2 a symbol and the other decimals as fractions (the base parameters exact)."""
    data = yaml.safe_load((EXAMPLES / "puma560.yaml").read_text())
    data["name"] = f"puma560_{joints}_symbolic"
    data["links"] = data["links"][:joints]
    for k, link in enumerate(data["links"], start=1):
        link["mass"] = f"m_{k}"
        link["com"] = [f"c{a}_{k}" for a in "xyz"]
        link["inertia"] = {f"i{a}": f"I{a}_{k}" for a in ("xx", "yy", "zz", "xy", "xz", "yz")}
        link["motor"] = {"inertia": f"J_{k}", "gear_ratio": 1}
        link.pop("friction", None)
        for f in ("a", "d") if exact else ():
            if k == 2 and f == "a":
                link[f] = "a2"
            elif isinstance(link[f], float):
                link[f] = str(sp.Rational(str(link[f])))
    return data


def _puma(joints: int, exact: bool):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return robot_from_data(_puma_data(joints, exact))


def _run_derived(capsys, monkeypatch, path, *argv):
    """(_run's text, the Dynamics the command derived): symdyn.dynamics.derive is watched while
    it runs, so a test checks the printed form against the very derivation (and its base
    parameters, found once) instead of deriving the robot again."""
    import symdyn.dynamics

    kept = []
    real = symdyn.dynamics.derive

    def watched(*args, **kwargs):
        kept.append(real(*args, **kwargs))
        return kept[-1]

    with monkeypatch.context() as m:
        m.setattr(symdyn.dynamics, "derive", watched)
        text = _run(capsys, path, *argv)
    assert len(kept) == 1
    return text, kept[0]


def test_puma_arm_with_symbolic_inertia_is_exact(tmp_path, capsys, monkeypatch):
    """The PUMA 560's first four links, 40 inertial parameters and 4 rotor inertias symbolic, a2
    symbolic (so the base parameters are exact): every entry of M, B, Csq and G substituted back
    is exactly the unlumped one, and the printed form is the oracle's at random values."""
    path = tmp_path / "puma4.yaml"
    path.write_text(yaml.safe_dump(_puma_data(4, True)))
    plain, _, _ = _parse(_run(capsys, path))
    text, dyn = _run_derived(capsys, monkeypatch, path, "--lumped")
    entries, sections, notes = _parse(text)
    assert not notes and set(entries) == set(plain)
    for label, e in entries.items():
        assert sp.expand(_back(e, sections) - plain[label]) == 0, label
    # the command's derivation is of the robot _puma(4, True) builds from the same data
    assert dyn.robot.links == _puma(4, True).resolved().links and dyn.method == "newton-euler"
    _check_names(dyn, entries, sections)
    # Izz1R regroups the links' masses carried about joint 1's axis (Khalil and Dombre)
    assert "Izz1R" in {str(s) for s in sections["base parameters"]}
    _oracle(dyn, entries, sections, 11, 1e-10)


def test_full_puma_with_60_symbolic_parameters_matches_the_oracle():
    """All six links, 60 inertial parameters symbolic, the file's decimal geometry: the base
    parameters' coefficients are 12-digit numbers, so substituted back M and G agree with the
    oracle to 1e-9, and no coefficient falls back to its value."""
    from symdyn.cli.derive_output import derive_text

    dyn = derive(_puma(6, False), simplify=False)
    text = derive_text(dyn, lumped=True)
    head = text.split("\n\nB[", 1)[0]
    tail = text[text.index("\nG[1] = ") :]
    entries, sections, notes = _parse(head + tail)
    assert not notes and len(dyn.params) == 66
    _oracle(dyn, entries, sections, 13, 1e-9)


def test_numeric_inertia_keeps_naming_by_value():
    """With numbers for every inertial parameter (the PUMA 560), or only symbols that the link
    placements use too (Roger's arm with m1, m2 and l2 given: l1 places link 2 and link 1's
    centre of mass), the constants are values, as before."""
    dyn = derive(example("puma560"))
    assert not symbolic_inertia(dyn.robot) and lumped_constants(dyn).base is None
    data = yaml.safe_load((EXAMPLES / "roger_arm.yaml").read_text())
    data["parameters"] = {"m1": 2, "m2": 3, "l2": 0.5}
    roger = robot_from_data(data)
    assert not symbolic_inertia(roger) and lumped_constants(derive(roger)).base is None


def test_base_parameters_unavailable_falls_back_with_a_note(tmp_path, capsys):
    """A joint offset on Roger's arm: its base parameters depend on l1 and cannot be found
    exactly (find_base_parameters asks for values), so the constants are values, with a note,
    and the printed form is still the oracle's."""
    data = yaml.safe_load((EXAMPLES / "roger_arm.yaml").read_text())
    data["links"][1]["theta"] = "1/5"
    path = tmp_path / "roger_offset.yaml"
    path.write_text(yaml.safe_dump(data))
    entries, sections, notes = _parse(_run(capsys, path, "--lumped"))
    assert len(notes) == 1 and "base parameters unavailable" in notes[0]
    assert sections["lumped constants"] and not sections["base parameters"]
    _oracle(derive(robot_from_data(data)), entries, sections, 17, 1e-12)


def test_python_api_names_the_closed_forms():
    """lumped_constants with TrigRing.to_sympy: Roger's M and G over the base parameters,
    substituted back, equal dyn.M and dyn.G."""
    dyn = derive(example("roger_arm"))
    cs = dyn.configuration_space
    lc = lumped_constants(dyn)
    m22 = cs.ring.to_sympy(cs.poly("M", 1, 1), lc.inertial.name)
    g1 = cs.ring.to_sympy(cs.poly("G", 0), lc.gravity.name)
    assert m22 == sp.Symbol("Izz2")
    sections = {
        "lumped constants": dict(lc.definitions()),
        "base parameters": dict(lc.base_definitions()),
        "standard parameters": dict(lc.standard_definitions()),
    }
    assert sp.expand(_back(m22, sections) - dyn.M[1, 1]) == 0
    assert sp.expand(_back(g1, sections) - dyn.G[0]) == 0
