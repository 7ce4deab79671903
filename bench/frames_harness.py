"""The C side of bench/frames.py: a harness around symdyn's generated frame functions.

The harness (`HARNESS`, one per robot and frame) links NAME_dynamics.c generated with
`--functions kinematics operational_space --frames F`. `STATES check K` prints the pose, the
world-aligned Jacobian, Jdot*qd and Lambda at the first K states; `STATES time REPS TARGET_MS`
prints ns per call of every repetition, interleaved across the functions, in the format of
bench/c_harness.py (parse_harness reads both).
"""

from __future__ import annotations

import time
from pathlib import Path

from c_snippets import JOINT_STATES, skeleton
from machine import C_COMPILER, FLAGS, run
from states import NSTATES

from symdyn.codegen.frame_functions import identifier

__all__ = ["LABELS", "build_frame_harness"]

#: What the harness times, in order: the symdyn functions called per label.
LABELS = {
    "pose": ("pose",),
    "jacobian": ("jacobian",),
    "pose_jacobian": ("pose", "jacobian"),
    "jacobian_dot_qd": ("jacobian_dot_qd",),
    "operational_space_inertia": ("operational_space_inertia",),
    "operational_space_bias": ("operational_space_bias",),
}

_ARGS = {  # the inputs of each generated frame function (before p and the output)
    "pose": "Q[k]",
    "jacobian": "Q[k]",
    "jacobian_dot_qd": "Q[k], QD[k]",
    "operational_space_inertia": "Q[k]",
    "operational_space_bias": "Q[k], QD[k]",
}
_LEN = {"pose": "16", "jacobian": "6 * N", "jacobian_dot_qd": "6", "operational_space_inertia": "36"}

HARNESS = r"""/* Frame-function timing harness: written by bench/frames_harness.py, do not edit. */
{prelude}
#include "{prefix}_dynamics.h"

#define N {n}
#define K {nstates}
#define MAXREPS 1000
#define NB {nb}

static double Q[K][N], QD[K][N], QDD[K][N], TAU[K][N];
static double OUT[16 + 6 * N + 36 + 6];
static const double *P = NULL; /* numeric robot: no free parameters */
static const char *LABELS[NB] = {{{labels}}};

{run_bench}

{print_out}

int main(int argc, char **argv)
{{
{main_head}{read_states}    if (strcmp(argv[2], "check") == 0) {{
        int ncheck = argc > 3 ? atoi(argv[3]) : 4;
        for (k = 0; k < ncheck && k < K; ++k) {{
{checks}
        }}
        return 0;
    }}
{time_main}}}
"""


def _call(prefix: str, frame: str, function: str, out: str) -> str:
    return f"{prefix}_{identifier(frame)}_{function}({_ARGS[function]}, P, {out})"


def harness_source(prefix: str, n: int, frame: str) -> str:
    """The harness's C for robot `prefix` (n joints) and frame `frame`."""
    cases = []
    for functions in LABELS.values():
        calls, offset = [], 0
        for fn in functions:
            calls.append(_call(prefix, frame, fn, f"OUT + {offset}" if offset else "OUT"))
            offset += 16 if fn == "pose" else 0
        cases.append("LOOP(" + "; ".join(calls) + ", OUT[k % 16])")
    checks = [
        f'            {_call(prefix, frame, fn, "OUT")}; print_out("{fn}", k, OUT, {_LEN[fn]});'
        for fn in _LEN
    ]
    labels = ", ".join(f'"{label}"' for label in LABELS)
    return HARNESS.format(
        prefix=prefix,
        n=n,
        nstates=NSTATES,
        nb=len(LABELS),
        labels=labels,
        checks="\n".join(checks),
        **skeleton(cases, *JOINT_STATES),
    )


def build_frame_harness(prefix: str, n: int, frame: str, gen_dir: Path, work: Path) -> tuple[Path, float]:
    """Write and compile the harness with machine.FLAGS: (executable, build seconds)."""
    name = f"frames_{prefix}_{identifier(frame)}"
    src = work / f"{name}.c"
    src.write_text(harness_source(prefix, n, frame))
    exe = work / name
    t0 = time.perf_counter()
    run([C_COMPILER, *FLAGS, "-I", gen_dir, "-o", exe, src, gen_dir / f"{prefix}_dynamics.c", "-lm"])
    return exe, time.perf_counter() - t0
