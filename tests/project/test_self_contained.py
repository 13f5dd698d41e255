"""Nothing in the repository reads a path outside it: a user's clone has nothing beside it.

Every Python file of the repository is parsed; a string that is a path with a ``..`` component,
a name of the development machine's shared folders, or ``dirname(ROOT)`` (the folder above the
repository) is reported with its file and line. The fresh-clone run (README's test command in a
clone with no ``../shared`` beside it) is the end-to-end check; this test keeps it from rotting.
"""
from __future__ import annotations

import ast
import os
import re

from conftest import ROOT

UP = re.compile(r"(^|[/\\])\.\.[/\\]")  # a literal path that climbs: "../x", "a/../../x"
OUTSIDE_NAMES = ("peer-scenarios", "/work/", "shared/notes")


def _python_files() -> list[str]:
    out = []
    for top in ("cspace", "planners", "scripts", "tests"):
        for d, _, files in os.walk(os.path.join(ROOT, top)):
            out += [os.path.join(d, f) for f in files if f.endswith(".py")]
    return sorted(out)


def _is_root(node) -> bool:
    return isinstance(node, ast.Name) and node.id == "ROOT"


def outside_references(source: str) -> list[tuple[int, str]]:
    """(line, what) of each place in ``source`` that points outside the repository.

    Flagged: a literal path that climbs (``"../shared"``), a name of the development
    machine's folders, ``dirname(ROOT)`` and ``join(ROOT, "..")`` (the folder above the
    repository). A file's own ``join(HERE, "..")`` (tests/ up to the root) stays inside.

    >>> outside_references('p = os.path.join(ROOT, "..", "x")')
    [(1, 'join(ROOT, "..")')]
    >>> outside_references('p = os.path.dirname(ROOT)\\nq = "a..b"\\nr = os.path.join(HERE, "..", "scenarios")')
    [(1, 'dirname(ROOT)')]
    >>> outside_references('def f():\\n    "writes d/../x"\\n    return "../x"')
    [(3, "'../x'")]
    """
    found = []
    tree = ast.parse(source)
    in_fstring = {id(v) for n in ast.walk(tree) if isinstance(n, ast.JoinedStr) for v in n.values}
    # a docstring describes paths ("d/../x is the same file"), it reads none
    in_fstring |= {id(n.body[0].value) for n in ast.walk(tree)
                   if isinstance(n, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and n.body
                   and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in in_fstring:
            if UP.search(node.value) or any(n in node.value for n in OUTSIDE_NAMES):
                found.append((node.lineno, repr(node.value)))
        elif isinstance(node, ast.Call) and isinstance(node.func, (ast.Attribute, ast.Name)) and node.args:
            name = getattr(node.func, "attr", getattr(node.func, "id", None))
            if name == "dirname" and _is_root(node.args[0]):
                found.append((node.lineno, "dirname(ROOT)"))
            elif name == "join" and _is_root(node.args[0]) and any(
                    isinstance(a, ast.Constant) and a.value == ".." for a in node.args[1:]):
                found.append((node.lineno, 'join(ROOT, "..")'))
    return found


def test_the_checker_sees_the_old_fault():
    # What tests/conftest.py used to say.
    old = 'PEER = os.path.join(os.path.dirname(ROOT), "shared", "peer-scenarios", "ompl")'
    assert {w for _, w in outside_references(old)} == {"dirname(ROOT)", "'peer-scenarios'"}
    assert outside_references('open("../shared/x.toml")') == [(1, "'../shared/x.toml'")]
    assert outside_references('t = f"{a:.3g}..{b:.3g} deg"') == []  # an f-string's "..", not a path
    assert outside_references('SCENARIOS = os.path.join(ROOT, "scenarios", "ompl")') == []


def test_no_python_file_reads_outside_the_repository():
    files = _python_files()
    assert len(files) > 40
    bad = []
    for path in files:
        if os.path.samefile(path, __file__):  # this file names the patterns it looks for
            continue
        with open(path, encoding="utf-8") as fh:
            for line, what in outside_references(fh.read()):
                bad.append(f"{os.path.relpath(path, ROOT)}:{line}: {what}")
    assert not bad, "\n".join(bad)
