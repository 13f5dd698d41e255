"""The import graph of ``cspace/`` and ``planners/`` obeys docs/architecture.md's layers.

Every import statement of every module is read from its syntax tree, the ones inside
functions included, and resolved to the module it loads (``from pkg import mod`` is an
arrow to ``pkg.mod``). The graph must have no cycle, every arrow must go down the
documented layer order (or stay inside one package), and no name starting with ``_``
may be taken from another module (by ``from M import _x`` or by ``M._x``).
The checks are functions of a source folder, so the tests also plant each fault in a
scratch tree and see it named.
"""
from __future__ import annotations

import ast
import os

import pytest

from conftest import ROOT

KERNEL = {"cspace.kernel", "cspace.kernel.polygons", "cspace.kernel.minkowski", "cspace.kernel.distance",
          "cspace.kernel.slabs"}
IO = {"cspace.io", "cspace.io.scenario", "cspace.io.importers"}
CS = KERNEL | IO | {"cspace.compiled", "cspace.translation", "cspace.paths", "cspace.se2", "cspace.car", "cspace"}
BASE = "planners.base"  # the shared helpers: planners/errors.py, output.py, progress.py, children.py, ...
# What each package may import of this project (besides itself): docs/architecture.md, "Layers".
# A package of cspace/ is a folder (cspace.kernel.polygons, cspace.se2, ...); a folder's
# __init__ holds only its docstring, so the parents cspace.kernel and cspace.io import nothing
# but cspace.io's loader (cspace/io/load.py), which dispatches to the scenario and the importers.
ALLOWED = {
    "cspace.kernel.polygons": set(),
    "cspace.kernel.minkowski": {"cspace.kernel.polygons"},
    "cspace.kernel.distance": {"cspace.kernel.polygons", "cspace.kernel.minkowski"},
    "cspace.kernel.slabs": {"cspace.kernel.polygons", "cspace.kernel.minkowski"},
    "cspace.kernel": set(),
    "cspace.compiled": KERNEL,
    "cspace.io.scenario": KERNEL,
    "cspace.io.importers": KERNEL | {"cspace.io.scenario"},
    "cspace.io": KERNEL | {"cspace.io.scenario", "cspace.io.importers"},
    "cspace.translation": KERNEL | IO | {"cspace.compiled"},
    "cspace.paths": KERNEL,
    "cspace.se2": KERNEL | IO | {"cspace.compiled", "cspace.translation", "cspace.paths"},
    "cspace.car": KERNEL | IO | {"cspace.compiled", "cspace.translation", "cspace.paths", "cspace.se2"},
    "cspace": CS - {"cspace"},  # cspace/__init__.py: the public names, loaded on first use
    BASE: CS,
    "planners.adapters": CS | {BASE},
    "planners.core": CS | {BASE, "planners.adapters"},
    "planners.pictures": CS | {BASE, "planners.adapters"},
    "planners.bench": CS | {BASE, "planners.adapters", "planners.core", "planners.pictures"},
    "planners.stability": CS | {BASE, "planners.adapters", "planners.core"},
    "planners.cli": CS | {BASE, "planners.adapters", "planners.core", "planners.pictures", "planners.bench",
                          "planners.stability"},
    "planners": CS | {BASE, "planners.adapters", "planners.core", "planners.pictures", "planners.bench",
                      "planners.stability", "planners.cli"},  # __init__ (lazy names) and __main__
}
FOREIGN = {"ompl", "matplotlib", "planners", "scripts"}  # never imported by cspace
# Compiled extensions and the one module that wraps each (their names start with "_", as
# C accelerators' do; everyone else calls the wrapper's public functions).
EXTENSIONS = {("cspace.compiled", "_fast"): "cspace.compiled.fastpath"}
MAX_LINES = 450
MAX_MODULES = 15  # per folder
SIZED = ("cspace", "planners", "tests")  # scripts/ aside


def modules(root: str, tops=("cspace", "planners")) -> dict[str, str]:
    """Dotted module name -> file, for every .py file below the top packages."""
    out = {}
    for top in tops:
        for dirpath, dirs, files in os.walk(os.path.join(root, top)):
            dirs[:] = sorted(d for d in dirs if not d.startswith((".", "__")))
            rel = os.path.relpath(dirpath, root).split(os.sep)
            for f in sorted(files):
                if f.endswith(".py"):
                    name = ".".join(rel if f == "__init__.py" else rel + [f[:-3]])
                    out[name] = os.path.join(dirpath, f)
    return out


def package_of(mod: str, mods: dict) -> str:
    """The layer package a module belongs to (see ALLOWED)."""
    is_pkg = mods[mod].endswith("__init__.py")
    parts = mod.split(".")
    if parts[0] == "cspace":  # its folder: cspace.kernel.polygons, cspace.se2, cspace.io (load.py), ...
        return mod if is_pkg else ".".join(parts[:-1])
    if mod == "planners" or mod == "planners.__main__":
        return "planners"
    if len(parts) == 2 and not is_pkg:
        return BASE
    return "planners." + parts[1]


def _resolve(mod: str, node: ast.ImportFrom, mods: dict) -> str:
    if not node.level:
        return node.module or ""
    here = mod.split(".") if mods[mod].endswith("__init__.py") else mod.split(".")[:-1]
    base = here[:len(here) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def imports(mod: str, mods: dict):
    """(line, target module, names) for every import of the project's modules in ``mod``.

    ``names`` are the names taken by ``from ... import`` from the target module itself
    (a submodule imported that way is its own target, with no names)."""
    tree = ast.parse(open(mods[mod], encoding="utf-8").read(), mods[mod])
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield node.lineno, a.name, ()
        elif isinstance(node, ast.ImportFrom):
            src = _resolve(mod, node, mods)
            taken = []
            for a in node.names:
                if f"{src}.{a.name}" in mods:
                    yield node.lineno, f"{src}.{a.name}", ()
                else:
                    taken.append(a.name)
            if taken:
                yield node.lineno, src, tuple(taken)


def private_attributes(mod: str, mods: dict):
    """(line, module, name) for ``alias._name`` where ``alias`` is an imported project module."""
    tree = ast.parse(open(mods[mod], encoding="utf-8").read(), mods[mod])
    aliases = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name in mods and a.asname:
                    aliases[a.asname] = a.name
        elif isinstance(node, ast.ImportFrom):
            src = _resolve(mod, node, mods)
            for a in node.names:
                if f"{src}.{a.name}" in mods:
                    aliases[a.asname or a.name] = f"{src}.{a.name}"
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases
                and node.attr.startswith("_") and not node.attr.startswith("__")):
            yield node.lineno, aliases[node.value.id], node.attr


def graph(mods: dict) -> dict[str, set]:
    """Module -> the project modules it imports (top level and inside functions)."""
    g = {m: set() for m in mods}
    for m in mods:
        for _, target, _ in imports(m, mods):
            if target in mods and target != m:
                g[m].add(target)
    return g


def cycles(g: dict[str, set]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for root in sorted(g):
        if root in index:
            continue
        work = [(root, iter(sorted(g[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(g[w]))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def faults(root: str) -> list[str]:
    """Every breach of the rules in the tree at ``root``, one line each, naming the modules."""
    mods = modules(root)
    out = []
    for comp in cycles(graph(mods)):
        out.append("import cycle: " + " <-> ".join(comp))
    for m in mods:
        pkg = package_of(m, mods)
        for line, target, names in imports(m, mods):
            top = target.split(".")[0]
            if pkg.startswith("cspace") and top in FOREIGN:
                out.append(f"{m}:{line} imports {target}: cspace never imports OMPL, matplotlib, planners or scripts")
            if target in mods and target != m:
                tpkg = package_of(target, mods)
                if tpkg != pkg and tpkg not in ALLOWED[pkg]:
                    out.append(f"{m}:{line} ({pkg}) imports {target} ({tpkg}): against the layers")
                for n in names:
                    if EXTENSIONS.get((target, n)) == m:
                        continue
                    if n.startswith("_") and not n.startswith("__"):
                        out.append(f"{m}:{line} imports the private name {n} of {target}")
        for line, target, n in private_attributes(m, mods):
            if target != m:
                out.append(f"{m}:{line} uses the private name {n} of {target}")
    return out


def test_the_project_obeys_the_layers():
    found = faults(ROOT)
    assert found == [], "\n".join(found)


def test_every_module_is_in_a_layer():
    mods = modules(ROOT)
    assert all(package_of(m, mods) in ALLOWED for m in mods)
    loose = [n for n in os.listdir(os.path.join(ROOT, "cspace")) if n.endswith(".py") and n != "__init__.py"]
    assert loose == [], f"modules outside the layer folders: {loose}"


def oversized(root: str, tops=SIZED) -> list[str]:
    """Every module over MAX_LINES lines and every folder over MAX_MODULES modules below ``tops``
    (the project's code and its tests; scripts/ aside: one script a benchmark or a figure)."""
    out = []
    for top in tops:
        for dirpath, dirs, files in os.walk(os.path.join(root, top)):
            dirs[:] = sorted(d for d in dirs if not d.startswith((".", "__")))
            mods = sorted(f for f in files if f.endswith(".py") and f not in ("__init__.py", "conftest.py"))
            if len(mods) > MAX_MODULES:
                out.append(f"{os.path.relpath(dirpath, root)}/ holds {len(mods)} modules (at most {MAX_MODULES})")
            for f in mods:
                with open(os.path.join(dirpath, f), encoding="utf-8") as fh:
                    n = sum(1 for _ in fh)
                if n > MAX_LINES:
                    out.append(f"{os.path.relpath(os.path.join(dirpath, f), root)}: {n} lines (at most {MAX_LINES})")
    return out


def test_modules_and_folders_stay_small():
    found = oversized(ROOT)
    assert found == [], "\n".join(found)


def test_an_oversized_module_or_folder_is_named(tmp_path):
    root = _tree(tmp_path, {"cspace/se2/long.py": "x = 1\n" * (MAX_LINES + 1),
                            **{f"tests/t/test_{i}.py": "" for i in range(MAX_MODULES + 1)}})
    assert oversized(root) == [f"cspace/se2/long.py: {MAX_LINES + 1} lines (at most {MAX_LINES})",
                               f"tests/t/ holds {MAX_MODULES + 1} modules (at most {MAX_MODULES})"]


# ------------------------------------------------------------- the checks catch planted faults

def _tree(tmp_path, files: dict) -> str:
    base = {"cspace/__init__.py": "", "cspace/kernel/__init__.py": "", "cspace/kernel/polygons/__init__.py": "",
            "cspace/kernel/minkowski/__init__.py": "", "cspace/io/__init__.py": "", "cspace/translation/__init__.py": "",
            "cspace/se2/__init__.py": "", "cspace/car/__init__.py": "", "planners/__init__.py": "", "planners/core/__init__.py": "",
            "planners/adapters/__init__.py": "", "planners/bench/__init__.py": ""}
    for rel, text in {**base, **files}.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return str(tmp_path)


def test_a_clean_tree_has_no_fault(tmp_path):
    root = _tree(tmp_path, {"cspace/kernel/polygons/a.py": "X = 1\n", "cspace/se2/b.py": "from ..kernel.polygons.a import X\n",
                            "planners/core/plan.py": "def f():\n    from ..adapters.glue import g\n",
                            "planners/adapters/glue.py": "from cspace.se2.b import X\ndef g(): pass\n"})
    assert faults(root) == []


def test_a_planted_cycle_through_a_function_level_import_is_named(tmp_path):
    root = _tree(tmp_path, {"planners/core/plan.py": "from . import routine\n",
                            "planners/core/routine.py": "def f():\n    from .plan import plan\n"})
    assert faults(root) == ["import cycle: planners.core.plan <-> planners.core.routine"]


def test_a_planted_upward_import_is_named(tmp_path):
    root = _tree(tmp_path, {"planners/adapters/glue.py": "def f():\n    from ..bench.sweep import run_one\n",
                            "planners/bench/sweep.py": "def run_one(): pass\n",
                            "cspace/kernel/polygons/k.py": "import planners\n"})
    found = faults(root)
    assert any("planners.adapters.glue:2 (planners.adapters) imports planners.bench.sweep" in f for f in found), found
    assert any(f.startswith("cspace.kernel.polygons.k:1 imports planners") for f in found), found


@pytest.mark.parametrize("low, high", [("cspace/se2", "cspace/car"), ("cspace/translation", "cspace/se2"),
                                       ("cspace/kernel/polygons", "cspace/kernel/minkowski"),
                                       ("cspace/io", "cspace/translation")])
def test_a_planted_upward_arrow_between_geometry_packages_is_named(tmp_path, low, high):
    # a lower package of cspace/ importing a higher one, even inside a function, is named;
    # the same arrow pointing down is allowed
    lo, hi = low.replace("/", "."), high.replace("/", ".")
    up = _tree(tmp_path / "up", {f"{low}/a.py": f"def f():\n    from {hi}.b import Y\n", f"{high}/b.py": "Y = 1\n"})
    assert faults(up) == [f"{lo}.a:2 ({lo}) imports {hi}.b ({hi}): against the layers"]
    down = _tree(tmp_path / "down", {f"{low}/a.py": "Y = 1\n", f"{high}/b.py": f"from {lo}.a import Y\n"})
    assert faults(down) == []


def test_a_planted_private_import_is_named(tmp_path):
    root = _tree(tmp_path, {"cspace/kernel/polygons/a.py": "_x = 1\ndef _y(): pass\n",
                            "cspace/kernel/polygons/b.py": "from .a import _x\nfrom . import a\nz = a._y\n"})
    assert faults(root) == ["cspace.kernel.polygons.b:1 imports the private name _x of cspace.kernel.polygons.a",
                            "cspace.kernel.polygons.b:3 uses the private name _y of cspace.kernel.polygons.a"]


@pytest.mark.parametrize("pkg", sorted(ALLOWED))
def test_the_layer_table_is_acyclic(pkg):
    # no package may reach itself through the allowed arrows
    seen, todo = set(), list(ALLOWED[pkg])
    while todo:
        p = todo.pop()
        if p not in seen:
            seen.add(p)
            todo.extend(ALLOWED[p] - {p})
    assert pkg not in seen
