"""Scaling plot: generation time and operation counts of the generic chains of 2..12 joints.

    python bench/plot.py                  # measure (about 1.5 minutes on 2 cores) and plot
    python bench/plot.py --from-json      # re-plot bench/results/scaling.json without measuring

For every chain (bench/chains.py) it runs `symdyn generate chain_N.yaml --target c`
in a fresh process (wall and CPU seconds, fastest of --gen-runs, as bench/run.py
does), reads symdyn's
operation counts of tau, M and C from the generated C, and counts the CasADi
route's flops for tau and M (bench/casadi_route.py) for reference. Writes
bench/results/scaling.json and bench/results/scaling.png (matplotlib, Agg).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import casadi_route  # noqa: E402
import chains  # noqa: E402
from generation import generate_best  # noqa: E402
from machine import RESULTS, log, machine, pin_to_one_core  # noqa: E402
from row import FUNCTIONS, SHORT  # noqa: E402


def measure(sizes, gen_runs: int = 2) -> list[dict]:
    files = chains.write_robot_files(sizes=sizes)
    out = []
    with tempfile.TemporaryDirectory(prefix="symdyn_scaling_") as tmp:
        for n in sizes:
            path = files[f"chain_{n}"]
            gen_dir = Path(tmp) / f"chain_{n}"
            log(f"[chain_{n}] symdyn generate --target c ...")
            wall, cpu, robot, ops = generate_best(path, gen_dir, gen_runs)
            fns = casadi_route.casadi_functions(robot)
            out.append(
                {
                    "n": n,
                    "gen_wall": wall,
                    "gen_cpu": cpu,
                    "ops": {fn: ops[fn]["total"] for fn in FUNCTIONS},
                    "casadi_ops": {
                        fn: casadi_route.flops(fns[fn])["total"] for fn in ("inverse_dynamics", "mass_matrix")
                    },
                }
            )
    return out


def plot(data: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = [d["n"] for d in data]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    ax1.plot(n, [d["gen_wall"] for d in data], "o-", label="wall")
    ax1.plot(n, [d["gen_cpu"] for d in data], "s--", label="CPU (user+sys)")
    ax1.set_xlabel("joints")
    ax1.set_ylabel("seconds")
    ax1.set_title("time of `symdyn generate --target c` (fresh process)")
    ax1.set_ylim(bottom=0)
    ax1.grid(True, alpha=0.3)
    ax1.legend()

    styles = {"inverse_dynamics": "o-", "mass_matrix": "s-", "coriolis_matrix": "^-"}
    for fn, style in styles.items():
        ax2.plot(n, [d["ops"][fn] for d in data], style, label=f"symdyn {SHORT[fn]}")
    for fn, style in (("inverse_dynamics", "o:"), ("mass_matrix", "s:")):
        ax2.plot(
            n, [d["casadi_ops"][fn] for d in data], style, color="gray", label=f"CasADi route {SHORT[fn]}"
        )
    ax2.set_xlabel("joints")
    ax2.set_ylabel("operations per call")
    ax2.set_ylim(bottom=0)
    ax2.set_title("operation count of the generated C")
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=8)
    for ax in (ax1, ax2):
        ax.set_xticks(n)
    fig.suptitle("Generic spatial revolute chains (bench/chains.py)")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="generation time and op counts against the number of joints")
    ap.add_argument("--from-json", action="store_true", help="plot bench/results/scaling.json as is")
    ap.add_argument("--max-joints", type=int, default=12)
    ap.add_argument("--gen-runs", type=int, default=2, help="generation runs per chain, fastest kept")
    opts = ap.parse_args(argv)
    data_file = RESULTS / "scaling.json"
    if opts.from_json:
        data = json.loads(data_file.read_text())["chains"]
    else:
        pin_to_one_core()
        data = measure(range(2, opts.max_joints + 1), opts.gen_runs)
        RESULTS.mkdir(parents=True, exist_ok=True)
        data_file.write_text(json.dumps({"machine": machine(), "chains": data}, indent=1))
    png = RESULTS / "scaling.png"
    plot(data, png)
    for d in data:
        print(
            f"chain_{d['n']:<3d} gen {d['gen_wall']:6.2f} s wall {d['gen_cpu']:6.2f} s CPU   "
            + "  ".join(
                f"{SHORT[f]} {d['ops'][f]}" for f in ("inverse_dynamics", "mass_matrix", "coriolis_matrix")
            )
        )
    print(f"wrote {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
