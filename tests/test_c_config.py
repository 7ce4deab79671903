"""The C backend's config (symdyn.codegen.c.config): types per precision and names that collide with nothing.

The reserved words are checked against the compiler's own <math.h> (what gcc's
preprocessor defines and declares under C99 and under POSIX), and a robot whose
parameters carry every reserved name a robot file accepts is generated, compiled
with the strict flags and compared with the numeric oracle symdyn.rnea.
"""

from __future__ import annotations

import importlib
import re
import shutil
import subprocess

import numpy as np
import pytest
from cbuild import CDynamics, compile_shared, header_macros, write_files

import symdyn.codegen
from symdyn.codegen import c as c_backend
from symdyn.codegen.c.config import C_RESERVED, TEMPORARY, CConfig
from symdyn.errors import SymdynError
from symdyn.model.expressions import C_KEYWORDS, RESERVED_NAMES
from symdyn.parsers import robot_from_data

oracle = importlib.import_module("symdyn.rnea")
needs_gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")


def test_config_per_precision():
    double, single = CConfig("double"), CConfig("float")
    assert (double.real, double.literal_suffix, double.math("sin")) == ("double", "", "sin")
    assert (single.real, single.literal_suffix, single.math("sin")) == ("float", "f", "sinf")
    assert single.math("fabs") == "fabsf" and single.math("pow") == "powf"
    with pytest.raises(SymdynError, match="unknown precision 'half'"):
        CConfig("half")


def _math_h(*defines: str) -> tuple[set[str], set[str]]:
    """(macros, declared functions) of <math.h> under -std=c99 and `defines`, per gcc."""

    def preprocess(*flags: str) -> str:
        command = ["gcc", "-std=c99", *defines, "-E", *flags, "-x", "c", "-"]
        return subprocess.run(
            command, input="#include <math.h>\n", capture_output=True, text=True, check=True
        ).stdout

    macros = {
        line.split()[1].split("(")[0] for line in preprocess("-dM").splitlines() if line.startswith("#define")
    }
    functions = set()
    for declaration in " ".join(preprocess("-P").split()).split(";"):
        if declaration.lstrip().startswith("extern"):
            functions.update(re.findall(r"\b([A-Za-z][A-Za-z0-9_]*) \(", declaration))
    public = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
    return {m for m in macros if public.match(m)}, {f for f in functions if public.match(f)}


@needs_gcc
@pytest.mark.parametrize("defines", [(), ("-D_DEFAULT_SOURCE",)], ids=["c99", "posix"])
def test_reserved_names_cover_math_h(defines):
    """Everything <math.h> defines or declares without a leading underscore is reserved."""
    macros, functions = _math_h(*defines)
    assert {"NAN", "INFINITY", "sin", "sinf"} <= macros | functions  # the probe works
    assert sorted(macros - C_RESERVED) == []
    assert sorted(functions - C_RESERVED) == []


def robot_with_parameters(names: list[str]):
    """One revolute link whose mass, inertia and friction are sums of the given parameter names
    (each field below the robot file's expression length limit)."""
    fields = [names[k::3] for k in range(3)]
    data = {
        "name": "reserved",
        "convention": "standard",
        "gravity": [0, -9.81, 0],
        "links": [
            {
                "name": "one",
                "joint": "revolute",
                "a": 0.5,
                "alpha": 0,
                "d": 0,
                "theta": 0,
                "mass": " + ".join(fields[0]),
                "com": [0.2, 0, 0],
                "inertia": {"izz": " + ".join(fields[1])},
                "friction": {"viscous": " + ".join(fields[2])},
            }
        ],
    }
    return robot_from_data(data, source="reserved.yaml")


@needs_gcc
def test_every_reserved_name_as_a_parameter(tmp_path):
    """Parameters named like keywords-that-are-allowed, <math.h> names, macros, argument names and
    temporaries get locals that collide with none of them; the C compiles and agrees with RNEA."""
    accepted = sorted(
        n
        for n in C_RESERVED
        if n not in C_KEYWORDS
        and n not in RESERVED_NAMES
        and not n.startswith("_")
        and not re.fullmatch(r"(q|qd|qdd|tau)[0-9]+", n)
    )
    names = [*accepted, "x0", "x0_", "x12", "reserved_NDOF", "reserved_P_M"]
    robot = robot_with_parameters(names)
    ctx = symdyn.codegen.context(robot)
    assert sorted(str(p) for p in ctx.dynamics.params) == sorted(names)
    c_names = c_backend.c_names(ctx)
    locals_ = [c_names.locals[p] for p in ctx.dynamics.params]
    macros = {m for m, _ in c_names.param_macros} | {a for a, _ in c_names.aliases}
    assert len(set(locals_)) == len(locals_)
    for local in locals_:
        assert local not in C_RESERVED and local not in macros and not TEMPORARY.match(local), local
    files = c_backend.render(ctx)
    write_files(files, tmp_path)
    index = header_macros(files["reserved_dynamics.h"])
    assert [int(index[f"reserved_P_{p}"]) for p in ctx.dynamics.params] == list(range(len(names)))
    library = compile_shared([tmp_path / "reserved_dynamics.c"], tmp_path / "libreserved.so")
    lib = CDynamics(library, "reserved", 1, len(names))
    rng = np.random.default_rng(11)
    p = rng.uniform(0.01, 0.02, len(names))
    values = {str(s): v for s, v in zip(ctx.dynamics.params, p, strict=True)}
    for q, qd in rng.uniform(-2, 2, (5, 2)):
        scale = 1.0 + abs(oracle.gravity_torque(robot, [q], values)[0])
        assert abs(lib.gravity([q], p)[0] - oracle.gravity_torque(robot, [q], values)[0]) <= 1e-12 * scale
        assert lib.friction([qd], p)[0] == pytest.approx(
            oracle.friction_torque(robot, [qd], values)[0], rel=1e-12
        )
        assert lib.mass_matrix([q], p)[0, 0] == pytest.approx(
            oracle.mass_matrix(robot, [q], values)[0, 0], rel=1e-12
        )
