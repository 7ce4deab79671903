"""A robot's cache entry for `symdyn.compile`: what it depends on, and how it is built.

The entry's key holds the robot's content and the options (`build_options`: the method, the compiler,
its flags, the machine); building it (`entry_builder`) derives the robot, generates its C, its
NumPy module and the batch runtime (symdyn.codegen) and compiles the generated C with the stepping
loop and the CSV writer into a shared library (symdyn.apps.compilation.build), keeping the generated
C's object files; the batch wrappers' sources (NAME_batch*.c) wait in the entry until a batch call
needs them (symdyn.apps.compilation.batch_library links them with those objects). The entry's
metadata names its functions and files for `CompiledDynamics` (symdyn.apps.compilation.compile).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

__all__ = ["build_options", "entry_builder", "loaded_files"]


def build_options(method: str, precision: str = "double") -> dict:
    """What a library depends on besides the robot: the method, the compiler, its flags (the
    optimisation level of $SYMDYN_OPT, the -march of $SYMDYN_MARCH), and with -march=native the
    machine (symdyn.apps.compilation.build)."""
    from .build import arch_flags, compile_flags, find_compiler, machine_fingerprint, opt_flag

    compiler = find_compiler()
    arch = list(arch_flags()) if compiler else []
    opt = opt_flag() if compiler else None
    return {
        "method": method,
        "precision": precision,
        "compiler": compiler,
        "flags": [*compile_flags(opt), *arch] if compiler else None,
        "arch": arch,
        "opt": opt,
        "machine": machine_fingerprint() if "-march=native" in arch else None,
    }


def entry_builder(robot, method: str, options: dict, frames: dict | None = None) -> Callable[[Path], dict]:
    """build(folder): derive, generate (C, NumPy, runtime), compile; return the entry's metadata.

    `frames`: None (the functions of symdyn.codegen.context's default groups) or the keywords
    functions, frames and task_axes of the frame functions' own entry (CompiledDynamics.frame_functions).
    """

    def build(folder: Path) -> dict:
        from ...codegen import c as c_target
        from ...codegen import context
        from ...codegen import python as numpy_target
        from ...codegen.c.runtime import (
            CSV_SOURCE,
            STEP_SOURCE,
            function_table,
            render_runtime,
            solve_loops_entry,
        )
        from .build import compile_library, library_suffix

        ctx = context(robot, options["precision"], method, **(frames or {}))
        generated, runtime = c_target.render(ctx), render_runtime(ctx)
        files = {**generated, **runtime, **numpy_target.render(ctx)}
        for name, text in files.items():
            (folder / name).write_text(text, encoding="utf-8")
        batch = sorted(set(runtime) - {STEP_SOURCE, CSV_SOURCE})  # NAME_batch*.c, built on first use
        kept = sorted(name for name in generated if name.endswith(".c"))
        library = None
        if options["compiler"]:
            library = f"lib{ctx.name}{library_suffix()}"
            compile_library(
                options["compiler"],
                {k: v for k, v in files.items() if k.endswith((".c", ".h")) and k not in batch},
                folder / library,
                options["arch"],
                keep=kept,
                opt=options["opt"],
            )
        return {
            "robot": {
                "name": ctx.name,
                "n": ctx.robot.n,
                "params": [str(s) for s in ctx.dynamics.params],
                "frames": list(ctx.robot.frame_names),
            },
            "functions": function_table(ctx),
            "solve_loops": solve_loops_entry(ctx),
            "numpy": numpy_target.file_name(ctx.name),
            "library": library,
            "batch": {  # what batch_library compiles and links into the batch library, on first use
                "sources": batch,
                "objects": [name[:-2] + ".o" for name in kept] if library else [],
                "library": f"lib{ctx.name}_batch{library_suffix()}",
                "compiler": options["compiler"],  # those of the key, as the scalar library's
                "arch": options["arch"],
                "opt": options["opt"],
            },
        }

    return build


def loaded_files(meta: dict) -> list[str]:
    """The file of an entry a CompiledDynamics loads at once: its library, or the NumPy module without one."""
    return [meta["library"] or meta["numpy"]]
