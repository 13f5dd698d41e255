"""Every script under scripts/ imports (its top-level imports resolve), so a moved module or a
renamed name cannot leave a benchmark broken until someone runs it."""
import glob
import os

import pytest

from conftest import ROOT, load_script

SCRIPTS = sorted(os.path.splitext(os.path.basename(p))[0] for p in glob.glob(os.path.join(ROOT, "scripts", "*.py")))


@pytest.mark.parametrize("name", SCRIPTS)
def test_script_imports(name):
    mod = load_script(name)
    assert mod.__name__ == name


@pytest.mark.parametrize("name", SCRIPTS)
def test_script_doctests_pass(name):
    # the scripts' examples are tested as the packages' are (scripts/ is not on pytest's doctest path)
    import doctest

    mod = load_script(name)
    assert doctest.testmod(mod, optionflags=doctest.ELLIPSIS).failed == 0


# Benchmarks that can run for minutes say at once what runs and the longest it can take, then
# how far they are (issue 51: they printed nothing for minutes). Each here in a small setting.
LONG = [("bench_planning", ["--quick"]),
        ("bench_se2_exact", ["--scenes", "door_tight", "--seeds", "2", "--time", "0.5"]),
        ("bench_auto", ["--parts", "S", "--seeds", "1", "--limit", "2"])]


@pytest.mark.slow
@pytest.mark.parametrize("name, args", LONG, ids=[n for n, _ in LONG])
def test_a_long_benchmark_says_what_it_runs_then_how_far_it_is(name, args):
    import re
    import subprocess
    import sys

    pytest.importorskip("ompl")
    r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", f"{name}.py"), *args], capture_output=True,
                       text=True, timeout=900, cwd=ROOT)
    assert r.returncode == 0, r.stderr[-2000:]
    lines = r.stderr.splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith(f"{name}"))
    m = re.search(r": (\d+) (runs|rounds), each at most .* \(at most .* in all\)$", lines[first])
    assert m, lines[first]
    n = int(m.group(1))
    done = [int(x) for x in re.findall(rf"^  (\d+)/{n} {m.group(2)}, .* so far, about .* left", r.stderr, re.M)]
    assert done and done[-1] == n and done == sorted(done), r.stderr[-2000:]
