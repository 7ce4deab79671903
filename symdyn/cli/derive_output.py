"""What `symdyn derive` prints, in its three forms (text, JSON or LaTeX each):

- "configuration" (the default): tau = M qdd + B [qd qd] + Csq [qd^2] + G + F
  (symdyn.algorithms.configuration_space), M by its upper triangle, the nonzero entries of B
  and Csq, then G and F; canonical closed forms, the same from either method; with `lumped`,
  each distinct coefficient named once and defined at the end (symdyn.lumped: by value, or over
  the base parameters, which are listed too, when the inertial data is symbolic);
- "compact": the program of named intermediates after common-subexpression elimination, one
  assignment per line as the generated code computes them, then M, C, V, G, F over them;
- "expanded": the recursion's full expansion (the output of symdyn before the configuration
  form), M, C, V, G, F.

JSON always has the keys M, C, V, G, F, and B and Csq in the configuration form; every
expression string parses with sympy.sympify. With `--frames F1,F2` each frame's pose world_T_F
and world-aligned Jacobian follow (symdyn.algorithms.frame_kinematics; JSON key "frames").
"""

from __future__ import annotations

import json
import re

import sympy as sp

from ..algorithms.configuration_space import pair_columns
from ..dynamics import Dynamics
from ..errors import SymdynError
from ..lumped import lumped_constants
from ..model.names import comment_text, identifiers, latex_text
from ..symbolic.simplify import count_ops, eliminate
from ..symbolic.trig_text import number_text

__all__ = [
    "FORMS",
    "header",
    "json_header",
    "derive_text",
    "derive_json",
    "configuration_entries",
    "lumped_sections",
    "lumped_lines",
    "lumped_json",
    "lumped_latex",
    "latex_notes",
    "latex_align",
    "prune_summary",
    "frame_names",
    "frames_text",
    "frames_json",
    "frames_latex",
]

FORMS = ("configuration", "compact", "expanded")
PRINTED = ("M", "C", "V", "G", "F")


def floating_note(dyn: Dynamics) -> str:
    """ " and a floating base (NV = ..)" after the number of joints of a floating robot, else ""."""
    return f" and a floating base (NV = {dyn.n})" if dyn.robot.floating else ""


def header(dyn: Dynamics, equation: str) -> list[str]:
    return [
        f"# {comment_text(dyn.robot.name)}: {dyn.robot.n} joints{floating_note(dyn)}, method {dyn.method}",
        f"# joints: q = ({', '.join(map(str, dyn.q))}); free parameters: "
        + (", ".join(map(str, dyn.params)) or "none"),
        f"# {equation}",
    ]


def configuration_entries(dyn: Dynamics, lumped: bool = False, cs=None, text: bool = False):
    """(labelled entries, lumped constants) of the configuration-space form.

    Returns:
        A dict name -> list of (label, entry) for M (upper triangle), B and Csq (nonzero
        entries), G and F; and with `lumped` the `LumpedConstants` the coefficients were named
        by (symdyn.lumped: over the base parameters when the inertial data is symbolic), else
        None. An entry is a SymPy expression, or with `text` its SymPy-syntax string written
        straight from the polynomial (ConfigurationSpace.text: the fast way for large forms).
        `cs`: another configuration-space form of `dyn` (a pruned one) instead of its own.
    """
    cs = cs or dyn.configuration_space
    n = dyn.n
    pairs = pair_columns(n)
    constants = lumped_constants(dyn, cs) if lumped else None

    def get(name, r, c):
        if constants is not None:
            return constants.entry(name, r, c, text)
        return cs.text(name, r, c) if text else cs.expr(name, r, c)

    F = dyn.closed_form("F")
    out = {
        "M": [(f"M[{i + 1},{j + 1}]", get("M", i, j)) for i in range(n) for j in range(i, n)],
        "B": [
            (f"B[{k + 1},({pairs[c][0] + 1},{pairs[c][1] + 1})]", get("B", k, c)) for k, c in cs.nonzero("B")
        ],
        "Csq": [(f"Csq[{k + 1},{i + 1}]", get("Csq", k, i)) for k, i in cs.nonzero("Csq")],
        "G": [(f"G[{k + 1}]", get("G", k, 0)) for k in range(n)],
        "F": [(f"F[{k + 1}]", sp.sstr(e) if text else e) for k, e in enumerate(F)],
    }
    return out, constants


def lumped_sections(constants) -> list[tuple[str, list[tuple[sp.Symbol, sp.Expr]]]]:
    """(heading, definitions) of the lumped constants, the base parameters they use and the
    standard parameters those use (empty ones left out)."""
    sections = [
        ("lumped constants", constants.definitions()),
        ("base parameters", constants.base_definitions()),
        ("standard parameters", constants.standard_definitions()),
    ]
    return [(head, items) for head, items in sections if items]


def prune_summary(dyn: Dynamics, pruned) -> list[str]:
    """Comment lines: what --prune REL guarantees and what it saves (operation counts)."""
    ops = {}
    for name in ("M", "B", "Csq", "G"):
        before = count_ops([], list(dyn.configuration_space.matrix(name))).total
        ops[name] = (before, count_ops([], list(pruned.configuration.matrix(name))).total)
    text = ", ".join(f"{k} {a} -> {b}" for k, (a, b) in ops.items())
    total = tuple(sum(v[i] for v in ops.values()) for i in (0, 1))
    return [
        f"# pruned at {pruned.rel:g} of each entry's largest value over the joint ranges: "
        f"{pruned.terms_before} -> {pruned.terms_after} terms",
        f"# {pruned.ranges}",
        f"# guaranteed: |error of an entry| <= {pruned.worst():.4g} x its largest value "
        "(per entry: the sum of the dropped terms' maxima)",
        f"# operations {text}; total {total[0]} -> {total[1]}",
    ]


def _value(v: sp.Expr) -> str:
    """A lumped constant's value, a float to 15 digits as the entries print theirs."""
    return number_text(float(v)) if v.is_Float else sp.sstr(v)


def _configuration_text(dyn: Dynamics, lumped: bool, pruned=None) -> str:
    n = dyn.n
    pairs = ", ".join(f"{dyn.qd[i]}*{dyn.qd[j]}" for i, j in pair_columns(n)) or "none"
    lines = header(dyn, "tau = M(q) qdd + B(q) [qd qd] + Csq(q) [qd^2] + G(q) + F(qd)")
    lines.append(f"# [qd qd] = ({pairs}); [qd^2] = ({', '.join(f'{v}**2' for v in dyn.qd)})")
    if pruned is not None:
        lines += prune_summary(dyn, pruned)
    entries, constants = configuration_entries(dyn, lumped, pruned and pruned.configuration, text=True)
    if constants is not None:
        lines += [f"# note: {note}" for note in constants.notes()]
    for name, items in entries.items():
        lines.append("")
        lines += [f"{label} = {e}" for label, e in items] or [f"# {name} = 0"]
    if constants is not None:
        lines += lumped_lines(constants)
    return "\n".join(lines) + "\n"


def lumped_lines(constants) -> list[str]:
    """The text of the lumped constants' sections: a blank line, `# heading`, `name = value`."""
    out = []
    for head, items in lumped_sections(constants):
        out += ["", f"# {head}"] + [f"{s} = {_value(v)}" for s, v in items]
    return out


def _entry_name(name: str, shape: tuple[int, int], k: int) -> str:
    cols = shape[1]
    return f"{name}[{k // cols + 1},{k % cols + 1}]" if name in ("M", "C") else f"{name}[{k + 1}]"


def _matrices(dyn: Dynamics, form: str) -> dict[str, sp.Matrix]:
    if form == "expanded":
        return {k: sp.Matrix(*dyn.compact[k].shape, dyn.expanded(k)) for k in PRINTED}
    return {k: dyn.closed_form(k) for k in PRINTED}


def _compact(dyn: Dynamics):
    """The eliminated program: temporaries and M, C, V, G, F over them."""
    outputs = [e for k in PRINTED for e in dyn.compact[k]]
    code = eliminate(dyn.assignments(PRINTED), outputs, prefix="x")
    mats, k = {}, 0
    for name in PRINTED:
        shape = dyn.compact[name].shape
        size = shape[0] * shape[1]
        mats[name] = sp.Matrix(*shape, list(code.outputs[k : k + size]))
        k += size
    return code.temporaries, mats


def derive_text(dyn: Dynamics, form: str = "configuration", lumped: bool = False, pruned=None) -> str:
    """The text of `symdyn derive` in one of FORMS (`pruned`: symdyn.algorithms.pruning.Pruned,
    configuration form only)."""
    if form == "configuration":
        return _configuration_text(dyn, lumped, pruned)
    lines = header(dyn, "tau = M(q) qdd + V(q, qd) + G(q) + F(qd),  V = C(q, qd) qd")
    if form == "compact":
        temporaries, mats = _compact(dyn)
        lines.append("")
        lines += [f"{s} = {sp.sstr(e)}" for s, e in temporaries]
    else:
        mats = _matrices(dyn, form)
    for name in PRINTED:
        m = mats[name]
        lines.append("")
        lines += [f"{_entry_name(name, m.shape, k)} = {sp.sstr(e)}" for k, e in enumerate(m)]
    return "\n".join(lines) + "\n"


def _nested(m: sp.Matrix, vector: bool) -> list:
    if vector:
        return [sp.sstr(e) for e in m]
    return [[sp.sstr(m[i, j]) for j in range(m.cols)] for i in range(m.rows)]


def json_header(dyn: Dynamics, form: str) -> dict:
    """The keys every JSON of `derive` starts with: robot, method, joints, form, q, qd, qdd, params."""
    return {
        "robot": dyn.robot.name,
        "method": dyn.method,
        "joints": dyn.n,
        "form": form,
        "q": [str(s) for s in dyn.q],
        "qd": [str(s) for s in dyn.qd],
        "qdd": [str(s) for s in dyn.qdd],
        "params": [str(s) for s in dyn.params],
    }


def derive_json(dyn: Dynamics, form: str = "configuration", lumped: bool = False) -> str:
    """The JSON of `symdyn derive`: keys M, C, V, G, F (and B, Csq, lumped in the
    configuration form; assignments in the compact form)."""
    doc = json_header(dyn, form)
    if form == "configuration":
        doc.update(_configuration_json(dyn, lumped))
        return json.dumps(doc, indent=2) + "\n"
    if form == "compact":
        temporaries, mats = _compact(dyn)
        doc["assignments"] = [[str(s), sp.sstr(e)] for s, e in temporaries]
    else:
        mats = _matrices(dyn, form)
    for name in PRINTED:
        doc[name] = _nested(mats[name], name not in ("M", "C"))
    return json.dumps(doc, indent=2) + "\n"


def _configuration_json(dyn: Dynamics, lumped: bool) -> dict:
    """M, C, V, G, F, B, Csq (and lumped) of the configuration-space form as strings, written
    from the polynomials: V_k = sum B[k,(i,j)] qd_i qd_j + sum Csq[k,i] qd_i^2 and
    C_kj = sum_i Gamma^k_ij qd_i with Gamma^k_ij = B[k,(i,j)]/2 (i != j), Gamma^k_ii = Csq[k,i]."""
    n = dyn.n
    pairs = pair_columns(n)
    entries, constants = configuration_entries(dyn, lumped, text=True)
    index = {label: e for items in entries.values() for label, e in items}
    qd = [sp.sstr(v) for v in dyn.qd]
    B = [[index.get(f"B[{k + 1},({i + 1},{j + 1})]", "0") for i, j in pairs] for k in range(n)]
    Csq = [[index.get(f"Csq[{k + 1},{i + 1}]", "0") for i in range(n)] for k in range(n)]

    def gamma(k: int, i: int, j: int) -> str:
        """Gamma^k_ij times qd_i as text ("" when zero)."""
        if i == j:
            return f"({Csq[k][i]})*{qd[i]}" if Csq[k][i] != "0" else ""
        b = B[k][pairs.index((min(i, j), max(i, j)))]
        return f"({b})*{qd[i]}/2" if b != "0" else ""

    def total(terms) -> str:
        return " + ".join(t for t in terms if t) or "0"

    V = [
        total(
            [f"({b})*{qd[i]}*{qd[j]}" for b, (i, j) in zip(B[k], pairs, strict=True) if b != "0"]
            + [f"({c})*{qd[i]}**2" for i, c in enumerate(Csq[k]) if c != "0"]
        )
        for k in range(n)
    ]
    doc = {
        "M": [[index[f"M[{min(i, j) + 1},{max(i, j) + 1}]"] for j in range(n)] for i in range(n)],
        "C": [[total(gamma(k, i, j) for i in range(n)) for j in range(n)] for k in range(n)],
        "V": V,
        "G": [index[f"G[{k + 1}]"] for k in range(n)],
        "F": [e for _, e in entries["F"]],
        "B": B,
        "Csq": Csq,
    }
    if constants is not None:
        doc.update(lumped_json(constants))
    return doc


def lumped_json(constants) -> dict:
    """The JSON keys of the lumped constants: lumped (name -> definition), base_parameters and
    standard_parameters (name -> definition, when used) and notes (when any)."""
    sections = dict(lumped_sections(constants))
    doc = {"lumped": {str(s): _value(v) for s, v in sections.get("lumped constants", [])}}
    for head in ("base parameters", "standard parameters"):
        if head in sections:
            doc[head.replace(" ", "_")] = {str(s): _value(v) for s, v in sections[head]}
    if constants.notes():
        doc["notes"] = constants.notes()
    return doc


def _latex_label(name: str, label: str) -> str:
    """M[1,2] -> M_{1,2}, B[1,(2,3)] -> B_{1,(2,3)}, Csq[2,1] -> C^{\\mathrm{sq}}_{2,1}, G[1] -> G_{1}."""
    head = "C^{\\mathrm{sq}}" if name == "Csq" else name
    return f"{head}_{{{label[len(name) + 1 : -1]}}}"


def _latex_name(name: str) -> str:
    """I12 -> I_{12}, Izz1R -> \\mathrm{Izz}_{1R}: letters, then the rest as a subscript
    (every other name upright, as latex_text spells it)."""
    m = re.fullmatch(r"([A-Za-z]+)(\d\w*)", name)
    if m is None:
        return f"\\mathrm{{{latex_text(name)}}}"
    head = m[1] if len(m[1]) == 1 else f"\\mathrm{{{m[1]}}}"
    return f"{head}_{{{m[2]}}}"


def latex_align(nt, items, expand: bool = True) -> str:
    """One align* of (LaTeX head, expression), each broken at its top-level + and - when long."""
    rows = []
    for head, e in items:
        lines = nt.lines(nt.prepare(e), expand=expand)
        rows.append(f"{head} &= {lines[0]}" + "".join(f" \\\\\n  &\\quad {ln}" for ln in lines[1:]))
    return "\\begin{align*}\n" + " \\\\\n".join(rows) + "\n\\end{align*}"


def latex_notes(constants) -> list[str]:
    """The lumped constants' notes (none without them) as LaTeX comment lines, each one line."""
    return [f"% note: {comment_text(note)}" for note in (constants.notes() if constants is not None else [])]


def lumped_latex(nt, constants) -> list[str]:
    """The lumped constants' sections as align* blocks (the lumped constants, the base
    parameters, the standard parameters), after giving each name they use its LaTeX name in
    the Notation nt (I12 -> I_{12}) so entries written over them print too."""
    sections = lumped_sections(constants)
    named = {s for _, items in sections for s, _ in items}
    named |= constants.inertial.referenced | constants.gravity.referenced
    for s in sorted(named, key=str):
        nt.names.setdefault(s, _latex_name(s.name))
    return [latex_align(nt, [(nt.names[s], v) for s, v in items]) for _, items in sections]


def derive_latex_configuration(dyn: Dynamics, lumped: bool = False) -> str:
    """The configuration-space form in LaTeX (amsmath): one align* per quantity, each entry
    broken over lines at its top-level + and - when long (symdyn.codegen.latex.Notation)."""
    from ..codegen.latex import Notation

    nt = Notation(dyn)
    entries, constants = configuration_entries(dyn, lumped)
    out = [
        "% tau = M(q) qdd + B(q) [qd qd] + Csq(q) [qd^2] + G(q) + F(qd)  (needs \\usepackage{amsmath})",
    ]
    definitions = lumped_latex(nt, constants) if constants is not None else []
    out += latex_notes(constants)
    for name, items in entries.items():
        if items:
            out.append(latex_align(nt, [(_latex_label(name, label), e) for label, e in items]))
    out += definitions
    abbreviations = []
    for ph, (kind, idx) in sorted(nt.trig.items(), key=lambda item: item[0].name):
        angle = " + ".join(f"q_{{{i}}}" for i in idx)
        abbreviations.append(f"${nt.names[ph]} = \\{'sin' if kind == 's' else 'cos'}({angle})$")
    if abbreviations:
        out.insert(1, "Abbreviations: " + ", ".join(abbreviations) + ".")
    return "\n".join(out) + "\n"


def frame_names(dyn: Dynamics, text: str | None) -> list[str]:
    """The frames of `--frames F1,F2` (None: none), each checked to exist (Robot.frame)."""
    if text is None:
        return []
    names = list(dict.fromkeys(a.strip() for a in text.split(",") if a.strip()))
    if not names:
        raise SymdynError("--frames: no frame given (a link's name or one of the robot's frames)")
    for name in names:
        dyn.robot.frame(name, "--frames")
    return names


def _frame_link(dyn: Dynamics, name: str) -> str:
    k = dyn.robot.frame(name).link
    return "the base" if k < 0 else f"link {k + 1} ({comment_text(dyn.robot.links[k].name)})"


def frames_text(dyn: Dynamics, names: list[str]) -> str:
    """Each frame's pose world_T_F (T[i,j], 4 x 4) and world-aligned Jacobian (J[i,j], 6 x n,
    rows v_x v_y v_z w_x w_y w_z), closed forms, one entry per line as M is printed; a frame's
    entries are labelled by its identifier (symdyn.model.names), its comment line names it."""
    lines = []
    ids = identifiers(names)
    for name in names:
        lines += [
            "",
            f"# frame {comment_text(name)} on {_frame_link(dyn, name)}: pose world_T_F, Jacobian J "
            "world-aligned at F's origin (rows v_x v_y v_z w_x w_y w_z)",
        ]
        for label, m in (("T", dyn.frame_pose(name)), ("J", dyn.frame_jacobian(name))):
            lines += [
                f"{label}_{ids[name]}[{i + 1},{j + 1}] = {sp.sstr(m[i, j])}"
                for i in range(m.rows)
                for j in range(m.cols)
            ]
    return "\n".join(lines) + "\n"


def frames_json(dyn: Dynamics, names: list[str]) -> dict:
    """{frame: {link, pose (4 x 4), jacobian (6 x n)}}, entries as SymPy strings."""
    return {
        name: {
            "link": dyn.robot.frame(name).link + 1,
            "pose": _nested(dyn.frame_pose(name), False),
            "jacobian": _nested(dyn.frame_jacobian(name), False),
        }
        for name in names
    }


def frames_latex(dyn: Dynamics, names: list[str]) -> str:
    """One align* per frame: the entries of T (world_T_F) and J (world-aligned), in LaTeX, each
    frame labelled by its identifier (symdyn.model.names.identifiers: distinct, LaTeX-safe) and
    named in a comment above its block."""
    symbols = {}
    for head, v in (("q", dyn.q), ("\\dot{q}", dyn.qd)):
        symbols.update({s: f"{head}_{{{i + 1}}}" for i, s in enumerate(v)})
    labels = identifiers(names)
    out = []
    for name in names:
        rows = []
        for label, m in (("T", dyn.frame_pose(name)), ("J", dyn.frame_jacobian(name))):
            head = f"{label}^{{\\mathrm{{{latex_text(labels[name])}}}}}"
            rows += [
                f"{head}_{{{i + 1},{j + 1}}} &= {sp.latex(m[i, j], symbol_names=symbols)}"
                for i in range(m.rows)
                for j in range(m.cols)
            ]
        spelled = "" if labels[name] == name else f" (labelled {labels[name]})"
        out.append(
            f"% frame {comment_text(name)}{spelled}: pose world_T_F and world-aligned Jacobian\n"
            "\\begin{align*}\n" + " \\\\\n".join(rows) + "\n\\end{align*}"
        )
    return "\n".join(out) + "\n"
