"""Lumped constants of the configuration-space form in terms of the base parameters.

`symdyn derive --lumped` names each distinct coefficient of M, B, Csq and G once
(symdyn.symbolic.lumping). When the robot's inertial data is symbolic (a mass, centre of mass,
inertia or rotor inertia names a free parameter that the kinematics and gravity do not), each
coefficient is instead written over the base parameters (symdyn.algorithms.base_parameters), as
identification tables print the explicit model (Khalil and Dombre, Modeling, Identification and
Control of Robots (2002), sec. 12.3; Armstrong, Khatib and Burdick 1986 name their constants
I1, I2, ..., g1, ...).

Every entry is linear in the standard parameters pi (symdyn.model.parameters: per body m, m c,
the inertia tensor I_O about the body frame's origin, then Ia), and so is each coefficient of one
angle group (the terms of an entry with the same sin/cos(k . q) and prismatic powers):

    c = r^T pi,    r a function of the geometry (and gravity) only.

r is read off a second derivation of a generic copy of the robot, in which body i has a mass
m_i, a centre of mass c_i, an inertia J_i about it and a rotor inertia A_i, all fresh symbols.
Its standard parameters m_i, m_i c_i, J_i + m_i (c_i^T c_i 1 - c_i c_i^T), A_i are independent
polynomials, and each of the monomials m_i, m_i c_ia, J_iab and A_i occurs in one of them only,
so r's entries are the coefficients of those monomials in the generic group's coefficient.
The entries depend on pi only through pi_b = K pi (rows of K: the base parameters; K[:, kept] the
identity), hence r = K^T w with w = r[kept]. The coefficient prints as

    w^T pi_b:  +-(a number times) one base parameter by its name, any other combination as a
    lumped constant I_k (g_k for G) defined as that combination,

after two checks: K^T w = r, and c - r^T pi(params) expands to 0, pi(params) the robot's own
standard parameters (symdyn.standard_parameters). Both hold exactly for exact data; with decimal
data the base parameters' coefficients are rounded to 12 digits (find_base_parameters), and a
residual counts as zero when every coefficient is below REL_TOL times the largest one compared.
A coefficient that fails (pruned terms, a group the generic form lacks) keeps the naming by value,
and `LumpedConstants.notes` says how many did.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from fractions import Fraction

import sympy as sp

from .algorithms.base_parameters import BaseParameters
from .algorithms.configuration_space import ConfigurationSpace, pair_columns
from .algorithms.product_form import ProductForm, product_form
from .dynamics import Dynamics, derive
from .errors import SymdynError
from .model.parameters import PER_BODY, standard_parameters
from .model.robot import Friction, Motor, Robot
from .model.tendons import refuse_tendons
from .symbolic.lumping import Lumper, split_sign
from .symbolic.trig_polynomial import TrigRing, scale, to_sympy_number

__all__ = ["LumpedConstants", "lumped_constants", "lumped_product_form", "symbolic_inertia", "REL_TOL"]

#: decimal data: a residual coefficient below this times the largest coefficient compared is zero
REL_TOL = 1e-9
#: the monomials of the generic body that occur in one standard parameter each: role -> offset
_PRIMARY = {"m": 0, "cx": 1, "cy": 2, "cz": 3, "Jxx": 4, "Jxy": 5, "Jyy": 6, "Jxz": 7, "Jyz": 8, "Jzz": 9}
_TENSOR = (("Jxx", "Jxy", "Jxz"), ("Jxy", "Jyy", "Jyz"), ("Jxz", "Jyz", "Jzz"))


@dataclass
class LumpedConstants:
    """The two namers of one configuration-space form and what their names mean.

    form: the configuration-space form named; inertial: names the coefficients of M, B and Csq
    (I1, I2, ...); gravity: those of G (g1, ...); base: the base parameters the names are written
    in (None: naming by value); standard: each standard parameter's symbol -> its value in the
    robot file's symbols.
    """

    form: ConfigurationSpace
    inertial: Lumper
    gravity: Lumper
    base: BaseParameters | None = None
    standard: dict[sp.Symbol, sp.Expr] = field(default_factory=dict)
    note: str | None = None

    def entry(self, name: str, k: int, c: int = 0, text: bool = False) -> sp.Expr | str:
        """Entry (k, c) of M, B or Csq, or entry k of G (0-based, as ConfigurationSpace.poly),
        its coefficients named; with `text` as `derive` prints it (ConfigurationSpace.text)."""
        namer = (self.gravity if name == "G" else self.inertial).name
        if text:
            return self.form.text(name, k, c, namer)
        return self.form.ring.to_sympy(self.form.poly(name, k, c), namer)

    def definitions(self) -> list[tuple[sp.Symbol, sp.Expr]]:
        """(I_k or g_k, its definition) in the order named: a combination of base parameters, or
        the coefficient's value where it is not one."""
        return self.inertial.definitions + self.gravity.definitions

    def base_definitions(self) -> list[tuple[sp.Symbol, sp.Expr]]:
        """The base parameters the printed names use, each as its combination of the standard
        parameters (`BaseParameters.expressions`), in the base parameters' order; one that is
        a standard parameter itself is left out (`standard_definitions` gives its value)."""
        if self.base is None:
            return []
        used = self.inertial.referenced | self.gravity.referenced
        pairs = zip(self.base.names, self.base.expressions, strict=True)
        out = [(sp.Symbol(n), e) for n, e in pairs if sp.Symbol(n) in used]
        return [(s, e) for s, e in out if e != s]

    def standard_definitions(self) -> list[tuple[sp.Symbol, sp.Expr]]:
        """The standard parameters in the used base parameters, with their values in the robot
        file's symbols (those equal to their own symbol left out), in standard order."""
        if self.base is None:
            return []
        used = self.inertial.referenced | self.gravity.referenced
        needed: set = set()
        for n, e in zip(self.base.names, self.base.expressions, strict=True):
            if sp.Symbol(n) in used:
                needed |= e.free_symbols
        return [(s, v) for s, v in self.standard.items() if s in needed and v != s]

    def values(self) -> dict[sp.Symbol, sp.Expr]:
        """Each name the named entries use (lumped constants I_k, g_k, base parameters and the
        standard parameters in them) -> its value in the robot file's symbols."""
        standard = dict(self.standard_definitions())
        base = {s: e.xreplace(standard) for s, e in self.base_definitions()}
        for s in self.inertial.referenced | self.gravity.referenced:
            base.setdefault(s, standard.get(s, s))
        out = {s: e.xreplace(base) for s, e in self.definitions()}
        return {**standard, **base, **out}

    def notes(self) -> list[str]:
        """One line each: why the base parameters are not used, or how many coefficients are
        not combinations of them and so are named by value."""
        missed = len(self.inertial.missed) + len(self.gravity.missed)
        out = [self.note] if self.note else []
        if self.base is not None and missed:
            out.append(
                f"{missed} coefficient(s) are not exact combinations of the base parameters: "
                "their constants are defined by value"
            )
        return out


def _geometry_symbols(robot: Robot) -> set:
    out = set(robot.base_gravity.free_symbols)
    for link in robot.links:
        out |= link.placement.R.free_symbols | link.placement.p.free_symbols | link.axis.free_symbols
        if link.mimic is not None:
            out |= sp.sympify(link.mimic.multiplier).free_symbols | sp.sympify(link.mimic.offset).free_symbols
    return out


def symbolic_inertia(robot: Robot) -> bool:
    """Whether a mass, centre of mass, inertia or rotor inertia of the (resolved) robot names a
    free parameter that its kinematics and gravity do not."""
    links = robot.resolved().links
    inertial: set = set()
    for link in links:
        inertial |= sp.sympify(link.mass).free_symbols | link.com.free_symbols | link.inertia.free_symbols
        inertial |= sp.sympify(link.motor.reflected_inertia).free_symbols
    return bool(inertial - _geometry_symbols(robot.resolved()))


def _generic(robot: Robot) -> tuple[Robot, dict[sp.Symbol, tuple[int, str]]]:
    """The robot with body i's mass, centre of mass, inertia and rotor inertia fresh symbols (no
    friction), and symbol -> (body index, role)."""
    roles: dict[sp.Symbol, tuple[int, str]] = {}
    links = []
    for i, link in enumerate(robot.links):
        s = {role: sp.Dummy(f"{role}_{i + 1}") for role in (*_PRIMARY, "A")}
        roles.update({sym: (i, role) for role, sym in s.items()})
        tensor = sp.ImmutableMatrix([[s[r] for r in row] for row in _TENSOR])
        com = sp.ImmutableMatrix([s["cx"], s["cy"], s["cz"]])
        links.append(
            replace(link, mass=s["m"], com=com, inertia=tensor, friction=Friction(), motor=Motor(s["A"]))
        )
    return replace(robot, name=f"{robot.name}_generic", links=tuple(links)), roles


def _readoff(ring, items: list, roles: dict) -> dict[int, sp.Expr] | None:
    """r of one generic group coefficient (items: (number, parameter monomial)): standard column
    -> geometry factor, from the monomials m, m c_a, J_ab and A of one body (m c_a c_b, the
    parallel-axis part of I_O, follows from them); None for any other monomial (the coefficient
    is not linear in pi)."""
    r: dict[int, sp.Expr] = {}
    for c, mono in items:
        body, kinds, geometry = None, {}, []
        for g, e in mono:
            role = roles.get(ring.gens[g])
            if role is None:
                geometry.append((g, e))
                continue
            if body not in (None, role[0]):
                return None
            body, kinds[role[1]] = role[0], e
        if body is None:
            return None
        moment = sum(e for k, e in kinds.items() if k.startswith("c"))  # degree in c
        others = [k for k in kinds if not k.startswith("c")]
        if others == ["m"] and kinds["m"] == 1 and moment == 2:
            continue  # m c_a c_b: the parallel-axis part of I_O
        if others == ["m"] and kinds["m"] == 1 and moment == 1:
            column = PER_BODY * body + _PRIMARY[next(k for k in kinds if k != "m")]
        elif len(kinds) == 1 and others and kinds[others[0]] == 1:
            column = PER_BODY * body + (10 if others[0] == "A" else _PRIMARY[others[0]])
        else:
            return None
        r[column] = r.get(column, sp.S.Zero) + to_sympy_number(c) * ring.mono_expr(tuple(geometry))
    return r


def _negligible(residual: sp.Expr, *compared: sp.Expr) -> bool:
    """residual (expanded) is 0, or for decimal data every coefficient is below REL_TOL times the
    largest coefficient of the compared expressions."""
    if residual == 0:
        return True
    values = residual.as_coefficients_dict().values()
    if not all(v.is_Float for v in values):
        return False
    scale = max(
        (
            abs(float(v))
            for e in compared
            for v in sp.expand(e).as_coefficients_dict().values()
            if v.is_number
        ),
        default=0.0,
    )
    return all(abs(float(v)) <= REL_TOL * scale for v in values)


class _Solver:
    """w for each coefficient: r from the generic form, w = r[kept], both checks (module docstring)."""

    def __init__(self, base: BaseParameters, standard: list[sp.Expr], roles: dict) -> None:
        self.base = base
        self.pi = standard
        self.roles = roles
        self.symbols = [sp.Symbol(n) for n in base.names]
        self.kept = {c: k for k, c in enumerate(base.columns)}
        K = base.K
        self.rows = [{c: K[k, c] for c in range(K.cols) if K[k, c] != 0} for k in range(K.rows)]

    def combination(self, ring, generic_items: list, coefficient: sp.Expr) -> sp.Expr | None:
        r = _readoff(ring, generic_items, self.roles)
        if r is None:
            return None
        w = {self.kept[c]: v for c, v in r.items() if c in self.kept}
        back: dict[int, sp.Expr] = {}
        for k, wk in w.items():
            for c, kc in self.rows[k].items():
                back[c] = back.get(c, sp.S.Zero) + wk * kc
        for c in set(back) | set(r):
            a, b = back.get(c, sp.S.Zero), r.get(c, sp.S.Zero)
            if not _negligible(sp.expand(a - b), a, b):
                return None
        value = sp.Add(*[v * self.pi[c] for c, v in r.items()])
        if not _negligible(sp.expand(coefficient - value), coefficient):
            return None
        return sp.Add(*[wk * self.symbols[k] for k, wk in sorted(w.items())])


def _entries(cs: ConfigurationSpace):
    """(name, row, column) of the entries `derive` prints with lumped constants, in its order."""
    n = cs.n
    yield from (("M", i, j) for i in range(n) for j in range(i, n))
    yield from (("B", k, c) for k in range(n) for c in range(len(pair_columns(n))))
    yield from (("Csq", k, i) for k in range(n) for i in range(n))
    yield from (("G", k, 0) for k in range(n))


def lumped_constants(dyn: Dynamics, cs: ConfigurationSpace | None = None) -> LumpedConstants:
    """The namers of `derive --lumped` for `dyn` (cs: a pruned form of it instead of its own).

    With numeric inertial data (`symbolic_inertia` false) the coefficients are named by value,
    as symdyn.symbolic.lumping.Lumper does alone. Otherwise each coefficient is written over the
    base parameters (module docstring); `notes` explains any exception.

    Use: `lc.entry(name, k, c)` for each entry, in the order `derive` prints them (names are
    given as met), then `lc.definitions()`, `lc.base_definitions()` and
    `lc.standard_definitions()`.
    """
    refuse_tendons(
        dyn.robot,
        "derive --lumped",
        "their springs are not trigonometric polynomials; derive without --lumped",
    )
    cs = cs or dyn.configuration_space
    q = list(dyn.q)
    names, values = standard_parameters(dyn.robot)
    reserved = {str(s) for s in dyn.params} | set(names)
    plain = LumpedConstants(cs, Lumper(q, "I", reserved=reserved), Lumper(q, "g", reserved=reserved))
    if not symbolic_inertia(dyn.robot):
        return plain
    try:
        base = dyn.linear_compact()[1]
        robot, roles = _generic(dyn.robot)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            generic = derive(robot, method=dyn.method, simplify=False).configuration_space
    except SymdynError as e:
        plain.note = f"base parameters unavailable, lumped constants defined by value: {e}"
        return plain
    solver = _Solver(base, list(values), roles)
    known: dict[str, dict[sp.Expr, sp.Expr]] = {"I": {}, "g": {}}
    for name, row, col in _entries(cs):
        actual = cs.poly(name, row, col)
        if not actual:
            continue
        table = known["g" if name == "G" else "I"]
        generic_groups = dict(generic.ring.groups(generic.poly(name, row, col)))
        for key, items in cs.ring.groups(actual):
            coefficient = cs.ring.group_coefficient(items)
            sign, magnitude = split_sign(coefficient)
            if magnitude in table or key not in generic_groups:
                continue
            w = solver.combination(generic.ring, generic_groups[key], coefficient)
            if w is not None:
                table[magnitude] = sign * w
    standard = {sp.Symbol(n): v for n, v in zip(names, values, strict=True)}
    reserved |= set(base.names)
    lumpers = (Lumper(q, prefix, known[prefix], reserved) for prefix in ("I", "g"))
    return LumpedConstants(cs, *lumpers, base, standard)


def lumped_product_form(dyn: Dynamics) -> tuple[ProductForm, LumpedConstants]:
    """The product form (symdyn.algorithms.product_form) with its coefficients written over the
    lumped constants of `derive --lumped` (`lumped_constants`): every entry of the
    configuration form has its angle groups' coefficients named (in `derive --lumped`'s order,
    so the names are the same), the named entries become trigonometric polynomials over the
    names, and those are rewritten over the atoms, factored and shared as without lumping.
    Substituting `LumpedConstants.values` into it gives the configuration form back
    (`ProductForm.check` with `constants`)."""
    cs = dyn.configuration_space
    lc = lumped_constants(dyn, cs)
    ring = TrigRing(cs.ring.q)
    named = {(name, row, col): ring.convert(lc.entry(name, row, col)) for name, row, col in _entries(cs)}
    n = cs.n
    gamma = {}
    for (name, k, c), p in named.items():
        if p and name == "B":
            i, j = pair_columns(n)[c]
            gamma[(k, i, j)] = scale(p, Fraction(1, 2))
        elif p and name == "Csq":
            gamma[(k, c, c)] = p
    M = [[named[("M", min(i, j), max(i, j))] for j in range(n)] for i in range(n)]
    G = [named[("G", k, 0)] for k in range(n)]
    form = ConfigurationSpace(ring, M, G, gamma)
    return product_form(dyn.robot, form, dyn.closed_form("F")), lc
