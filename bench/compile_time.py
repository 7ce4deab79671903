"""How long the generated C of large robots takes to compile, and how fast it runs: one file with
whole functions (the layout before issue 35) against functions cut into parts over several files
(symdyn.codegen.c.parts).

    python bench/compile_time.py                       # panda, solo12 and talos floating
    python bench/compile_time.py talos g1 --floating   # example-robot-data URDFs by name
    python bench/compile_time.py examples/panda.yaml
    python bench/compile_time.py --menagerie DIR       # MuJoCo Menagerie's humanoids in DIR

Each robot is derived as symdyn.compile derives it (symdyn.codegen.context: the default
functions, double precision) and rendered in both layouts. Every .c file is compiled with
symdyn.compile's flags (-O2 -march=native ...): one after the other (CPU seconds of the compiler,
per file) and all at once as symdyn.compile does (wall seconds, on this machine's cores). A small C
program (bench/c_snippets-free: written here) then calls every function of both builds on the same
inputs, checks that their outputs are bit for bit equal, and times them in alternating rounds
(median ns per call), and callgrind counts the instructions of one call of each. The machine may be
shared: compare the ratios of one run, not the absolute seconds of different runs.

--menagerie DIR: the humanoids of MuJoCo Menagerie (MENAGERIE, paths inside a copy of the
repository) found in DIR, each on its floating base: `symdyn generate FILE --floating --target c`
in a fresh process (CPU and wall seconds), then its files compiled as symdyn.compile compiles them (all at
once, at most one per core: wall seconds, and CPU seconds of the compilers). A model whose meshes
are missing is reported in symdyn's one line and skipped; a folder that does not exist, with a
message.
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from symdyn.apps.compilation.build import COMPILE_FLAGS, arch_flags, compile_library  # noqa: E402
from symdyn.codegen import context  # noqa: E402
from symdyn.codegen.c import parts  # noqa: E402
from symdyn.codegen.c import target as c_target  # noqa: E402
from symdyn.codegen.c.runtime import function_table  # noqa: E402

DEFAULT = ("examples/panda.yaml", "solo12", "talos_reduced")
URDFS = {
    "solo12": "solo_description/robots/solo12.urdf",
    "talos_reduced": "talos_data/robots/talos_reduced.urdf",
    "talos": "talos_data/robots/talos_full_v2.urdf",
    "g1": "g1_description/urdf/g1_29dof_rev_1_0.urdf",
}
#: MuJoCo Menagerie's humanoids: name -> the model's path in a copy of the repository
MENAGERIE = {
    "talos": "pal_talos/talos.xml",
    "g1": "unitree_g1/g1.xml",
    "apollo": "apptronik_apollo/apptronik_apollo.xml",
    "toddlerbot": "toddlerbot_2xc/toddlerbot_2xc.xml",
    "op3": "robotis_op3/op3.xml",
}
ROUNDS = 7

DRIVER = r"""#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "{name}_dynamics.h"
static double now(void)
{{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}}
static double in[8][4096], out[8][65536];
int main(int argc, char **argv)
{{
    int f, k, r, reps = argc > 1 ? atoi(argv[1]) : 0;
    srand(35);
    for (f = 0; f < 8; ++f) for (k = 0; k < 4096; ++k) in[f][k] = 2.0 * rand() / RAND_MAX - 1.0;
{calls}
    return 0;
}}
"""

CALL = r"""    memset(out, 0, sizeof out);
    {call};
    if (!reps) {{ for (k = 0; k < {size}; ++k) printf("%a\n", out[0][k]); }}
    else {{
        double t0 = now();
        for (r = 0; r < reps; ++r) {call};
        printf("{fn} %.1f\n", 1e9 * (now() - t0) / reps);
    }}
"""


def load(name: str, floating: bool):
    """A robot file, or example-robot-data's URDF called `name`."""
    import warnings

    from symdyn import load_robot
    from symdyn.parsers.urdf import load_urdf
    from symdyn.regenerate import example_robot_data_folder

    warnings.simplefilter("ignore")
    if Path(name).suffix in (".yaml", ".yml", ".json"):
        return load_robot(ROOT / name)
    if Path(name).suffix == ".urdf":
        return load_urdf(Path(name), floating=floating)
    return load_urdf(example_robot_data_folder() / URDFS[name], floating=floating)


def render(ctx, whole: bool) -> dict[str, str]:
    """The C target's files; `whole`: no parts, one file (the layout before issue 35)."""
    saved = parts.PART_STATEMENTS, parts.SPLIT_BYTES
    if whole:
        parts.PART_STATEMENTS = parts.SPLIT_BYTES = 10**12
    try:
        return c_target.render(ctx)
    finally:
        parts.PART_STATEMENTS, parts.SPLIT_BYTES = saved


def cpu_seconds(cmd: list[str], folder: Path, check: bool = True) -> tuple[float, float] | str:
    """The CPU seconds (user + system) and the wall seconds of the process running `cmd`; with
    `check` False, the last line of its stderr when it fails."""
    before, start = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    done = subprocess.run(
        cmd, cwd=folder, check=check, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
    )
    after, wall = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter() - start
    if done.returncode:
        return (done.stderr.strip().splitlines() or ["failed"])[-1]
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime, wall


def build(ctx, files: dict[str, str], folder: Path) -> dict:
    """Compile each .c serially (CPU seconds), then all at once into a library (wall seconds), then
    the timing driver."""
    folder.mkdir(parents=True)
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    flags = [f for f in COMPILE_FLAGS if f != "-shared"] + list(arch_flags())
    c_files = sorted(n for n in files if n.endswith(".c"))
    timed = {n: cpu_seconds(["gcc", *flags, "-c", n, "-o", n[:-2] + ".o"], folder) for n in c_files}
    serial = {n: cpu for n, (cpu, _) in timed.items()}
    parallel = timed[c_files[0]][1]  # one file: its wall time
    if len(c_files) > 1:  # several: built at once as symdyn.compile builds them
        start = time.perf_counter()
        compile_library(["gcc"], files, folder / "lib.so", arch_flags())
        parallel = time.perf_counter() - start
    calls = []
    for entry in function_table(ctx):
        args = [f"in[{k}]" for k in range(len(entry["inputs"]))]
        args += [f"out[{k}]" for k in range(len(entry["outputs"]))]
        size = entry["outputs"][0][1] * entry["outputs"][0][2]
        call = f"{entry['c_name']}({', '.join(args)})"
        calls.append(CALL.format(call=call, size=size, fn=entry["name"]))
    (folder / "driver.c").write_text(DRIVER.format(name=ctx.name, calls="".join(calls)))
    objects = [n[:-2] + ".o" for n in c_files]
    subprocess.run(["gcc", *flags, "-o", "driver", "driver.c", *objects, "-lm"], cwd=folder, check=True)
    size = sum(len(files[n].encode()) for n in c_files)
    return {"files": len(c_files), "size": size, "serial": serial, "parallel": parallel, "folder": folder}


def run_driver(folder: Path, reps: int) -> dict[str, float]:
    text = subprocess.run(
        [str(folder / "driver"), str(reps)], capture_output=True, text=True, check=True
    ).stdout
    return {fn: float(ns) for fn, ns in (line.split() for line in text.splitlines())}


def instructions(folder: Path, names: list[str], reps: int = 10) -> dict[str, float] | None:
    """Instructions per call of each function (callgrind's inclusive counts over reps + 1 calls; parts
    included), or None without valgrind: unlike ns, not disturbed by other work on the machine."""
    import shutil

    if not (shutil.which("valgrind") and shutil.which("callgrind_annotate")):
        return None
    out = folder / "callgrind.out"
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(folder / "driver"), str(reps)]
    subprocess.run(cmd, capture_output=True, check=True)
    text = subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(out)], capture_output=True, text=True
    ).stdout
    counts = {}
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+)\s.*?:(\w+)(?:\s|$)", line)
        if m and m.group(2) in names:
            counts[m.group(2)] = int(m.group(1).replace(",", "")) / (reps + 1)
    return counts


def largest(files: dict[str, str]) -> str:
    """The function of the whole layout with the most lines of code, and their count."""

    text = "".join(v for k, v in files.items() if k.endswith(".c"))

    counts = {
        m.group(1): m.group(0).count("\n") for m in re.finditer(r"^void (\w+)\(.*?^}", text, re.M | re.S)
    }

    name = max(counts, key=counts.get)
    return f"{name} ({counts[name]} lines)"


def measure_parts(label: str, ctx) -> None:
    """--parts-only: the compile time of the current layout alone (a large robot's whole functions
    can take many minutes)."""
    with tempfile.TemporaryDirectory(prefix="symdyn-compile-time-") as tmp:
        files = render(ctx, False)
        b = build(ctx, files, Path(tmp, "parts"))
        print(f"\n{label}: {ctx.robot.n} joints")
        print(f"{b['size'] / 1000:.0f} KB of C in {b['files']} files, all at once {b['parallel']:.1f} s wall")
        for name, cpu in b["serial"].items():
            print(f"  {name}: {len(files[name].encode()) / 1000:.0f} KB, gcc -O2 {cpu:.1f} s of CPU")
        # without the whole build, which can take many minutes: the instructions per call of each
        # function in parts, and its stash stores and loads in the source (the stash's restrict lets
        # the compiler reload a value from it instead of spilling it: Talos' coriolis_matrix in parts
        # runs fewer instructions than whole although 20,761 stash stores and loads are written)
        text = "".join(v for k, v in files.items() if k.endswith(".c"))
        counts = instructions(b["folder"], [e["c_name"] for e in function_table(ctx)]) or {}
        for entry in function_table(ctx):
            c_name = entry["c_name"]
            bodies = re.findall(rf"^static \w+ void {c_name}_part\d+\(.*?^}}", text, re.M | re.S)
            if bodies and c_name in counts:
                traffic = sum(len(re.findall(r"stash\[", body)) for body in bodies)
                print(
                    f"  {entry['name']}: {len(bodies)} parts, {counts[c_name]:.0f} instructions per call, "
                    f"{traffic} stash stores and loads written"
                )


def measure(label: str, ctx) -> None:
    with tempfile.TemporaryDirectory(prefix="symdyn-compile-time-") as tmp:
        builds, whole = {}, render(ctx, True)
        for layout in ("whole", "parts"):
            files = whole if layout == "whole" else render(ctx, False)
            builds[layout] = build(ctx, files, Path(tmp, layout))
        outputs = [
            subprocess.run([str(b["folder"] / "driver")], capture_output=True, text=True, check=True).stdout
            for b in builds.values()
        ]
        same = "bit for bit equal" if outputs[0] == outputs[1] else "DIFFERENT OUTPUTS"
        probe = run_driver(builds["parts"]["folder"], 100)
        reps = max(10, int(2e7 / max(1.0, max(probe.values()))))  # about 20 ms per function and round
        times: dict[str, dict[str, list[float]]] = {layout: {} for layout in builds}
        for _ in range(ROUNDS):
            for layout, b in builds.items():
                for fn, ns in run_driver(b["folder"], reps).items():
                    times[layout].setdefault(fn, []).append(ns)
        print(f"\n{label}: {ctx.robot.n} joints, largest function {largest(whole)}; outputs {same}")
        print(
            f"{'layout':<7} {'KB of C':>8} {'files':>5} {'gcc -O2 CPU s':>13} "
            f"{'wall s (all at once)':>21}  slowest file"
        )
        for layout, b in builds.items():
            slow = max(b["serial"], key=b["serial"].get)
            print(
                f"{layout:<7} {b['size'] / 1000:8.0f} {b['files']:5d} {sum(b['serial'].values()):13.1f} "
                f"{b['parallel']:21.1f}  {slow} {b['serial'][slow]:.1f} s"
            )
        names = [e["c_name"] for e in function_table(ctx)]
        counts = {layout: instructions(b["folder"], names) for layout, b in builds.items()}
        print(
            f"{'function':<28} {'whole ns':>10} {'parts ns':>10} {'ratio':>6}"
            f" {'whole instr':>12} {'parts instr':>12} {'ratio':>6}"
        )
        for fn, c_name in zip(times["whole"], names, strict=True):
            a, b = (statistics.median(times[layout][fn]) for layout in ("whole", "parts"))
            line = f"{fn:<28} {a:10.0f} {b:10.0f} {b / a:6.3f}"
            if counts["whole"] and counts["parts"]:
                x, y = counts["whole"][c_name], counts["parts"][c_name]
                line += f" {x:12.0f} {y:12.0f} {y / x:6.3f}"
            print(line)


def two_cores(seconds: list[float]) -> float:
    """The wall seconds of files taking `seconds` of one core each when built as symdyn.compile
    builds them on an idle machine with two cores: the largest first, each on the first free core."""
    cores = [0.0, 0.0]
    for cpu in sorted(seconds, reverse=True):
        cores[cores.index(min(cores))] += cpu
    return max(cores)


def measure_menagerie(folder: Path) -> None:
    """`symdyn generate` (a fresh process, floating base, the default functions) and the -O2
    compile of every file it writes (CPU seconds of the compiler, one file after the other), for
    each model of MENAGERIE found in `folder`."""
    from symdyn.progress import quiet

    quiet()
    if not folder.is_dir():
        print(f"\nmenagerie: {folder} is not a folder: skipped (a copy of mujoco_menagerie, meshes optional)")
        return
    print("\nMuJoCo Menagerie, the default functions on a floating base (joints: besides the free flyer)")
    print(
        f"{'robot':<12} {'joints':>6} {'generate CPU s':>14} {'wall s':>6} {'KB of C':>8} "
        f"{'files':>5} {'cut':>4} {'gcc -O2 CPU s':>13} {'slowest file s':>14} {'2 idle cores s':>14}"
    )
    flags = [f for f in COMPILE_FLAGS if f != "-shared"] + list(arch_flags())
    for name, path in MENAGERIE.items():
        model = folder / path
        if not model.is_file():
            print(f"{name:<12} not in the folder ({path}): skipped")
            continue
        with tempfile.TemporaryDirectory(prefix="symdyn-menagerie-") as tmp:
            cmd = [sys.executable, "-m", "symdyn.cli", "generate", str(model), "--floating", "--target", "c"]
            generate = cpu_seconds([*cmd, "--out", tmp, "--quiet"], Path(tmp), check=False)
            if isinstance(generate, str):  # e.g. a model whose meshes give its inertia, without its meshes
                print(f"{name:<12} {generate}")
                continue
            c_files = sorted(p.name for p in Path(tmp).iterdir() if p.suffix == ".c")
            text = "".join(Path(tmp, n).read_text(encoding="utf-8") for n in c_files)
            header = "".join(p.read_text(encoding="utf-8") for p in Path(tmp).glob("*_dynamics.h"))
            ndof = int(re.search(r"#define \w+_NDOF (\d+)", header).group(1))
            cpu = [cpu_seconds(["gcc", *flags, "-c", n, "-o", n[:-2] + ".o"], Path(tmp))[0] for n in c_files]
            cut = len(set(re.findall(r"^static \w+ void (\w+)_part\d+\(", text, re.M)))
            print(
                f"{name:<12} {ndof - 6:6d} {generate[0]:14.1f} {generate[1]:6.0f} "
                f"{len(text.encode()) / 1000:8.0f} {len(c_files):5d} {cut:4d} {sum(cpu):13.1f} "
                f"{max(cpu):14.1f} {two_cores(cpu):14.1f}"
            )
            sys.stdout.flush()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("robots", nargs="*", default=list(DEFAULT))
    parser.add_argument("--floating", action="store_true", help="URDFs on a free flyer (default robots: yes)")
    parser.add_argument("--parts-only", action="store_true", help="compile only the current layout")
    parser.add_argument("--menagerie", type=Path, metavar="DIR", help="MuJoCo Menagerie's humanoids in DIR")
    args = parser.parse_args()
    print(f"{os.cpu_count()} cores, load averages {os.getloadavg()} (a shared machine: compare ratios)")
    if args.menagerie is not None:
        measure_menagerie(args.menagerie)
        if not args.robots or args.robots == list(DEFAULT):
            return
    for name in args.robots:
        floating = args.floating or name in DEFAULT
        ctx = context(load(name, floating))
        label = f"{Path(name).stem}{' floating' if floating and name in URDFS else ''}"
        (measure_parts if args.parts_only else measure)(label, ctx)
        sys.stdout.flush()


if __name__ == "__main__":
    main()
