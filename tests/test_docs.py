"""The documentation site keeps its promises: it builds, its navigation is complete, and its examples run.

1. `mkdocs build --strict` (mkdocs.yml, docs/) succeeds: no broken link, no missing API reference.
2. mkdocs.yml's nav lists every page of docs/ and every nav entry exists.
3. Every block a page marks for testing runs (docs/layout.md, "Runnable documentation"):
   `<!-- test: file PATH -->` writes the block to PATH, `<!-- test: run -->` runs a python or
   shell block (`<!-- test: run exit=N -->` expects exit status N), `<!-- test: output -->`
   holds the expected output of the run block before it (a line `...` stands for any lines).
   The blocks of one page run in order, in one Python process of their own, in a temporary folder
   holding a copy of examples/, with `symdyn` and `python` on PATH meaning this source tree; that
   process and the blocks' `symdyn` and `python` commands are forked from a warm interpreter
   (tests/warm_python.py), which imported SymPy and symdyn once.
4. The embedded C example (examples/embedded_control/main.c) compiles with the strict flags of
   the C contract and tracks its reference as the linear error equation predicts, and the
   CasADi tutorial's optimal trajectory satisfies the dynamics of the numeric oracle.
5. docs/command-line.md names exactly the flags of the command's parser.
"""

from __future__ import annotations

import contextlib
import csv
import difflib
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import warm_python
import yaml

import symdyn
from symdyn.cli.main import build_parser

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
MARKER = re.compile(r"<!-- test: (run|output|file)((?: [^ ]+)*) -->\Z")
FENCE = re.compile(r"(`{3,})\s*([\w-]*)")
SHELLS = ("sh", "bash", "console", "shell")
PAGE_TIMEOUT = 120  # seconds for all blocks of one page (they take a few seconds each)


# --------------------------------------------------------------------------- reading the pages


@dataclass
class Block:
    """One marked fenced block of a page."""

    page: str
    line: int  # 1-based line of the block's opening fence
    kind: str  # "python", "shell" or "file"
    code: str
    path: str = ""  # file blocks: where to write
    exit_status: int = 0  # run blocks: the expected exit status
    expected: str | None = None  # run blocks: the expected output, if the page shows it


def _fenced(lines: list[str], start: int, page: str) -> tuple[str, str, int]:
    """(info, text, index after the closing fence) of the fenced block opening at lines[start]."""
    m = FENCE.match(lines[start])
    assert m, f"{page}:{start + 1}: a test marker must be followed by a fenced block"
    ticks, info = m.groups()
    end = start + 1
    while end < len(lines) and lines[end].strip() != ticks:
        end += 1
    assert end < len(lines), f"{page}:{start + 1}: unclosed fenced block"
    return info, "\n".join(lines[start + 1 : end]) + "\n", end + 1


def marked_blocks(path: Path) -> list[Block]:
    """The blocks of one page that carry a test marker, in page order."""
    page = str(path.relative_to(DOCS))
    lines = path.read_text(encoding="utf-8").splitlines()
    blocks: list[Block] = []
    last_run: Block | None = None
    k = 0
    while k < len(lines):
        m = MARKER.match(lines[k].strip())
        if not m:
            k += 1
            continue
        what, args = m.group(1), m.group(2).split()
        info, text, after = _fenced(lines, k + 1, page)
        where = f"{page}:{k + 2}"
        if what == "file":
            assert len(args) == 1, f"{where}: write as <!-- test: file PATH -->"
            blocks.append(Block(page, k + 2, "file", text, path=args[0]))
        elif what == "run":
            kind = "python" if info == "python" else "shell" if info in SHELLS else None
            assert kind, f"{where}: a run block must be python or one of {', '.join(SHELLS)}, not {info!r}"
            options = dict(a.split("=", 1) for a in args)
            assert set(options) <= {"exit"}, f"{where}: unknown option in {args}"
            last_run = Block(page, k + 2, kind, text, exit_status=int(options.get("exit", 0)))
            assert kind == "shell" or last_run.exit_status == 0, f"{where}: exit= applies to shell blocks"
            blocks.append(last_run)
        else:
            assert last_run is not None and last_run.expected is None, (
                f"{where}: an output block must follow its own run block"
            )
            last_run.expected = text
        k = after
    return blocks


def pages() -> list[Path]:
    return sorted(DOCS.rglob("*.md"))


def pages_with_blocks() -> list[Path]:
    return [p for p in pages() if marked_blocks(p)]


# --------------------------------------------------------------------------- running the blocks

#: Runs a page's blocks in order in one process: python blocks share one namespace, shell
#: blocks run in bash. Reads the blocks (JSON) from argv[1], writes the results to argv[2].
WORKER = textwrap.dedent(
    """
    import contextlib, io, json, subprocess, sys, traceback
    blocks = json.load(open(sys.argv[1]))
    results, namespace = [], {"__name__": "__main__"}
    for b in blocks:
        if b["kind"] == "file":
            with open(b["path"], "w") as f:
                f.write(b["code"])
            results.append({"output": "", "status": 0})
        elif b["kind"] == "shell":
            p = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", b["code"]],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            results.append({"output": p.stdout, "status": p.returncode})
        else:
            out = io.StringIO()
            status = 0
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
                try:
                    exec(compile(b["code"], b["where"], "exec"), namespace)
                except BaseException:
                    traceback.print_exc()
                    status = 1
            results.append({"output": out.getvalue(), "status": status})
        if results[-1]["status"] != b["exit_status"]:
            break
    json.dump(results, open(sys.argv[2], "w"))
    """
)


#: the client end of the warm interpreter (tests/warm_python.py)
WARM = Path(__file__).resolve().parent / "warm_python.py"


def _through_warm(arguments: str) -> str:
    """The command line of `python ARGUMENTS` through the warm interpreter's client."""
    return f'exec "{sys.executable}" -S "{WARM}" client "{sys.executable}" {arguments}'


def environment(shims: Path) -> dict[str, str]:
    """The environment of the blocks: this source tree's symdyn, unbuffered, `symdyn` on PATH.

    `symdyn` and `python` are served by a warm interpreter once `warm_interpreter` has started
    one (tests/warm_python.py: a forked child of a process that imported SymPy and symdyn once),
    else run by this one."""
    shims.mkdir(parents=True, exist_ok=True)
    for name, command in (("symdyn", '-m symdyn.cli "$@"'), ("python", '"$@"'), ("python3", '"$@"')):
        script = shims / name
        script.write_text(f"#!/bin/sh\n{_through_warm(command)}\n")
        script.chmod(0o755)
    env = dict(os.environ)
    env.update(
        PATH=f"{shims}{os.pathsep}{env.get('PATH', '')}",
        PYTHONPATH=os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])]),
        PYTHONUNBUFFERED="1",
        PYTHONHASHSEED="0",
        NO_MKDOCS_2_WARNING="1",
        COLUMNS="100",
    )
    return env


@contextlib.contextmanager
def warm_interpreter(env: dict[str, str], folder: Path):
    """A warm interpreter (tests/warm_python.py) serving the commands run with `env`, which names
    it ($SYMDYN_WARM_PYTHON) while the context lasts."""
    address = folder / "warm.sock"
    server = subprocess.Popen(
        [sys.executable, str(WARM), "serve", str(address)],
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert server.stdout.readline().strip() == "ready", "the warm interpreter did not start"
        env[warm_python.ADDRESS_ENV] = str(address)
        yield env
    finally:
        env.pop(warm_python.ADDRESS_ENV, None)
        server.terminate()  # it waits for its children: their CPU time counts as this process's
        try:
            server.wait(timeout=60)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
        server.stdout.close()


def workspace(tmp_path: Path) -> Path:
    """A temporary folder with a copy of examples/, where a page's blocks run."""
    work = tmp_path / "work"
    shutil.copytree(ROOT / "examples", work / "examples", ignore=shutil.ignore_patterns("__pycache__"))
    return work


def run_blocks(blocks: list[Block], work: Path, env: dict[str, str]) -> list[dict]:
    spec = [{**b.__dict__, "where": f"docs/{b.page}:{b.line}"} for b in blocks]
    todo, done = work.parent / "blocks.json", work.parent / "results.json"
    todo.write_text(json.dumps(spec))
    proc = subprocess.run(
        [sys.executable, "-S", str(WARM), "client", sys.executable, "-c", WORKER, str(todo), str(done)],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=PAGE_TIMEOUT,
    )
    assert proc.returncode == 0, f"the block runner failed:\n{proc.stdout}{proc.stderr}"
    return json.loads(done.read_text())


def _normalise(text: str) -> list[str]:
    return [line.rstrip() for line in text.strip("\n").splitlines()]


def output_matches(expected: str, actual: str) -> bool:
    """Whether `actual` is `expected`, line by line (trailing spaces ignored; `...` = any lines)."""
    any_lines = r"(?:[^\n]*\n)*?"
    pattern = "".join(
        any_lines if line.strip() == "..." else re.escape(line) + r"\n" for line in _normalise(expected)
    )
    return re.fullmatch(pattern, "".join(line + "\n" for line in _normalise(actual))) is not None


@pytest.fixture(scope="module")
def block_env(tmp_path_factory) -> dict[str, str]:
    """The blocks' environment, with a warm interpreter for their commands (`warm_interpreter`)."""
    folder = tmp_path_factory.mktemp("bin")
    with warm_interpreter(environment(folder), folder) as env:
        yield env


def check_results(blocks: list[Block], results: list[dict]) -> None:
    """Each block ended with its expected exit status and printed what its page shows."""
    for block, result in zip(blocks, results, strict=False):
        where = f"docs/{block.page}:{block.line}"
        assert result["status"] == block.exit_status, (
            f"{where}: exit status {result['status']}, expected {block.exit_status}\n"
            f"{block.code}\n--- output:\n{result['output']}"
        )
        if block.expected is not None and not output_matches(block.expected, result["output"]):
            diff = "\n".join(
                difflib.unified_diff(
                    _normalise(block.expected), _normalise(result["output"]), "page", "actual", lineterm=""
                )
            )
            pytest.fail(f"{where}: the output differs from the page\n{block.code}\n{diff}")
    assert len(results) == len(blocks), f"docs/{blocks[0].page}: not every block ran"


#: Pages whose blocks a dedicated test below runs (and checks further).
OWN_TEST = ("tutorials/casadi-opti.md",)


@pytest.mark.parametrize(
    "page",
    [p for p in pages_with_blocks() if str(p.relative_to(DOCS)) not in OWN_TEST],
    ids=lambda p: str(p.relative_to(DOCS)),
)
def test_marked_blocks_run(page: Path, tmp_path: Path, block_env: dict[str, str]):
    blocks = marked_blocks(page)
    shell = "\n".join(b.code for b in blocks if b.kind == "shell")
    missing = sorted({c for c in re.findall(r"^\s*(gcc|clang)\b", shell, re.M) if shutil.which(c) is None})
    if missing:
        pytest.skip(f"docs/{page.relative_to(DOCS)} compiles C with {', '.join(missing)}: not installed")
    check_results(blocks, run_blocks(blocks, workspace(tmp_path), block_env))


def test_markers_are_well_formed():
    """Every marker is followed by its block; a page that shows output also runs the command."""
    for page in pages():
        text = page.read_text(encoding="utf-8")
        for k, line in enumerate(text.splitlines(), 1):
            if line.startswith("<!--") and "test" in line:
                assert MARKER.match(line.strip()), f"{page.relative_to(DOCS)}:{k}: malformed marker {line!r}"
        marked_blocks(page)  # asserts the structure


def test_output_matching():
    """The matcher itself: exact lines, trailing spaces ignored, `...` for any lines."""
    assert output_matches("a\nb\n", "a  \nb")
    assert output_matches("a\n...\nd\n", "a\nb\nc\nd\n")
    assert output_matches("a\n...\nd\n", "a\nd\n")
    assert not output_matches("a\nb\n", "a\nc\n")
    assert not output_matches("a\n", "a\nb\n")


# --------------------------------------------------------------------------- the site


def _nav_pages(nav) -> list[str]:
    out: list[str] = []
    for item in nav:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        out += _nav_pages(value) if isinstance(value, list) else [value]
    return out


def test_nav_lists_every_page_and_every_entry_exists():
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    nav = _nav_pages(config["nav"])
    assert len(nav) == len(set(nav)), "a page is listed twice in mkdocs.yml's nav"
    on_disk = {str(p.relative_to(DOCS)) for p in pages()}
    assert sorted(set(nav) - on_disk) == [], "nav entries without a page"
    assert sorted(on_disk - set(nav)) == [], "pages missing from mkdocs.yml's nav"


def test_site_builds_strictly(tmp_path: Path, block_env: dict[str, str]):
    if importlib.util.find_spec("mkdocs") is None:
        pytest.skip("mkdocs is not installed (pip install mkdocs mkdocs-material 'mkdocstrings[python]')")
    site = tmp_path / "site"
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", ROOT / "mkdocs.yml", "-d", site],
        cwd=ROOT,
        env=block_env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, f"mkdocs build --strict failed:\n{proc.stdout}{proc.stderr}"
    assert (site / "images" / "slide24.png").read_bytes() == (ROOT / "examples" / "slide24.png").read_bytes()
    api = (site / "python-api" / "index.html").read_text(encoding="utf-8")
    for name in ("symdyn.derive", "symdyn.Dynamics", "symdyn.generate", "symdyn.SymdynError"):
        assert name in api, f"the API reference lacks {name}"
    assert re.search(r'<a href="\.\./floating-base/">docs/floating-base\.md</a>', api), (
        "the API reference's page paths are not links"
    )
    internal = re.findall(r'id="(symdyn\.[\w.]*NumericModel\.(?:R0|p0|axis))"', api)
    assert not internal, f"the API reference lists internal attributes: {internal}"
    assert offline_problems(site) == []
    assert unrendered_math(site) == []
    for page in MATH_PAGES:
        html = (site / page.removesuffix(".md").removesuffix("index") / "index.html").read_text(
            encoding="utf-8"
        )
        assert 'class="arithmatex"' in html, f"{page}: no typeset math"
        for asset in KATEX_ASSETS:
            assert re.search(rf'(src|href)="(\.\./)*{re.escape(asset)}"', html), (
                f"{page} does not load {asset}"
            )


# --------------------------------------------------------------------------- math, offline

#: The vendored KaTeX (docs/assets/katex/) and the script that typesets pymdownx.arithmatex's output.
KATEX_ASSETS = (
    "assets/katex/katex.min.css",
    "assets/katex/katex.min.js",
    "assets/katex/contrib/auto-render.min.js",
    "assets/katex-init.js",
)
#: Pages whose equations are typeset (a sample: every page with an equation has them).
MATH_PAGES = (
    "index.md",
    "lecture.md",
    "generated-code.md",
    "tutorials/embedded-c.md",
    "tutorials/operational-space.md",
)
EXTERNAL = re.compile(
    r"<(?:script|link|img|iframe)\b[^>]*\b(?:src|href)=[\"'](?:https?:)?//[^\"']*[\"'][^>]*>"
    r"|@import\s+(?:url\()?[\"']?(?:https?:)?//|url\([\"']?(?:https?:)?//",
    re.I,
)


def offline_problems(site: Path) -> list[str]:
    """What a built site would load from outside (scripts, style sheets, fonts, pictures; plain
    links to other sites are fine), and the vendored KaTeX fonts it lacks."""
    problems = []
    for path in sorted(site.rglob("*")):
        if path.suffix in (".html", ".css", ".js") and path.is_file():
            text = path.read_text(encoding="utf-8", errors="replace")
            if path.suffix == ".js":  # scripts: only the loaders of style sheets and scripts
                text = "\n".join(re.findall(r"@import[^;]*|url\([^)]*\)", text))
            problems += [f"{path.relative_to(site)}: {m.group(0)[:100]}" for m in EXTERNAL.finditer(text)]
    css = site / "assets" / "katex" / "katex.min.css"
    if not css.is_file():
        return [*problems, "assets/katex/katex.min.css is missing"]
    fonts = re.findall(r"url\((fonts/[^)]+\.woff2)\)", css.read_text(encoding="utf-8"))
    problems += [f"assets/katex/{f} is missing" for f in fonts if not (css.parent / f).is_file()]
    return problems + ([] if fonts else ["katex.min.css names no woff2 font"])


#: What arithmatex leaves as it is, and so the reader sees raw: a display or inline delimiter
#: outside the elements arithmatex made, code and scripts (a display indented wrongly in a list).
RAW_MATH = re.compile(r"\$\$|\\\(|\\\[")
NOT_PROSE = re.compile(
    r"<(pre|code|script|style)\b.*?</\1>|<(div|span) class=\"arithmatex\">.*?</\2>", re.S | re.I
)


def unrendered_math(site: Path) -> list[str]:
    """Every place of the built site's pages where LaTeX math is shown raw instead of typeset."""
    problems = []
    for path in sorted(site.rglob("*.html")):
        text = NOT_PROSE.sub("", path.read_text(encoding="utf-8"))
        problems += [
            f"{path.relative_to(site)}: {text[max(0, m.start() - 60) : m.end() + 40]!r}"
            for m in RAW_MATH.finditer(text)
        ]
    return problems


def test_the_raw_math_check_finds_what_it_looks_for(tmp_path: Path):
    """unrendered_math itself: a display left in a paragraph and a raw inline formula are found,
    typeset math and code are not."""
    (tmp_path / "a.html").write_text(
        '<p>$$\n\\kappa = 1\n$$</p><div class="arithmatex">\\[x\\]</div>'
        '<span class="arithmatex">\\(y\\)</span><code>$$ \\(z\\)</code><p>and \\(w\\)</p>'
    )
    found = unrendered_math(tmp_path)
    assert len(found) == 3 and all(f.startswith("a.html: ") for f in found)


def test_the_offline_check_finds_what_it_looks_for(tmp_path: Path):
    """offline_problems itself, on a small site: a CDN script, style sheet and font are found."""
    (tmp_path / "assets" / "katex" / "fonts").mkdir(parents=True)
    (tmp_path / "assets" / "katex" / "katex.min.css").write_text("a{src:url(fonts/K.woff2)}")
    (tmp_path / "assets" / "katex" / "fonts" / "K.woff2").write_bytes(b"")
    page = '<a href="https://example.org">a link</a><script src="assets/x.js"></script>'
    (tmp_path / "index.html").write_text(page)
    assert offline_problems(tmp_path) == []
    (tmp_path / "cdn.html").write_text('<script defer src="https://cdn.example/katex.js"></script>')
    (tmp_path / "style.html").write_text('<link rel="stylesheet" href="//fonts.example/css">')
    (tmp_path / "font.css").write_text("@font-face{src:url(https://fonts.example/a.woff2)}")
    (tmp_path / "assets" / "katex" / "fonts" / "K.woff2").unlink()
    found = offline_problems(tmp_path)
    assert [p.split(":")[0] for p in found] == [
        "cdn.html",
        "font.css",
        "style.html",
        "assets/katex/fonts/K.woff2 is missing",
    ]


# --------------------------------------------------------------------------- the command line page


def _parser_flags() -> dict[str, set[str]]:
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    flags = {"": {o for a in parser._actions for o in a.option_strings if o.startswith("--")}}
    for name, p in sub.choices.items():
        flags[name] = {o for a in p._actions for o in a.option_strings if o.startswith("--")}
    return flags


def test_command_line_page_names_every_flag_and_no_other():
    """docs/command-line.md: the section of `symdyn` and of each subcommand names exactly its parser's
    --flags, and no flag on the page is unknown."""
    text = (DOCS / "command-line.md").read_text(encoding="utf-8")
    sections = {s.split("\n", 1)[0].strip(): s for s in re.split(r"^## ", text, flags=re.MULTILINE)[1:]}
    every = set()
    for name, flags in _parser_flags().items():
        title = f"`symdyn {name}`" if name else "`symdyn`"
        assert title in sections, f"docs/command-line.md needs a section '## {title}'"
        named = set(re.findall(r"`(--[a-z][a-z0-9-]*)", sections[title])) - {"--help"}
        assert named == flags - {"--help"}, f"{title}: page {sorted(named)}, parser {sorted(flags)}"
        every |= flags
    unknown = set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", text)) - every
    assert not unknown, f"docs/command-line.md names flags no parser has: {sorted(unknown)}"


def test_named_tests_exist():
    """Every test a page names (`tests/test_x.py::test_y`, or `::test_z` after it) is defined there."""
    for page in pages():
        current = None
        for m in re.finditer(r"(tests/test_\w+\.py)?::(test_\w+)", page.read_text(encoding="utf-8")):
            current = m.group(1) or current
            assert current, f"{page.relative_to(DOCS)}: '::{m.group(2)}' names no test file before it"
            source = (ROOT / current).read_text(encoding="utf-8")
            assert re.search(rf"^def {m.group(2)}\(", source, re.MULTILINE), (
                f"{page.relative_to(DOCS)}: {current}::{m.group(2)} does not exist"
            )


def test_layout_page_names_every_subpackage():
    """docs/layout.md gives each floor of the package (every subpackage of symdyn/) its row."""
    text = (DOCS / "layout.md").read_text(encoding="utf-8")
    floors = {p.parent.name for p in (ROOT / "symdyn").glob("*/__init__.py")}
    named = set(re.findall(r"^\| `symdyn/(\w+)` \|", text, re.MULTILINE))
    assert floors <= named, f"docs/layout.md lacks {sorted(floors - named)}"
    assert all((ROOT / "symdyn" / n).exists() or (ROOT / "symdyn" / f"{n}.py").exists() for n in named)


# --------------------------------------------------------------------------- the tutorials' programs


def test_embedded_controller_tracks_as_the_error_equation_predicts(tmp_path: Path):
    """examples/embedded_control/main.c under computed-torque control of Roger's arm.

    With an exact model the joint error obeys e'' + Kd e' + Kp e = 0; the program starts with
    e(0) = (0.1, -0.1) rad, de/dt(0) = 0 and Kp = 100, Kd = 20 (critically damped, omega = 10
    rad/s), so e_i(t) = e_i(0) (1 + omega t) exp(-omega t): 0.040601 rad at t = 0.2 s and
    2.9e-13 rad at t = 3 s. The program integrates the plant with the generated forward dynamics
    (RK4, h = 1 ms: a global error near 1e-12 rad); the bound 1e-9 rad (plus the rounding of the
    7 printed digits) leaves a margin of hundreds, while a controller without V leaves about
    1e-3 rad at t = 3 s and one without G about 0.1 rad (measured by editing the law).
    """
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("no C compiler (gcc)")
    out = tmp_path / "gen"
    symdyn.generate(ROOT / "examples" / "roger_arm_values.yaml", targets=("c",), out_dir=out)
    program = tmp_path / "controller"
    build = [gcc, "-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", f"-I{out}"]
    sources = [ROOT / "examples" / "embedded_control" / "main.c", out / "roger_arm_values_dynamics.c"]
    proc = subprocess.run([*build, "-o", program, *sources, "-lm"], capture_output=True, text=True)
    assert proc.returncode == 0 and not proc.stderr, proc.stderr
    run = subprocess.run([str(program)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stdout + run.stderr
    rows = {}
    for line in run.stdout.splitlines():
        m = re.match(r"t = ([0-9.]+) s: error ([-0-9.e+]+) ([-0-9.e+]+) rad", line)
        if m:
            rows[float(m.group(1))] = np.array([float(m.group(2)), float(m.group(3))])
    assert set(rows) >= {0.0, 0.2, 1.0, 3.0}, run.stdout
    omega, e0 = 10.0, np.array([0.1, -0.1])
    for t, e in rows.items():
        predicted = e0 * (1 + omega * t) * np.exp(-omega * t)
        printed = 5e-7 * np.abs(predicted)  # the program prints 7 significant digits
        assert np.all(np.abs(e - predicted) < 1e-9 + printed), (t, e, predicted)
    m = re.search(r"inverse_dynamics agrees with M a \+ V \+ G \+ F to ([0-9.e+-]+)", run.stdout)
    assert m and float(m.group(1)) < 1e-12, run.stdout


def _rk4(f, x, u, h):
    k1 = f(x, u)
    k2 = f(x + h / 2 * k1, u)
    k3 = f(x + h / 2 * k2, u)
    k4 = f(x + h * k3, u)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def test_casadi_tutorial_solution_satisfies_the_oracles_dynamics(tmp_path: Path, block_env: dict[str, str]):
    """The Opti tutorial's trajectory, re-integrated interval by interval with symdyn.rnea.

    The tutorial (docs/tutorials/casadi-opti.md) writes its solution to trajectory.csv. Here each
    shooting interval is integrated again with the numeric oracle's forward dynamics (the same
    RK4 step, the same held torque): the end states must meet the next knot to within IPOPT's
    tolerances, the torques must respect the bound and the boundary states must hold.
    """
    pytest.importorskip("casadi")
    blocks = marked_blocks(DOCS / "tutorials" / "casadi-opti.md")
    work = workspace(tmp_path)
    check_results(blocks, run_blocks(blocks, work, block_env))
    with open(work / "trajectory.csv", newline="") as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    t = np.array([r["t"] for r in rows])
    x = np.array([[r["q1"], r["q2"], r["qd1"], r["qd2"]] for r in rows])
    tau = np.array([[r["tau1"], r["tau2"]] for r in rows])
    robot = symdyn.load_robot(ROOT / "examples" / "roger_arm_values.yaml")

    def f(state, u):
        return np.concatenate([state[2:], symdyn.rnea.forward_dynamics(robot, state[:2], state[2:], u)])

    h = t[1] - t[0]
    assert len(t) == 41 and np.allclose(np.diff(t), 0.025, rtol=0, atol=1e-15)
    for k in range(len(t) - 1):
        defect = np.abs(_rk4(f, x[k], tau[k], h) - x[k + 1]).max()
        assert defect < 1e-8, (k, defect)
    assert np.abs(tau[:-1]).max() <= 0.5 + 1e-8
    assert np.abs(x[:, 2:]).max() <= 10.0 + 1e-8
    assert np.abs(x[0] - [0, 0, 0, 0]).max() < 1e-8
    assert np.abs(x[-1] - [np.pi / 2, 0, 0, 0]).max() < 1e-8
