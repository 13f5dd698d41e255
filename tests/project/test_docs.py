"""The documentation is tested: every scenario and every command shown in README.md and
docs/guide.md works as shown.

* Every fenced ```toml block is a whole scenario file: it is loaded and planned (all its queries,
  with its own ``[planner]`` defaults, the time capped at a couple of seconds), and it must come
  out as its ``expect`` says. A block that is deliberately a fragment starts with the line
  ``# fragment`` and is only parsed as TOML.
* Every line of a fenced ```sh / ```bash / ```shell block is a command: it is run as written, in
  a temporary folder holding links to ``scenarios/`` and ``scripts/`` (so the files it writes go
  there, never into the repository), with ``cspace`` and ``python`` of the running interpreter.
  Lines of one block run in order in the same folder (a block may plan the file it generated).
  The exit status must be 0, or the one a trailing ``# exit N`` comment states. Only the parts
  listed in ``SKIP`` (and, unless ``CSPACE_DOCS_SLOW=1``, in ``SLOW``) are not run, each with its
  reason; a command that is neither run nor listed fails the test, so new sections are picked up.
  Usage synopses (``cspace plan SCENARIO [--planner NAME] ...``) are ```text blocks, not commands.
* Every ```python block of the README that starts with ``import`` (a whole program, not a listing
  of signatures) runs from the repository root (docs/guide.md's run in tests/project/test_guide.py).
* Every inline `cspace ...` / `python scripts/... ` span names a subcommand or script that exists,
  and each option it shows is one its ``--help`` offers.
"""
from __future__ import annotations

import functools
import os
import re
import shlex
import subprocess
import sys

import pytest

from conftest import ROOT

DOCS = ("README.md", os.path.join("docs", "guide.md"))
PLAN_TIME_CAP = 2.0  # seconds per query for the toml blocks expected unsolvable (they use it all)
# A block expected solvable is planned by a planner that stops at its first solution (RRTConnect,
# the exact planners): its time is what the machine needs, so the cap is generous, for loaded
# machines; no answer may depend on the machine's speed.
SOLVABLE_TIME_CAP = 30.0
FIRST_SOLUTION_PLANNERS = ("RRTConnect", "exact")

# Parts of commands that are not run (the exact text of the part, as in the docs).
SKIP = {
    "pip install -e .": "installs packages: the suite runs inside the installed environment",
    'pip install -e ".[test]"': "installs packages: the suite runs inside the installed environment",
    "pytest": "the suite itself (it would run this test again)",
    "pytest -m slow": "the suite's slow pass (it would run this test again)",
    "python scripts/make_figures.py": "regenerates every figure into docs/ (~1 min, writes into the repository); "
                                      "tests/project/test_guide.py and test_make_figures.py cover its parts",
    "python scripts/make_benchmarks_page.py": "runs every bench script (minutes, writes docs/benchmarks.md); "
                                              "the bench scripts' quick modes have their own tests",
}
# Commands that are run only with CSPACE_DOCS_SLOW=1 (the default suite stays fast); measured on
# the 2-core development machine.
SLOW = {
    "cspace stability --plot stability.png": "the whole catalogue, ~16 s; tests/planning/test_stability.py runs the "
                                             "same catalogue through the same entry point",
    "cspace bench scenarios/bug_trap.toml --planners RRTConnect,RRTstar --times 0.03,0.1,0.3 --runs 5 "
    "--out bench_out": "30 runs in separate processes, ~18 s",
    "cspace plan scenarios/ompl/circles.toml --all-queries --time 1 --json circ.json":
        "100 queries, ~9 s; tests/planning/test_plan_api.py plans the same queries at the same budget",
}
RUN_SLOW = os.environ.get("CSPACE_DOCS_SLOW") == "1"


def _read(doc: str) -> str:
    with open(os.path.join(ROOT, doc), encoding="utf-8") as fh:
        return fh.read()


def _blocks(lang: str) -> list[tuple[str, int, str]]:
    """(doc, line number, body) of every fenced block of that language in DOCS."""
    out = []
    for doc in DOCS:
        text = _read(doc)
        for m in re.finditer(r"^```(%s)[ \t]*\n(.*?)^```" % lang, text, re.S | re.M):
            out.append((doc, text.count("\n", 0, m.start()) + 1, m.group(2)))
    return out


def _commands(body: str) -> list[tuple[str, int]]:
    """The commands of a shell block: (command without its comment, expected exit status)."""
    cmds = []
    for line in body.replace("\\\n", " ").splitlines():
        m = re.search(r"#\s*exit (\d+)\s*$", line)
        code = re.sub(r"(^|\s)#.*$", "", line).strip()
        if code:
            cmds.append((code, int(m.group(1)) if m else 0))
    return cmds


def _parts(command: str) -> list[str]:
    """The parts of ``a && b``."""
    return [p.strip() for p in command.split("&&")]


TOML_BLOCKS = _blocks("toml")
SH_BLOCKS = _blocks("sh|bash|shell")


def test_the_docs_show_scenarios_and_commands():
    # The extraction finds what is there (a regex gone wrong would make the tests below vacuous).
    assert len(TOML_BLOCKS) >= 2
    assert sum(len(_commands(b)) for _, _, b in SH_BLOCKS) >= 15
    assert ("cspace plan scenarios/narrow_closed.toml", 1) in [c for _, _, b in SH_BLOCKS for c in _commands(b)]


@pytest.mark.parametrize("doc, line, body", TOML_BLOCKS, ids=[f"{d}:{n}" for d, n, _ in TOML_BLOCKS])
def test_toml_block_loads_and_plans(doc, line, body, tmp_path):
    if body.startswith("# fragment"):
        try:
            import tomllib
        except ModuleNotFoundError:  # Python 3.10
            import tomli as tomllib
        tomllib.loads(body)
        return
    import planners
    from cspace.io.load import load_scenario

    path = tmp_path / "block.toml"
    path.write_text(body, encoding="utf-8")
    sc = load_scenario(str(path))  # a fault raises ScenarioError naming the field
    # A rotating robot's first plan also builds its angle slabs (lazily, inside the budget).
    name = sc.planner.get("name", "RRTConnect")
    if sc.expect == "unsolvable":
        budget = min(sc.planner.get("time", 1.0), PLAN_TIME_CAP)
    else:
        assert name in FIRST_SOLUTION_PLANNERS, f"{doc}:{line}: {name} would use the whole budget"
        budget = SOLVABLE_TIME_CAP
    res = planners.plan(str(path), time=budget, all_queries=True)
    solved = [q.solved for q in res.queries]
    assert len(solved) == len(sc.all_queries()) >= 1
    if sc.expect == "unsolvable":
        assert not any(solved), f"{doc}:{line}: a query of an unsolvable scene was solved"
    else:
        assert all(solved), f"{doc}:{line}: queries not solved: {[i for i, s in enumerate(solved) if not s]}"


def _run_block(doc: str, line: int, body: str, tmp_path) -> list[str]:
    """Run every command of one block in tmp_path; return the parts skipped, with reasons."""
    for name in ("scenarios", "scripts"):
        os.symlink(os.path.join(ROOT, name), tmp_path / name)
    env = dict(os.environ, PATH=os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", ""),
               MPLBACKEND="Agg")
    skipped = []
    for command, want in _commands(body):
        for part in _parts(command):
            reason = SKIP.get(part) or (None if RUN_SLOW else SLOW.get(part))
            if reason:
                skipped.append(f"{part!r}: {reason}")
                continue
            argv = shlex.split(part)
            run_env = dict(env)
            while argv and re.fullmatch(r"[A-Z_][A-Z0-9_]*=.*", argv[0]):  # VAR=value prefixes
                k, _, v = argv.pop(0).partition("=")
                run_env[k] = v
            if argv[0] == "python":
                argv[0] = sys.executable
            proc = subprocess.run(argv, cwd=tmp_path, env=run_env, capture_output=True, text=True, timeout=300)
            assert proc.returncode == want, (
                f"{doc}:{line}: `{part}` exited {proc.returncode}, the docs say {want}\n"
                f"stdout: {proc.stdout[-2000:]}\nstderr: {proc.stderr[-2000:]}")
            if want == 2:  # bad input: one line on stderr, no traceback
                assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("error: "), proc.stderr
    written = [e.name + ("/" if e.is_dir() else "") for e in os.scandir(tmp_path) if e.name not in ("scenarios", "scripts")]
    kept = not_ignored(written)
    assert kept == [], f"{doc}:{line}: run from the repository root, these outputs would show in git status: {kept}"
    return skipped


def not_ignored(paths: list[str]) -> list[str]:
    """Which of these paths (relative to the repository root) its .gitignore does not ignore
    ([] where git or the repository's history is absent: nothing to judge against; .git is a folder, or a
    worktree's file)."""
    if not paths or not os.path.exists(os.path.join(ROOT, ".git")):
        return []
    try:
        proc = subprocess.run(["git", "-C", ROOT, "check-ignore", "--no-index", "--stdin"], input="\n".join(paths),
                              capture_output=True, text=True, timeout=60)
    except OSError:
        return []
    ignored = set(proc.stdout.split("\n"))
    return [p for p in paths if p not in ignored]


def test_the_ignore_check_tells_outputs_from_sources():
    if not os.path.exists(os.path.join(ROOT, ".git")):
        pytest.skip("not a git checkout")
    assert not_ignored(["path.png", "bench_out/", "plan.json"]) == []
    assert not_ignored(["scenarios/basic.toml", "cspace/__init__.py"]) == ["scenarios/basic.toml", "cspace/__init__.py"]


@pytest.mark.parametrize("doc, line, body", SH_BLOCKS, ids=[f"{d}:{n}" for d, n, _ in SH_BLOCKS])
@pytest.mark.slow
def test_shell_block_runs_as_written(doc, line, body, tmp_path):
    skipped = _run_block(doc, line, body, tmp_path)
    if skipped and len(skipped) == sum(len(_parts(c)) for c, _ in _commands(body)):
        pytest.skip("; ".join(skipped))


def test_skip_lists_name_only_commands_the_docs_show():
    # A stale entry would silently skip nothing, and hide that the docs changed.
    shown = {p for _, _, b in SH_BLOCKS for c, _ in _commands(b) for p in _parts(c)}
    assert set(SKIP) | set(SLOW) <= shown, sorted((set(SKIP) | set(SLOW)) - shown)


INLINE = sorted({(doc, m) for doc in DOCS
                 for m in re.findall(r"`((?:cspace |python scripts/)[^`]*)`", _read(doc))})


@pytest.mark.parametrize("doc, span", INLINE, ids=[f"{d}:{s}" for d, s in INLINE])
def test_inline_command_names_exist(doc, span):
    from planners.cli import COMMANDS

    words = span.split()
    if words[0] == "cspace":
        if words[1] == "COMMAND":  # the guide's placeholder
            return
        assert words[1] in COMMANDS, f"{doc}: `{span}`: no command {words[1]!r}"
        argv = [sys.executable, "-c", "from planners.cli import main; import sys; sys.exit(main())", words[1]]
    else:
        script = os.path.join(ROOT, words[1])
        assert os.path.isfile(script), f"{doc}: `{span}`: no such script"
        argv = [sys.executable, script]
    options = [w for w in words[2:] if w.startswith("--")]
    if options:
        offered = _help(tuple(argv))
        for opt in options:
            assert re.search(r"(?<![\w-])%s(?![\w-])" % re.escape(opt), offered), f"{doc}: `{span}`: {opt}?"


@functools.lru_cache(maxsize=None)
def _help(argv: tuple) -> str:
    proc = subprocess.run(list(argv) + ["--help"], capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


README_PYTHON = [(d, n, b) for d, n, b in _blocks("python") if d == "README.md" and b.startswith("import")]


@pytest.mark.parametrize("doc, line, body", README_PYTHON, ids=[f"{d}:{n}" for d, n, _ in README_PYTHON])
def test_readme_python_programs_run(doc, line, body, monkeypatch):
    monkeypatch.chdir(ROOT)
    env: dict = {}
    exec(compile(body, f"{doc}:{line}", "exec"), env)
    assert env["res"].solved and env["cs"].is_free([(1, 1), (2.7, 3)]).tolist() == [True, False]


def test_the_guide_quotes_bench_import_as_the_benchmarks_page_shows_it():
    # The guide's sentence on bench_import once quoted figures 5-40x off those its page showed:
    # every number it quotes is the page's (which make_benchmarks_page writes from a run).
    with open(os.path.join(ROOT, "docs", "guide.md"), encoding="utf-8") as fh:
        guide = fh.read()
    with open(os.path.join(ROOT, "docs", "benchmarks.md"), encoding="utf-8") as fh:
        page = fh.read()
    section = page[page.index("## bench_import"):]
    section = section[:section.index("\n## ", 3)]
    col = {name: float(re.search(re.escape(name) + r"\s+([\d.]+)", section).group(1))
           for name in ("import default (2 cells)", "import exact (0)", "C-space build default (2 cells)",
                        "C-space build exact (0)")}
    default = re.search(r"default \(2 cells\): \d+ obstacles, (\d+) vertices, (\d+) C-obstacle pieces; .*?\((\d+) vertices",
                        section)
    exact_pieces = re.search(r"exact \(0\): \d+ obstacles, \d+ vertices, (\d+) C-obstacle pieces", section).group(1)
    sentence = guide[guide.index("`python scripts/bench_import.py` times"):]
    sentence = " ".join(sentence[:sentence.index("The targets")].split())
    want = (f"the default import takes {col['import default (2 cells)']:.3f} s and leaves {default.group(1)} vertices of "
            f"the staircase's {default.group(3)}, whose C-space (a 0.25 m disk robot, {default.group(2)} pieces) builds "
            f"in {col['C-space build default (2 cells)']:.3f} s; the exact staircase imports in "
            f"{col['import exact (0)']:.3f} s and builds in {col['C-space build exact (0)']:.3f} s ({exact_pieces} pieces)")
    assert want in sentence, f"the guide says:\n{sentence}\nthe page's run says:\n{want}"
