"""Typeset LaTeX fragments with pdflatex (or latexmk) in a folder: the tests of the LaTeX outputs.

    done = typeset(tmp_path, {"robot_dynamics.tex": text})   # \\input inside an article with amsmath
    assert done.returncode == 0, done.stdout[-3000:]

`TEX` is the command found (None: the tests that need it skip). `shell_escape` lets the document run
\\write18, so that a test can show that none of the text it typesets does.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from collections.abc import Mapping
from pathlib import Path

__all__ = ["TEX", "ESCAPES", "commands", "uncommented", "typeset"]

TEX = shutil.which("pdflatex") or shutil.which("latexmk")
#: the escapes of LaTeX's special characters symdyn writes in a user's text (symdyn.model.names)
ESCAPES = frozenset({"\\_", "\\#", "\\%", "\\&", "\\{", "\\}", "\\$"})


def uncommented(tex: str) -> str:
    """`tex` without its comments (from an unescaped % to the end of its line)."""
    return re.sub(r"(?<!\\)%.*", "", tex)


def commands(tex: str) -> set[str]:
    """Every control sequence TeX reads in `tex` (its comments left out): a backslash and letters,
    or a backslash and one character."""
    return set(re.findall(r"\\(?:[A-Za-z]+|.)", uncommented(tex), re.S))


def typeset(
    folder: Path, fragments: Mapping[str, str], shell_escape: bool = False
) -> subprocess.CompletedProcess:
    """Write `fragments` (file name -> LaTeX) into `folder` and typeset doc.tex, an article with
    amsmath that \\inputs each, in nonstop mode halting on the first error."""
    for name, text in fragments.items():
        (folder / name).write_text(text, encoding="utf-8")
    inputs = "".join(f"\\input{{{name}}}\n" for name in fragments)
    (folder / "doc.tex").write_text(
        f"\\documentclass{{article}}\n\\usepackage{{amsmath}}\n\\begin{{document}}\n{inputs}\\end{{document}}\n"
    )
    escape = ["-shell-escape" if shell_escape else "-no-shell-escape"]
    if shutil.which("pdflatex"):
        cmd = ["pdflatex", *escape, "-interaction=nonstopmode", "-halt-on-error", "doc.tex"]
    else:
        cmd = ["latexmk", "-pdf", *escape, "-interaction=nonstopmode", "-halt-on-error", "doc.tex"]
    return subprocess.run(cmd, cwd=folder, capture_output=True, text=True, timeout=120)
