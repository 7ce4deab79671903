"""Checking textbook (or homework) answers against symdyn's derivation.

An answers file (YAML) gives any of M, C, V, G, F, tau of a robot as
expressions in the robot's parameter names and the joint symbols q1.., qd1..,
qdd1..:

    M: [["m2*l2**2 + 2*m2*l1*l2*cos(q2) + (m1 + m2)*l1**2", "m2*l2**2 + m2*l1*l2*cos(q2)"],
        ["m2*l2**2 + m2*l1*l2*cos(q2)", "m2*l2**2"]]
    G: ["(m1 + m2)*g*l1*sin(q1) + m2*g*l2*sin(q1 + q2)", "m2*g*l2*sin(q1 + q2)"]

M and C are n x n lists of rows, the others lists of n entries (a 1-joint robot
may give a single entry). Entries are numbers or strings parsed by symdyn's
safe parser (never evaluated as code). Parameters that have a value in the
robot file are replaced by that value. `null` (an entry, a row or a whole
quantity) means "not checked", and a single entry may be given on its own with
a key such as `M[2,2]` or `G[1]` (indices from 1); at least one entry must be
given. The report says how many of the entries of the quantities given were
checked.

Each entry is compared with symdyn's closed form: first symbolically (the
expanded difference, without floating-point rounding noise below 1e-12 of the
largest number, then `sympy.simplify` of it, must be 0), and when that is
inconclusive numerically at random points (joint values in [-pi, pi],
velocities and accelerations in [-2, 2], free parameters in [0.5, 2]). An entry
that differs at any point differs; one that agrees everywhere but resists
simplification counts as matching numerically. A differing entry's line gives symdyn's entry in
the form `symdyn derive` prints it and the difference answer - symdyn, simplified; an answer M
that is not symmetric gets a note (symdyn.apps.checking.check_explain).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import sympy as sp

from ...dynamics import METHODS, derive
from ...errors import SymdynError
from ...model.bounded import MAX_ANSWER_TERMS
from ...model.expressions import parse_expression
from ...model.robot import Robot
from ...model.symbols import joint_symbols
from ...parsers.yaml_text import parse_text
from .check_explain import SIMPLIFY_MAX_OPS, asymmetry_notes, chop, derive_form, difference_text
from .check_state import AT_KEY, TOLERANCE_KEY, compare_at_state
from .check_steps import check_steps

__all__ = [
    "QUANTITIES",
    "STEPS_KEY",
    "EntryResult",
    "CheckReport",
    "read_answers",
    "load_answers",
    "parse_answers",
    "answer_entry",
    "entry_count",
    "compare_entry",
    "check_answers",
    "MAX_SAMPLES",
]

QUANTITIES = ("M", "C", "V", "G", "F", "tau")
MATRICES = ("M", "C")
SAMPLES = 16
#: the most random points of the numeric comparison (each entry is evaluated at all of them at once)
MAX_SAMPLES = 100_000
RTOL = 1e-9
#: the key of answers for the derivation's intermediate steps (symdyn.apps.checking.check_steps)
STEPS_KEY = "steps"
#: a key giving one entry on its own: M[2,2], G[1]
_ENTRY_KEY = re.compile(r"(\w+)\[\s*(\d+)\s*(?:,\s*(\d+)\s*)?\]")


_NOTHING_GIVEN = "no answer entry given: every entry is null (not checked); give at least one"


def _entry_label(name: str, index: tuple[int, ...]) -> str:
    return f"{name}[{','.join(str(i) for i in index)}]" if index else name


def _parse_entry(value: object, file: str | None, label: str) -> sp.Expr:
    """Parse one answer entry, letting the joint symbols q<k>, qd<k>, qdd<k> through, and
    refusing one that would expand to more than MAX_ANSWER_TERMS terms."""
    return parse_expression(
        value, file=file, field=label, allow_joint_symbols=True, max_terms=MAX_ANSWER_TERMS
    )


def _entry_key(key: object) -> tuple[str, tuple[int, ...]] | None:
    """(quantity, 1-based index) of a key naming one entry, such as M[2,2] or G[1]; None otherwise."""
    m = _ENTRY_KEY.fullmatch(key) if isinstance(key, str) else None
    if m is None or m.group(1) not in QUANTITIES:
        return None
    return m.group(1), tuple(int(g) for g in m.groups()[1:] if g is not None)


def _cells(name: str, raw: object, n: int, file: str | None) -> list[tuple[tuple[int, ...], object]]:
    """(1-based index, value) of every entry of quantity `name` as written (None: not checked)."""
    if raw is None:
        return []
    if name in MATRICES:
        if n == 1 and not isinstance(raw, list):
            raw = [[raw]]
        ok = (
            isinstance(raw, list)
            and len(raw) == n
            and all(r is None or (isinstance(r, list) and len(r) == n) for r in raw)
        )
        if not ok:
            raise SymdynError(
                f"{name} must be a list of {n} rows of {n} entries (null for a row or entry not checked)",
                file=file,
                field=name,
            )
        return [((i + 1, j + 1), raw[i][j]) for i in range(n) if raw[i] is not None for j in range(n)]
    if n == 1 and not isinstance(raw, list):
        raw = [raw]
    if not (isinstance(raw, list) and len(raw) == n):
        raise SymdynError(
            f"{name} must be a list of {n} entries (null for one not checked)", file=file, field=name
        )
    return [((i + 1,), raw[i]) for i in range(n)]


def entry_count(name: str, n: int) -> int:
    """How many entries quantity `name` has for n joints (n x n for M and C, n for the others)."""
    return n * n if name in MATRICES else n


def parse_answers(
    data: object, robot: Robot, file: str | None = None
) -> dict[str, dict[tuple[int, ...], sp.Expr]]:
    """The answers of a mapping (e.g. read from YAML): quantity -> {1-based index: expression over
    the robot's symbols} for the entries given, row-major (entries that are null are left out)."""
    if not isinstance(data, Mapping):
        kind = "empty file" if data is None else type(data).__name__
        raise SymdynError(f"expected a mapping of M, C, V, G, F, tau to answers, got {kind}", file=file)
    keys = (*QUANTITIES, STEPS_KEY, AT_KEY, TOLERANCE_KEY)
    unknown = [str(k) for k in data if k not in keys and _entry_key(k) is None]
    if unknown:
        raise SymdynError(
            f"unknown key(s) {', '.join(unknown)} (answers may give {', '.join(QUANTITIES)}, single entries "
            f"such as M[1,2] and {STEPS_KEY}, or numbers {AT_KEY} a state with a {TOLERANCE_KEY})",
            file=file,
        )
    if not data:
        raise SymdynError(f"no answers given (any of M, C, V, G, F, tau, {STEPS_KEY})", file=file)
    n = robot.n
    given: dict[str, dict[tuple[int, ...], object]] = {}
    for name in QUANTITIES:
        if name in data:
            given[name] = dict(_cells(name, data[name], n, file))
    for key, value in data.items():
        entry = _entry_key(key)
        if entry is None:
            continue
        name, index = entry
        shape = (n, n) if name in MATRICES else (n,)
        if len(index) != len(shape) or not all(1 <= i <= n for i in index):
            where = f"[i,j], i and j in 1..{n}" if name in MATRICES else f"[i], i in 1..{n}"
            raise SymdynError(
                f"no such entry: {name} has the entries {name}{where}", file=file, field=str(key)
            )
        entries = given.setdefault(name, {})
        if entries.get(index) is not None and value is not None:
            raise SymdynError(f"entry given twice (also in {name})", file=file, field=str(key))
        if value is not None:
            entries[index] = value
    return {
        name: {
            index: answer_entry(value, robot, file, _entry_label(name, index))
            for index, value in sorted(given[name].items())
            if value is not None
        }
        for name in QUANTITIES
        if name in given
    }


def answer_entry(value: object, robot: Robot, file: str | None, label: str) -> sp.Expr:
    """One answer entry over the robot's free parameters and joint symbols (valued parameters
    replaced by their values); `label` names it in messages."""
    n = robot.n
    if isinstance(value, list):
        raise SymdynError("expected one expression, got a list", file=file, field=label)
    expr = _parse_entry(value, file, label).xreplace(robot.value_map)
    q, qd, qdd = joint_symbols(n)
    extra = sorted(str(s) for s in expr.free_symbols - (set(robot.params) | set(q) | set(qd) | set(qdd)))
    if extra:
        names = ", ".join(str(s) for s in robot.params) or "none"
        raise SymdynError(
            f"unknown name(s) {', '.join(extra)}: use the robot's free parameters ({names}) and "
            f"q1..q{n}, qd1..qd{n}, qdd1..qdd{n} (write cos(q2), not c2)",
            file=file,
            field=label,
        )
    return expr


def read_answers(path: str | os.PathLike) -> object:
    """The data of an answers file: YAML read as robot files are (symdyn.parsers.yaml_text: safe
    loader, repeated keys, deep nesting and aliases that expand too far refused in one line)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise SymdynError(f"not a UTF-8 text file: {exc.reason}", file=str(p)) from None
    return parse_text(text, str(p))


def load_answers(path: str | os.PathLike, robot: Robot) -> dict[str, dict[tuple[int, ...], sp.Expr]]:
    """Read an answers file (YAML, safe loader) for `robot`."""
    return parse_answers(read_answers(path), robot, str(Path(path)))


@dataclass
class EntryResult:
    """One compared entry: 1-based `index`, symdyn's `expected` and the answer's `got`.

    status: "symbolic" (the difference simplifies to 0), "numeric" (equal at every
    random point, simplification inconclusive), "at the state" (numbers at the state of an
    `at:` key, symdyn.apps.checking.check_state) or "differs".
    """

    quantity: str
    index: tuple[int, ...]
    expected: sp.Expr
    got: sp.Expr
    status: str
    #: symdyn's entry as `symdyn derive` prints it ('' for the plain text of `expected`)
    shown: str = ""

    @property
    def label(self) -> str:
        return _entry_label(self.quantity, self.index)

    @property
    def ok(self) -> bool:
        return self.status != "differs"

    def line(self) -> str:
        """label: expected E, got A; answer - symdyn = A - E (simplified)."""
        expected = self.shown or sp.sstr(self.expected)
        return (
            f"{self.label}: expected {expected}, got {sp.sstr(self.got)}; "
            f"answer - symdyn = {difference_text(self.expected, self.got)}"
        )


@dataclass
class CheckReport:
    robot: str
    method: str
    samples: int
    results: list[EntryResult] = field(default_factory=list)
    #: the first step of the recursion (in the order it is computed) whose answer differs
    first_step: str | None = None
    #: the entries of the quantities and steps the answers give, checked or not (null)
    entries: int = 0
    #: the quantities the answers give (M, G, ...) and how many steps, checked or not
    given: tuple[str, ...] = ()
    steps_given: int = 0
    #: what else is wrong with the answers (an M that is not symmetric)
    notes: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return all(r.ok for r in self.results)

    @property
    def differing(self) -> list[EntryResult]:
        return [r for r in self.results if not r.ok]

    def summary(self) -> str:
        """One line: how many entries were checked, of how many, and whether they all match."""
        total = len(self.results)
        steps = self.steps_given
        names = ", ".join([f"{steps} step{'s' * (steps != 1)}"] * bool(steps) + list(self.given))
        partial = f"{total} of {self.entries} entries of {names} checked (the others null); "
        if self.ok:
            numeric = sum(r.status == "numeric" for r in self.results)
            if any(r.status == "at the state" for r in self.results):
                how = "at the given state"
            elif not numeric:
                how = "all symbolically"
            else:
                how = f"{total - numeric} symbolically, {numeric} numerically at {self.samples} random points"
            if total < self.entries:
                return f"{self.robot}: {partial}{'it matches' if total == 1 else 'all match'} ({how})"
            if how == "at the given state":
                return f"{self.robot}: all {total} entries of {names} match at the given state"
            return f"{self.robot}: all {total} entries of {names} match ({how})"
        bad = self.differing
        labels = ", ".join(r.label for r in bad)
        if total < self.entries:
            return f"{self.robot}: {partial}{len(bad)} differ{'s' * (len(bad) == 1)} ({labels})"
        return f"{self.robot}: {len(bad)} of {total} entries of {names} differ ({labels})"

    def text(self, verbose: bool = False) -> str:
        lines = []
        for r in self.results:
            if not r.ok:
                lines.append(r.line())
            elif verbose:
                lines.append(f"{r.label}: matches ({r.status})")
        if self.first_step:
            lines.append(f"first differing step: {self.first_step}")
        lines += [f"note: {note}" for note in self.notes]
        lines.append(self.summary())
        return "\n".join(lines) + "\n"


def _numeric_zero(diff: sp.Expr, scale: sp.Expr, symbols: list[sp.Symbol], points: np.ndarray) -> bool:
    """Whether diff is 0 (relative to 1 + |scale|) at every sample point."""
    f = sp.lambdify([symbols], [diff, scale], modules="numpy")
    with np.errstate(all="ignore"):
        d, s = (np.broadcast_to(np.asarray(x, dtype=float), points.shape[:1]) for x in f(points.T))
    if not np.all(np.isfinite(d)):
        return False
    return bool(np.all(np.abs(d) <= RTOL * (1.0 + np.abs(s))))


def _symbolic_zero(diff: sp.Expr) -> bool:
    if diff == 0:
        return True
    if sp.count_ops(diff) > SIMPLIFY_MAX_OPS:
        return False
    try:
        return sp.simplify(diff) == 0
    except Exception:  # simplification failing is only an inconclusive result
        return False


def compare_entry(expected: sp.Expr, got: sp.Expr, symbols: list[sp.Symbol], points: np.ndarray) -> str:
    """ "symbolic", "numeric" or "differs" (module docstring) for one answer entry."""
    diff = chop(sp.expand(got - expected), expected, got)
    if diff == 0:
        return "symbolic"
    if not _numeric_zero(diff, sp.Abs(expected) + sp.Abs(got), symbols, points):
        return "differs"
    return "symbolic" if _symbolic_zero(diff) else "numeric"


def check_answers(
    robot: Robot,
    answers: str | os.PathLike | Mapping,
    method: str = "newton-euler",
    samples: int = SAMPLES,
    seed: int = 0,
) -> CheckReport:
    """Compare answers (a file or a mapping as in the YAML) with symdyn's derivation of `robot`.

    Answers for the derivation's steps (the `steps` key) are compared by
    symdyn.apps.checking.check_steps, before the final quantities, in the order the steps are computed.
    """
    if method not in METHODS:
        raise SymdynError(f"unknown method '{method}' (use {' or '.join(METHODS)})")
    if (
        isinstance(samples, bool)
        or not isinstance(samples, (int, np.integer))
        or not 1 <= samples <= MAX_SAMPLES
    ):
        raise SymdynError(f"check: samples must be a whole number from 1 to {MAX_SAMPLES:,}, got {samples!r}")
    file = None if isinstance(answers, Mapping) else str(Path(answers))
    data = answers if isinstance(answers, Mapping) else read_answers(answers)
    parsed = parse_answers(data, robot, file)
    dyn = derive(robot, method=method)
    symbols = [*dyn.q, *dyn.qd, *dyn.qdd, *dyn.params]
    rng = np.random.default_rng(seed)
    n = dyn.n
    points = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, (samples, n)),
            rng.uniform(-2, 2, (samples, 2 * n)),
            rng.uniform(0.5, 2.0, (samples, len(dyn.params))),
        ]
    )
    report = CheckReport(robot.name, method, samples)
    report.entries = sum(entry_count(name, n) for name in parsed)
    report.given = tuple(parsed)
    if STEPS_KEY not in data and not any(parsed.values()):
        raise SymdynError(_NOTHING_GIVEN, file=file)
    if AT_KEY in data:
        if STEPS_KEY in data:
            raise SymdynError(f"{STEPS_KEY} are checked symbolically: leave out {AT_KEY}", file=file)
        at = compare_at_state(dyn, parsed, data[AT_KEY], data.get(TOLERANCE_KEY), file)
        report.results = [EntryResult(*r) for r in at]
        return report
    if STEPS_KEY in data:
        steps, report.first_step, sizes = check_steps(
            robot,
            data[STEPS_KEY],
            method,
            file,
            lambda value, label: answer_entry(value, robot, file, label),
            lambda e, g: compare_entry(e, g, symbols, points),
        )
        report.results = [EntryResult(*s) for s in steps]
        report.entries += sum(sizes)
        report.steps_given = len(sizes)
    show = derive_form(dyn)
    for name, got in parsed.items():
        expected = dyn.closed_form(name)
        for index, g in got.items():
            e = expected[index[0] - 1, index[1] - 1] if name in MATRICES else expected[index[0] - 1]
            status = compare_entry(e, g, symbols, points)
            shown = show(name, index, e) if status == "differs" else ""
            report.results.append(EntryResult(name, index, e, g, status, shown))
    report.notes = asymmetry_notes(
        parsed.get("M", {}), lambda a, b: compare_entry(a, b, symbols, points) == "differs"
    )
    if not report.results:
        raise SymdynError(_NOTHING_GIVEN, file=file)
    return report
