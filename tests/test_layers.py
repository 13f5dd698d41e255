"""The layers import downwards only: cspace.kernel <- cspace.io <- cspace.spaces <- planners <- scripts.

Every import statement of every module (top level and inside functions) is read from
its syntax tree, so a lazy import that climbs a layer is caught too.
"""
import ast
import os

import pytest

from conftest import ROOT

# What each package may import of this project (besides itself).
ALLOWED = {
    "cspace.kernel": set(),
    "cspace.io": {"cspace.kernel"},
    "cspace.spaces": {"cspace.kernel", "cspace.io"},
    "cspace": {"cspace.kernel", "cspace.io", "cspace.spaces"},  # cspace/__init__.py re-exports
    "planners": {"cspace", "cspace.kernel", "cspace.io", "cspace.spaces"},
}
FOREIGN = {"ompl", "matplotlib", "planners", "scripts"}


def _modules():
    for pkg in ALLOWED:
        folder = os.path.join(ROOT, *pkg.split("."))
        for name in sorted(os.listdir(folder)):
            if name.endswith(".py"):
                yield pkg, os.path.join(folder, name)


def _imports(path: str, pkg: str):
    """Absolute names of the project's modules that the file imports."""
    tree = ast.parse(open(path, encoding="utf-8").read(), path)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.split(".")
                base = base[:len(base) - (node.level - 1)] if node.level > 1 else base
                yield ".".join(base + ([node.module] if node.module else []))
            elif node.module:
                yield node.module


def _package_of(name: str) -> str | None:
    for pkg in sorted(ALLOWED, key=len, reverse=True):
        if name == pkg or name.startswith(pkg + "."):
            return pkg
    return None


@pytest.mark.parametrize("pkg, path", list(_modules()), ids=lambda v: os.path.relpath(v, ROOT) if isinstance(v, str) and os.sep in v else v)
def test_imports_go_down_the_layers(pkg, path):
    for name in _imports(path, pkg):
        top = name.split(".")[0]
        if pkg.startswith("cspace"):
            assert top not in FOREIGN, f"{path} imports {name}: cspace never imports OMPL, matplotlib or planners"
        target = _package_of(name)
        if target is None or target == pkg:
            continue
        assert target in ALLOWED[pkg], f"{path} ({pkg}) imports {name} ({target}): against the layers"


def test_every_cspace_module_is_in_a_layer():
    loose = [n for n in os.listdir(os.path.join(ROOT, "cspace")) if n.endswith(".py") and n != "__init__.py"]
    assert loose == [], f"modules outside the layer folders: {loose}"
