"""The product form: the configuration-space form as textbooks print it (`derive --form product`).

    tau = M(q) qdd + B(q) [qd qd] + Csq(q) [qd^2] + G(q) + F(qd)

with every entry of M (upper triangle), B, Csq and G written over the trig atoms
c_i = cos q_i, s_i = sin q_i and, for consecutive joints whose axes are parallel at every q
(`parallel_groups`), c_23 = cos(q2 + q3), s_23 = sin(q2 + q3) (symdyn.symbolic.atom_polynomial),
factored Horner-like and with equal or opposite pieces shared under names x1, x2, ...
(symdyn.symbolic.horner). The entries are those of the configuration form
(symdyn.algorithms.configuration_space), only written differently: `check` substitutes the
atoms and shared quantities back and compares.

Its size is bounded (`check_product_size`): at most MAX_PRODUCT_JOINTS = 10 joints in a chain
(from the base to a leaf: the branches of a tree, the legs of a quadruped, hardly couple), refused
before anything is derived, and a configuration form of at most MAX_PRODUCT_TERMS = 250,000 terms
(the Panda's is 228,647 and takes about 20 s). A chain's form grows about threefold with each
joint: a 12-joint arm ran out of memory after minutes. Beyond, `derive --form compact` prints
the dynamics as named intermediates.

References: Armstrong, Khatib, Burdick, "The explicit dynamic model and inertial
parameters of the PUMA 560 arm", Proc. IEEE ICRA 1986 (the PUMA 560 in 1,165 operations over
c_i, s_i, c_23, s_23 and named constants); Craig, Introduction to Robotics (3rd ed., 2005),
sec. 6.8; R. Grupen, "Dynamics" (2015), slide 18 (the two-link arm over c_2, s_1, s_12).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..errors import SymdynError
from ..model.robot import Robot
from ..symbolic.atom_polynomial import Atoms
from ..symbolic.horner import Factoring
from ..symbolic.trig_polynomial import TrigRing, chop, largest
from .configuration_space import ConfigurationSpace, pair_columns

__all__ = [
    "ProductForm",
    "product_form",
    "parallel_groups",
    "check_product_size",
    "MATRICES",
    "MAX_PRODUCT_JOINTS",
    "MAX_PRODUCT_TERMS",
]

#: the quantities of the product form, in printed order
MATRICES = ("M", "B", "Csq", "G", "F")
#: the most joints of a chain (base to leaf) a product form is built for, checked before anything is derived
MAX_PRODUCT_JOINTS = 10
#: the most terms of the configuration form a product form is built from (the Panda: 228,647)
MAX_PRODUCT_TERMS = 250_000
_INSTEAD = "use --form compact (the dynamics as named intermediates)"


def check_product_size(robot: Robot, cs: ConfigurationSpace | None = None) -> None:
    """Refuse a product form beyond MAX_PRODUCT_JOINTS joints in a chain or, given the configuration
    form `cs`, beyond MAX_PRODUCT_TERMS of its terms: building it would take minutes and gigabytes."""
    depth: list[int] = []
    for parent in robot.parents:  # a parent comes before its children
        depth.append(1 + (depth[parent] if parent >= 0 else 0))
    longest = max(depth, default=0)
    if longest > MAX_PRODUCT_JOINTS:
        raise SymdynError(
            f"the product form is limited to chains of {MAX_PRODUCT_JOINTS} joints and robot "
            f"'{robot.name}' has one of {longest} (it grows about threefold with each joint); {_INSTEAD}"
        )
    if cs is not None and cs.terms > MAX_PRODUCT_TERMS:
        raise SymdynError(
            f"the product form is limited to configuration forms of {MAX_PRODUCT_TERMS:,} terms and "
            f"robot '{robot.name}' has {cs.terms:,} (factoring them would take minutes); {_INSTEAD}"
        )


def _parallel(robot: Robot, child: int, parent: int) -> bool:
    """Whether joint `child`'s axis, carried into the parent's body frame by its placement, is
    joint `parent`'s axis (same direction): then the child's frame turns by q_parent + q_child
    about one fixed direction."""
    a = robot.links[child].placement.R * robot.links[child].axis
    d = a - robot.links[parent].axis
    for x in d:
        x = sp.sympify(x)
        if x.free_symbols:
            x = x.xreplace(robot.value_map) if robot.values else x
        if x.free_symbols:
            if sp.simplify(x) != 0:
                return False
        elif abs(complex(x)) > 1e-12:
            return False
    return True


def parallel_groups(robot: Robot) -> list[tuple[int, ...]]:
    """Runs of consecutive revolute joints (independent coordinates i, i+1, ..., each joint
    the child of the one before) whose axes are parallel at every q, as 0-based coordinate
    indices; runs of one joint left out."""
    coords = robot.coordinates
    groups: list[list[int]] = []
    parents = robot.parents
    for b, link in enumerate(robot.links):
        c = coords[b]
        if link.joint != "revolute" or link.mimic is not None:
            continue
        p = parents[b]
        joined = False
        if p >= 0 and robot.links[p].joint == "revolute" and robot.links[p].mimic is None:
            pc = coords[p].index
            if pc == c.index - 1 and groups and groups[-1][-1] == pc and _parallel(robot, b, p):
                groups[-1].append(c.index)
                joined = True
        if not joined:
            groups.append([c.index])
    return [tuple(g) for g in groups if len(g) > 1]


@dataclass
class ProductForm:
    """The product form of one derivation: atoms and shared quantities (name, definition) in
    the order they are defined, and entries (label, expression) per quantity of MATRICES."""

    atoms: list[tuple[sp.Symbol, sp.Expr]]
    shared: list[tuple[sp.Symbol, sp.Expr]]
    entries: dict[str, list[tuple[str, sp.Expr]]]
    groups: list[tuple[int, ...]]

    def substitution(self, constants: dict | None = None) -> dict[sp.Symbol, sp.Expr]:
        """name -> definition in q and the parameters (shared quantities over atoms expanded;
        constants: the lumped constants' values, symdyn.lumped, substituted too)."""
        sub = {**dict(self.atoms), **(constants or {})}
        for name, e in self.shared:
            sub[name] = e.xreplace(sub)
        return sub

    def entry(self, label: str) -> sp.Expr:
        for items in self.entries.values():
            for lab, e in items:
                if lab == label:
                    return e
        raise KeyError(label)

    def check(self, cs: ConfigurationSpace, rel: float = 1e-12, constants: dict | None = None) -> None:
        """Assert that every entry, atoms and shared quantities (and the lumped `constants`,
        name -> value) substituted back, is the configuration form's entry: exactly for exact
        data, within rel of the entry's largest coefficient for float data."""
        ring = TrigRing(cs.ring.q)
        sub = self.substitution(constants)
        for name in ("M", "B", "Csq", "G"):
            labels = dict(_labelled(cs, name))
            got = {lab: e for lab, e in self.entries[name]}
            for lab, (k, c) in labels.items():
                want = cs.ring.named(cs.poly(name, k, c))
                have = ring.named(ring.convert(got.get(lab, sp.S.Zero).xreplace(sub)))
                big = max([abs(float(x)) for x in want.values()] or [0.0])
                for key in set(want) | set(have):
                    a, b = want.get(key, 0), have.get(key, 0)
                    if isinstance(a, float) or isinstance(b, float):
                        assert abs(float(a) - float(b)) <= rel * big, (lab, key, a, b)
                    else:
                        assert sp.simplify(sp.sympify(a) - sp.sympify(b)) == 0, (lab, key, a, b)


def _labelled(cs: ConfigurationSpace, name: str) -> list[tuple[str, tuple[int, int]]]:
    """(label, (k, c)) of the printed entries: M's upper triangle, B's and Csq's nonzero ones, G."""
    n = cs.n
    if name == "M":
        return [(f"M[{i + 1},{j + 1}]", (i, j)) for i in range(n) for j in range(i, n)]
    if name == "G":
        return [(f"G[{k + 1}]", (k, 0)) for k in range(n)]
    if name == "B":
        return [
            (f"B[{k + 1},({i + 1},{j + 1})]", (k, c))
            for k in range(n)
            for c, (i, j) in enumerate(pair_columns(n))
            if cs.poly("B", k, c)
        ]
    return [(f"Csq[{k + 1},{i + 1}]", (k, i)) for k in range(n) for i in range(n) if cs.poly("Csq", k, i)]


def product_form(robot: Robot, cs: ConfigurationSpace, F) -> ProductForm:
    """The product form of a configuration-space form.

    Args:
        robot: the robot (its kinematics tell the parallel axes).
        cs: its configuration-space form (either route).
        F: the friction vector, closed (n entries; printed as it is).

    Returns:
        The `ProductForm`: atoms used (c before s, single joints by index, then blocks),
        shared quantities, and the entries factored and shared.

    Raises:
        SymdynError: beyond the size `check_product_size` allows.
    """
    check_product_size(robot, cs)
    groups = parallel_groups(robot)
    taken = {sp.sstr(g) for g in cs.ring.gens} | {str(s) for s in robot.params}
    atoms = Atoms(cs.ring, groups, taken)
    polys = {}
    for name in ("M", "B", "Csq", "G"):
        converted = [(lab, atoms.convert(cs.poly(name, k, c))) for lab, (k, c) in _labelled(cs, name)]
        big = largest(p for _, p in converted)
        polys[name] = [(lab, chop(p, big)) for lab, p in converted]
    factoring = Factoring(atoms.symbols, atoms.name, taken | {atoms.name(v) for v in atoms.definitions})
    refs = {name: [(lab, factoring.piece(p)) for lab, p in items] for name, items in polys.items()}
    for items in refs.values():
        for _, ref in items:
            factoring.count(ref)
    entries = {name: [(lab, factoring.expr(ref)) for lab, ref in items] for name, items in refs.items()}
    entries["F"] = [(f"F[{k + 1}]", sp.sympify(e)) for k, e in enumerate(F)]
    used = set().union(*[e.free_symbols for items in entries.values() for _, e in items])
    used |= set().union(*[e.free_symbols for _, e in factoring.shared])
    order = [v for v in atoms.definitions if atoms.symbols[v] in used]
    order.sort(key=lambda v: _atom_order(atoms, v))
    defined = [(atoms.symbols[v], atoms.definitions[v]) for v in order]
    return ProductForm(defined, factoring.shared, entries, groups)


def _atom_order(atoms: Atoms, v: int) -> tuple:
    """Atoms by their angle (single joints first, then blocks, by first joint), c before s."""
    angle = atoms.definitions[v].args[0]
    joints = sorted(atoms.ring.q.index(s) for s in angle.free_symbols if s in atoms.ring.q)
    return (len(joints) > 1, joints, sp.sstr(angle), isinstance(atoms.definitions[v], sp.sin))
