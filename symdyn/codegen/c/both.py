"""One set of C files for both precisions, chosen when compiled (`symdyn generate --precision both`).

Each file the C target writes (NAME_dynamics.h, NAME_dynamics.c, ...) holds the float file and the
double file whole, one branch each of `#ifdef NAME_USE_FLOAT` (templates/c/both.j2), so that either
is the plain C of its precision (readable, and -Wdouble-promotion and -Wconversion clean as each
is) and a build system picks the precision with one definition: the CMakeLists.txt's
`NAME_PRECISION` (float or double, a cache variable) adds `-DNAME_USE_FLOAT` to the library and to
whatever links it (docs/embedded.md). The header defines `NAME_real` as the chosen type for the
caller's arrays. The two renderings put the same functions in the same files (the double's layout),
and the preprocessor keeps one: a compiler sees what `--precision float` or `double` writes.
"""

from __future__ import annotations

import dataclasses

from ..render import RenderContext, environment, header_lines
from .target import CMAKE_FILE, file_groups_of, render

__all__ = ["render_both", "use_float_macro"]


def use_float_macro(name: str) -> str:
    """The definition that selects float: NAME_USE_FLOAT."""
    return f"{name}_USE_FLOAT"


def render_both(ctx: RenderContext) -> dict[str, str]:
    """The C target's files for `ctx` (any precision: it is replaced) with both precisions in each."""
    double = dataclasses.replace(ctx, precision="double")
    single = dataclasses.replace(ctx, precision="float")
    groups = file_groups_of(double)
    files = {"double": render(double, groups), "float": render(single, groups)}
    assert files["double"].keys() == files["float"].keys()
    env = environment()
    lines = header_lines(dataclasses.replace(ctx, precision="float or double"))
    macro = use_float_macro(ctx.name)
    both: dict[str, str] = {}
    for name in files["double"]:
        if name == CMAKE_FILE:
            continue
        both[name] = env.get_template("c/both.j2").render(
            header_lines=lines,
            name=ctx.name,
            macro=macro,
            header=name.endswith("_dynamics.h"),  # not NAME_dynamics_parts.h
            float_text=files["float"][name],
            double_text=files["double"][name],
        )
    sources = sorted(name for name in both if name.endswith(".c"))
    both[CMAKE_FILE] = env.get_template("c/CMakeLists.txt.j2").render(
        header_lines=lines,
        name=ctx.name,
        real="float or double",
        sources=sources,
        freestanding=ctx.freestanding,
        switch=macro,
    )
    return both
