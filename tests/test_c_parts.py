"""The C target's layout for large robots (symdyn.codegen.c.parts): functions cut into parts, the
functions spread over several files, and the parallel build of symdyn.compile.

The thresholds are lowered so that Roger's arm takes the large robots' path: every function in
parts, the functions in several files. The split C compiles under the strict flags (-Werror) and
gives bit for bit the numbers of the single file (same operations in the same order), which agree
with the numeric oracle.
"""

from __future__ import annotations

import ctypes
import dataclasses
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
from cbuild import STRICT_FLAGS, CDynamics, compile_shared, source_files, write_files
from robots import example_context, random_params, random_state
from timebound import within

import symdyn.rnea as oracle
from symdyn.apps.compilation import build
from symdyn.codegen.c import parts
from symdyn.codegen.c import target as c_target
from symdyn.codegen.c.both import render_both
from symdyn.errors import SymdynError

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc")


def _split(monkeypatch, ctx, statements: int, file_bytes: int, render=c_target.render) -> dict[str, str]:
    """The C of `ctx` rendered (by `render`) with parts of at most `statements` statements and files
    of about `file_bytes` bytes of statements."""
    with monkeypatch.context() as m:
        m.setattr(parts, "PART_ABOVE", statements)
        m.setattr(parts, "LIVE_ABOVE", 0)
        m.setattr(parts, "PART_STATEMENTS", statements)
        m.setattr(parts, "SPLIT_BYTES", file_bytes)
        return render(ctx)


@pytest.fixture(scope="module")
def roger():
    """Roger's arm's C in one file, and cut into parts of 12 statements in files of about 4 KB."""
    ctx = example_context("roger_arm")
    mp = pytest.MonkeyPatch()
    try:
        return ctx, c_target.render(ctx), _split(mp, ctx, 12, 4_000)
    finally:
        mp.undo()


def test_the_file_set_is_deterministic_and_each_function_is_defined_once(roger, monkeypatch):
    ctx, single, split = roger
    assert sorted(single) == ["CMakeLists.txt", "roger_arm_dynamics.c", "roger_arm_dynamics.h"]
    names = sorted(split)
    count = len(names) - 3
    assert count >= 3 and names == sorted(
        [
            "CMakeLists.txt",
            "roger_arm_dynamics.h",
            "roger_arm_dynamics_parts.h",
            "roger_arm_dynamics.c",
            *(f"roger_arm_dynamics_{k}.c" for k in range(2, count + 1)),
        ]
    )
    assert split == _split(monkeypatch, ctx, 12, 4_000)  # same names, same bytes
    assert split["roger_arm_dynamics.h"] == single["roger_arm_dynamics.h"]  # the contract is unchanged
    sources = re.findall(r"roger_arm_dynamics[_0-9]*\.c", split["CMakeLists.txt"])
    assert sorted(set(sources)) == [n for n in names if n.endswith(".c")]  # the library builds every file
    for spec in ctx.functions:
        c_name = f"roger_arm_{spec.name}"
        defined = [n for n in names if n.endswith(".c") and re.search(rf"^void {c_name}\(", split[n], re.M)]
        assert len(defined) == 1, c_name
    cut = [s.name for s in ctx.functions if any(f"void roger_arm_{s.name}_part2(" in split[n] for n in names)]
    assert {"inverse_dynamics", "mass_matrix", "coriolis_matrix", "forward_dynamics"} <= set(cut)
    # each part defined once; those outside their function's file hidden and declared in the
    # internal header, which the files defining or calling them include
    header = split["roger_arm_dynamics_parts.h"]
    spread = set()
    for name in (spec.name for spec in ctx.functions):
        where = {}
        for n in names:
            for linkage, part in re.findall(
                rf"^(\w+) roger_arm_NOINLINE void (roger_arm_{name}_part\d+)\(", split[n], re.M
            ):
                assert part not in where, part
                where[part] = (n, linkage)
        home = next(
            n for n in names if n.endswith(".c") and re.search(rf"^void roger_arm_{name}\(", split[n], re.M)
        )
        for part, (n, linkage) in where.items():
            declared = f"roger_arm_HIDDEN void {part}(" in header
            assert (linkage, declared) == (("static", False) if n == home else ("roger_arm_HIDDEN", True)), (
                part
            )
            if n != home:
                spread.add(name)
                assert '#include "roger_arm_dynamics_parts.h"' in split[n]
        assert '#include "roger_arm_dynamics_parts.h"' in split[home] or name not in spread
    assert len(spread) >= 2


def test_split_c_gives_the_single_files_numbers_and_the_oracles(roger, tmp_path):
    ctx, single, split = roger
    libs = []
    for label, files in (("single", single), ("split", split)):
        out = tmp_path / label
        write_files(files, out)
        lib = compile_shared(source_files(files, out, "roger_arm"), out / "lib.so", "gcc", "-O0")
        libs.append(CDynamics(lib, "roger_arm", ctx.robot.n, len(ctx.dynamics.params)))
    # the parts in another file than their function are not exported (hidden visibility)
    exported = ctypes.CDLL(str(tmp_path / "split" / "lib.so"))
    hidden = re.findall(r"roger_arm_HIDDEN void (\w+)\(", split["roger_arm_dynamics_parts.h"])
    assert hidden and not any(hasattr(exported, name) for name in hidden)
    assert hasattr(exported, "roger_arm_mass_matrix")
    robot, rng = ctx.robot, np.random.default_rng(35)
    for _ in range(5):
        q, qd, qdd = random_state(robot, rng)
        p = random_params(robot, rng)
        values = [
            {
                "tau": lib.inverse_dynamics(q, qd, qdd, p),
                "M": lib.mass_matrix(q, p),
                "C": lib.coriolis_matrix(q, qd, p),
                "V": lib.coriolis(q, qd, p),
                "G": lib.gravity(q, p),
                "F": lib.friction(qd, p),
                "qdd": lib.forward_dynamics(q, qd, lib.inverse_dynamics(q, qd, qdd, p), p),
            }
            for lib in libs
        ]
        for key, value in values[0].items():
            assert np.array_equal(values[1][key], value), key
        params = dict(zip(map(str, ctx.dynamics.params), p, strict=True))
        np.testing.assert_allclose(
            values[1]["tau"], oracle.rnea(robot, q, qd, qdd, params), rtol=1e-9, atol=1e-9
        )
        np.testing.assert_allclose(values[1]["M"], oracle.mass_matrix(robot, q, params), rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(values[1]["qdd"], qdd, rtol=1e-7, atol=1e-7)


@pytest.mark.parametrize("arch", [(), ("-mavx2", "-mfma")], ids=["libm", "avx2"])
def test_split_c_compiles_strict_at_O2(roger, tmp_path, arch):
    """-O2 finds the warnings that need flow analysis; with AVX2 the parts read the sines of the
    function's arrays, without it they call sin and cos. With AVX2 and FMA the split build still
    gives the single file's numbers to the bit: gcc's SLP vectorizer, which fused a*b + c into
    vfmaddsub in Talos' parts despite -ffp-contract=off, is off in the parts (templates/c/parts.c.j2)."""
    ctx, single, files = roger
    assert 'optimize("no-tree-slp-vectorize")' in files["roger_arm_dynamics.c"]
    libs = []
    for label, layout in (("split", files), ("single", single))[: 1 + bool(arch)]:
        write_files(layout, tmp_path / label)
        with within(60):
            lib = compile_shared(
                source_files(layout, tmp_path / label, "roger_arm"),
                tmp_path / label / "lib.so",
                "gcc",
                "-O2",
                STRICT_FLAGS,
                (*arch, "-ffp-contract=off", "-Wmissing-prototypes", "-Wmissing-declarations"),
            )
        libs.append(CDynamics(lib, "roger_arm", ctx.robot.n, len(ctx.dynamics.params)))
    if arch:
        rng = np.random.default_rng(5)
        q, qd, _ = random_state(ctx.robot, rng)
        p = random_params(ctx.robot, rng)
        split, whole = (
            np.concatenate([lib.mass_matrix(q, p).ravel(), lib.coriolis_matrix(q, qd, p).ravel()])
            for lib in libs
        )
        assert np.array_equal(split, whole)


def test_spread_parts_build_in_both_precisions_freestanding_and_with_cmake(roger, tmp_path, monkeypatch):
    """Parts spread over several files in the other layouts: `--precision both` (the float
    functions cut as the double ones, into the same files) compiled in either precision, and
    --freestanding. Every file compiles under the strict flags with -Wmissing-prototypes (the
    internal header declares the parts) and each build gives its single file's numbers to the
    bit; the CMakeLists.txt builds the files of both precisions into a library a program links."""
    ctx, _, split = roger
    free_ctx = dataclasses.replace(ctx, freestanding=True)
    both = _split(monkeypatch, ctx, 12, 4_000, render_both)
    free = _split(monkeypatch, free_ctx, 12, 4_000)
    assert "roger_arm_dynamics_parts.h" in both and "roger_arm_dynamics_parts.h" in free
    # the double branch of each file is the double split file (built by the tests above)
    assert both.keys() == split.keys()
    assert all(split[name] in both[name] for name in split if name.endswith((".c", ".h")))
    layouts = {
        "both float": (both, "float", ("-Droger_arm_USE_FLOAT",)),
        "float": (c_target.render(dataclasses.replace(ctx, precision="float")), "float", ()),
        "free split": (free, "double", ()),
        "free": (c_target.render(free_ctx), "double", ()),
    }
    strict = (*STRICT_FLAGS, "-Wmissing-prototypes", "-Wmissing-declarations")
    rng = np.random.default_rng(41)
    q, qd, _ = random_state(ctx.robot, rng)
    p = random_params(ctx.robot, rng)
    values = {}
    for label, (files, precision, defines) in layouts.items():
        out = tmp_path / label.replace(" ", "_")
        write_files(files, out)
        with within(60):
            lib = compile_shared(
                source_files(files, out, "roger_arm"), out / "lib.so", "gcc", "-O0", strict, defines
            )
        c = CDynamics(lib, "roger_arm", ctx.robot.n, len(ctx.dynamics.params), precision)
        values[label] = np.concatenate([c.mass_matrix(q, p).ravel(), c.coriolis_matrix(q, qd, p).ravel()])
    for cut, whole in (("both float", "float"), ("free split", "free")):
        assert values[cut].dtype == values[whole].dtype and np.array_equal(values[cut], values[whole]), cut
    if shutil.which("cmake") is None:
        return
    project = tmp_path / "cmake"
    write_files(both, project / "dyn")
    main = '#include "roger_arm_dynamics.h"\nint main(void)\n{\n    roger_arm_real q[2] = {0.3f, -0.7f};\n'
    main += "    roger_arm_real p[5] = {9.81f, 1, 1, 1, 1}, M[4];\n"
    main += "    roger_arm_mass_matrix(q, p, M);\n    return !(M[0] > 0);\n}\n"
    (project / "main.c").write_text(main)
    (project / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.13)\nproject(app C)\nadd_subdirectory(dyn)\n"
        "add_executable(app main.c)\ntarget_link_libraries(app PRIVATE roger_arm_dynamics)\n"
    )
    flags = "-DCMAKE_C_FLAGS=" + " ".join((*STRICT_FLAGS[1:], "-Wmissing-prototypes"))
    build_dir = project / "build"
    with within(60):
        configure = ["cmake", "-S", str(project), "-B", str(build_dir), flags, "-Droger_arm_PRECISION=float"]
        subprocess.run(configure, check=True, capture_output=True)
        subprocess.run(["cmake", "--build", str(build_dir), "-j", "2"], check=True, capture_output=True)
        subprocess.run([str(build_dir / "app")], check=True)


def test_stash_slots_are_reused_once_read():
    """x0 is read by parts 2 and 3, x1 by part 2 only: x1's slot is free after part 2, so x3,
    computed in part 2 (after x1 is loaded there), takes a new one; a save in part 3 would reuse it."""
    body = [
        ("let", "x0", "q1"),
        ("let", "x1", "2*x0"),
        ("let", "x2", "x1 + x0"),
        ("let", "x3", "x2*q1"),
        ("store", "tau[0]", "x3 + x0"),
        ("store", "tau[1]", "x0"),
    ]
    with pytest.MonkeyPatch.context() as m:
        m.setattr(parts, "PART_ABOVE", 2)
        m.setattr(parts, "LIVE_ABOVE", 0)
        m.setattr(parts, "PART_STATEMENTS", 2)
        split = parts.split_body(body, [("q1", "q", "0")], "f", ["q", "tau"])
    first, second, third = split["parts"]
    assert [p["name"] for p in split["parts"]] == ["f_part1", "f_part2", "f_part3"]
    assert first["body"] == [body[0], ("save", "0", "x0"), body[1], ("save", "1", "x1")]
    assert second["loads"] == [("x0", 0), ("x1", 1)]
    assert second["body"] == [("load", "x0", "0"), ("load", "x1", "1"), body[2], body[3], ("save", "2", "x3")]
    assert third["loads"] == [("x0", 0), ("x3", 2)] and split["slots"] == 3
    assert first["unused"] == ["tau"] and third["unused"] == ["q"] and third["reads"] == []


def test_only_functions_with_a_large_live_span_are_cut(monkeypatch):
    """A chain (each temporary read by the next only: one alive at a time) stays whole however long;
    the same number of statements all read by the last (every temporary alive to the end) is cut."""
    monkeypatch.setattr(parts, "PART_ABOVE", 10)
    monkeypatch.setattr(parts, "PART_STATEMENTS", 10)
    monkeypatch.setattr(parts, "LIVE_ABOVE", 1000)
    chain = [("let", "x0", "q1"), *(("let", f"x{k}", f"2*x{k - 1}") for k in range(1, 100))]
    chain.append(("store", "tau[0]", "x99"))
    assert parts._alive(chain) == [0, *[1] * 100, 0]  # x(k-1) alive across the cut before statement k
    assert parts.split_body(chain, [("q1", "q", "0")], "f", ["q", "tau"]) is None
    wide = [
        *(("let", f"x{k}", f"{k}*q1") for k in range(100)),
        ("store", "tau[0]", "+".join(f"x{k}" for k in range(100))),
    ]
    assert sum(parts._alive(wide)) == sum(range(101)) > 1000
    split = parts.split_body(wide, [("q1", "q", "0")], "f", ["q", "tau"])
    assert split is not None and len(split["parts"]) == 11


def test_file_groups_balance_and_keep_small_robots_in_one_file():
    assert parts.file_groups([10, 20, 30]) == [[0, 1, 2]]
    size = parts.SPLIT_BYTES
    assert parts.file_groups([size // 2, size // 2, size // 2, size // 2]) == [[0, 1], [2, 3]]
    assert parts.file_groups([size // 2, size, size // 2, size // 4]) == [[0], [1], [2, 3]]
    assert parts.file_groups([3 * size]) == [[0]]  # one function stays whole (its parts are in it)


def test_a_parallel_build_stops_at_its_first_error_in_one_line(tmp_path, monkeypatch):
    """Files built at most os.cpu_count() at once; a failing file is named, with its first error,
    on one line."""
    compiler = build.find_compiler()
    if compiler is None:
        pytest.skip("no C compiler")
    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    good = {f"a{k}.c": f"int f{k}(void) {{ return {k}; }}\n" for k in range(3)}
    assert build.compile_library(compiler, good, tmp_path / "lib.so").is_file()
    bad = {**good, "b.c": "int g(void) { return undeclared; }\n"}
    with within(60), pytest.raises(SymdynError) as info:
        build.compile_library(compiler, bad, tmp_path / "bad.so")
    message = str(info.value)
    assert "\n" not in message and "b.c, one of 4 files" in message and "undeclared" in message
