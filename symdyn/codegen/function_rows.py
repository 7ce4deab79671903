"""The records of a generated function, shared by every family of them (symdyn.codegen.functions,
derivative_functions, regressor_functions): its inputs (`Input`, `Inputs`), its outputs (`Output`,
over the size names `DIMS`), a function before elimination (`FunctionRow`) and after
(`FunctionSpec`). Nothing here depends on a family, so the family modules import this one and
symdyn.codegen.functions imports them all, without a cycle."""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..algorithms.operational_space import TASK_AXES
from ..dynamics import Dynamics
from ..symbolic.program import Program
from ..symbolic.simplify import Eliminated, OpCount

__all__ = [
    "DIMS",
    "FrameChoice",
    "FunctionRow",
    "FunctionSpec",
    "Input",
    "Inputs",
    "Output",
    "joint_matrix_output",
    "vector_output",
    "with_steps",
]


@dataclass(frozen=True)
class Input:
    """A vector argument: its name in the generated code and its symbols."""

    name: str
    symbols: tuple[sp.Symbol, ...]


#: Size names of the outputs (Output.dims): "1" for a vector's columns, "n" for the joints, "2n"
#: for the state x = (q, qd), "3", "4", "6" fixed sizes, "k" the task axes of the
#: operational-space functions (symdyn.codegen.frame_functions), "nact" and "npas" the actuated
#: and passive coordinates of a robot with loops (symdyn.codegen.loop_functions), "nq" and "nv" a
#: floating robot's configuration and velocity sizes (symdyn.codegen.configuration_functions),
#: "ncontact" and "nlambda" the contacts and their rows (symdyn.codegen.contact_functions); a
#: target spells each as its own expression (C: a macro), and a family of functions that needs
#: another size adds the name and every target's spelling.
DIMS = (
    "1",
    "n",
    "2n",
    "nstd",
    "nbase",
    "3",
    "4",
    "6",
    "k",
    "nact",
    "npas",
    "nq",
    "nv",
    "ncontact",
    "nlambda",
)


@dataclass(frozen=True)
class Output:
    """One output array of a generated function: its argument name, shape and meaning.

    `dims` names the two sizes for the targets (see DIMS); a vector has dims (rows, "1") and
    a matrix is stored row-major, entry [i*cols + j] being row i, column j.
    """

    name: str
    rows: int
    cols: int
    doc: str
    dims: tuple[str, str]

    @property
    def size(self) -> int:
        return self.rows * self.cols

    @property
    def matrix(self) -> bool:
        """A matrix even when it has one column (M of a one-joint robot is 1 x 1)."""
        return self.dims[1] != "1"


def vector_output(name: str, n: int, doc: str) -> Output:
    """An n x 1 output over the joints (tau, V, G, F, qdd)."""
    return Output(name, n, 1, doc, ("n", "1"))


def joint_matrix_output(name: str, n: int, doc: str) -> Output:
    """An n x n output over the joints, row-major (M, C, derivatives by q or qd)."""
    return Output(name, n, n, doc, ("n", "n"))


@dataclass(frozen=True)
class FunctionSpec:
    """One generated function: inputs, one or more output arrays, and the code computing them.

    `code.outputs` holds every output's row-major entries, the outputs one after the other in
    the order of `results` (the order of the arguments); `entries(result)` is one output's part.
    """

    name: str
    doc: str
    inputs: tuple[Input, ...]
    results: tuple[Output, ...]
    code: Eliminated

    def __post_init__(self) -> None:
        assert len(self.code.outputs) == sum(r.size for r in self.results), f"{self.name}: output sizes"

    @property
    def ops(self) -> OpCount:
        return self.code.ops

    @property
    def temporaries(self):
        return self.code.temporaries

    @property
    def outputs(self):
        """Every entry of every output, in argument order (see `entries`)."""
        return self.code.outputs

    def entries(self, result: Output) -> list:
        """The row-major entries of one of this function's outputs."""
        start = 0
        for r in self.results:
            if r is result:
                return list(self.code.outputs[start : start + r.size])
            start += r.size
        raise KeyError(f"{result.name} is not an output of {self.name}")

    @property
    def free_symbols(self) -> set[sp.Symbol]:
        """Every symbol the temporaries and outputs read (input symbols and temporaries)."""
        return set().union(
            *(e.free_symbols for _, e in self.code.temporaries),
            *(sp.sympify(e).free_symbols for e in self.code.outputs),
        )


@dataclass(frozen=True)
class FunctionRow:
    """A function before elimination: what `build_functions` turns into a FunctionSpec.

    `exprs` are the outputs' row-major entries over the program's intermediates (in the order
    of `results`); `steps` the assignments they need beyond the dynamics' own program. Rows of
    one `cse` group share a CSE pass; a family in a group of its own cannot change the code of
    the others. `visit`, if given, is the order of the entries in which their temporaries are laid
    out (symdyn.symbolic.simplify.eliminate_many); `lead`, intermediates of `steps` laid out first,
    in their order.
    """

    name: str
    doc: str
    inputs: tuple[Input, ...]
    results: tuple[Output, ...]
    exprs: tuple[sp.Expr, ...]
    steps: tuple = ()
    cse: str = ""
    visit: tuple[int, ...] | None = None
    lead: tuple[sp.Symbol, ...] = ()


@dataclass(frozen=True)
class FrameChoice:
    """The frames of the generated frame functions and the task axes of the operational space.

    `frames`: (name, identifier, link description) per frame, in order; `rows`: the world-aligned
    Jacobian rows of the task axes (0-5)."""

    frames: tuple[tuple[str, str, str], ...] = ()
    rows: tuple[int, ...] = tuple(range(6))

    @property
    def axes(self) -> tuple[str, ...]:
        return tuple(TASK_AXES[r] for r in self.rows)


@dataclass(frozen=True)
class Inputs:
    """The input vectors every function family draws from: q, qd, qdd, tau and p."""

    q: Input
    qd: Input
    qdd: Input
    tau: Input
    p: Input
    #: the frames and task axes of the frame functions (symdyn.codegen.frame_functions)
    frames: FrameChoice = FrameChoice()

    @classmethod
    def of(cls, dyn: Dynamics, frames: FrameChoice | None = None) -> Inputs:
        n = dyn.n
        return cls(
            Input("q", tuple(dyn.q)),
            Input("qd", tuple(dyn.qd)),
            Input("qdd", tuple(dyn.qdd)),
            Input("tau", tuple(sp.Symbol(f"tau{i + 1}") for i in range(n))),
            Input("p", tuple(dyn.params)),
            frames or FrameChoice(),
        )

    @property
    def symbols(self) -> tuple[sp.Symbol, ...]:
        return (*self.q.symbols, *self.qd.symbols, *self.qdd.symbols, *self.tau.symbols, *self.p.symbols)


def with_steps(rows: list[tuple], prog: Program, first: int, cse: str) -> list[FunctionRow]:
    """FunctionRows of one CSE group, the first carrying every step after `first` in `prog` that
    the rows need (build_functions gathers the rows' steps into one program)."""
    if not rows:
        return []
    new = {s for s, _ in prog.assignments[first:]}
    steps = [a for a in prog.needed([e for row in rows for e in row[4]]) if a[0] in new]
    carried = [tuple(steps)] + [()] * (len(rows) - 1)
    return [FunctionRow(*row, s, cse=cse) for row, s in zip(rows, carried, strict=True)]
