"""Build hook for the optional compiled fast path (cspace/compiled/_fast.c, _build.c, _cells.c,
_chords.c, _gjk.c, _nearest.c, _se2motion.c, _carmotion.c, _carwords.c, _carrrt.c, _disccost.c and their header
_fast.h); everything else is in pyproject.toml.

``optional=True``: on a machine without a C compiler (or where the build fails) the
install goes on and cspace runs its pure-Python path, with the same answers.
"""
import importlib.util
import os
import sys

from setuptools import Extension, setup

HERE = os.path.dirname(os.path.abspath(__file__))

# Each product rounded once, as the float filter's error bound assumes: no FMA contraction.
args = [] if sys.platform == "win32" else ["-O2", "-ffp-contract=off"]
sources = [f"cspace/compiled/{name}.c" for name in ("_fast", "_build", "_cells", "_chords", "_gjk", "_nearest", "_se2motion", "_carmotion", "_carwords", "_carrrt", "_disccost")]

# The sources' fingerprint, compiled in (cspace/compiled/fingerprint.py: loaded by its path, numpy
# may not be installed yet), so that sources edited or pulled since the build run the pure path.
_spec = importlib.util.spec_from_file_location("fingerprint", os.path.join(HERE, "cspace", "compiled", "fingerprint.py"))
_fp = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_fp)
fingerprint = [("CSPACE_SOURCE_HASH", '"%s"' % _fp.fingerprint(os.path.join(HERE, "cspace", "compiled")))]
setup(ext_modules=[Extension("cspace.compiled._fast", sources, depends=["cspace/compiled/_fast.h"], optional=True,
                             extra_compile_args=args, define_macros=fingerprint)])
