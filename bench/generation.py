"""Generation in bench/run.py: `symdyn generate ROBOT --target c --functions dynamics`, timed.

`generate_best(path, out_dir, runs)` runs the command line `runs` times (wall and CPU of
the child, fastest kept), then reads symdyn's own operation counts (OpCount, the cost
comment above every function of NAME_dynamics.c). Also used by bench/plot.py.
"""

from __future__ import annotations

import re
import resource
import sys
import time
from pathlib import Path

from machine import run
from robots import URDF_TIPS, load
from row import FUNCTIONS

__all__ = ["generate", "generate_best", "op_counts", "symdyn_command"]


def symdyn_command() -> list[str]:
    """The `symdyn` command of this interpreter's environment (or the same entry point via -c)."""
    exe = Path(sys.executable).with_name("symdyn")
    if exe.exists():
        return [str(exe)]
    return [sys.executable, "-c", "import sys; from symdyn.cli.main import main; sys.exit(main())"]


_OPS = re.compile(
    r"\((\d+) operations: (\d+) multiplications, (\d+) additions, (\d+) divisions, "
    r"(\d+) trigonometric calls, (\d+) other calls\) \*/\s*\nvoid (\w+)\("
)


def op_counts(c_text: str, name: str, robot=None) -> dict:
    """Per function {total, mul, add, div, trig, other}: the counts printed in NAME_dynamics.c.

    These are symdyn's own OpCount (the cost comment above every function). If the
    comments cannot be read, the counts come from symdyn.codegen.context(robot).
    """
    out = {}
    for m in _OPS.finditer(c_text):
        fn = m.group(7)[len(name) + 1 :]
        total, mul, add, div, trig, other = map(int, m.groups()[:6])
        out[fn] = dict(total=total, mul=mul, add=add, div=div, trig=trig, other=other)
    if set(out) >= set(FUNCTIONS) or robot is None:
        return out
    from symdyn.codegen import context

    for spec in context(robot).functions:
        o = spec.ops
        out[spec.name] = dict(total=o.total, mul=o.mul, add=o.add, div=o.div, trig=o.trig, other=o.other)
    return out


def generate(path: Path, out_dir: Path, seven: bool = True) -> tuple[float, float]:
    """`symdyn generate PATH --target c --functions dynamics --out OUT_DIR` (the seven functions the
    generation goals are stated for; every function when not `seven`) in a fresh process:
    (wall s, CPU s)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    tip = ["--tip", URDF_TIPS[path]] if path in URDF_TIPS else []
    run(
        [
            *symdyn_command(),
            "generate",
            path,
            "--target",
            "c",
            "--functions",
            "dynamics" if seven else "all",
            "--out",
            out_dir,
            "--force",
            *tip,
        ]
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def generate_best(path: Path, out_dir: Path, runs: int) -> tuple[float, float, object, dict]:
    """`generate` `runs` times (fastest wall and CPU kept), then every function once more (the
    harnesses also time the regressor and the derivatives), load the robot and read op_counts.

    Returns (wall s, CPU s of the seven functions, robot, op counts of OUT_DIR/NAME_dynamics.c).
    """
    times = [generate(path, out_dir) for _ in range(runs)]
    generate(path, out_dir, seven=False)
    wall, cpu = min(w for w, _ in times), min(c for _, c in times)
    robot = load(path)
    ops = op_counts((out_dir / f"{robot.name}_dynamics.c").read_text(), robot.name, robot)
    return wall, cpu, robot, ops
