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
