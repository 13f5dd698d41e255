"""Build hook for the optional compiled fast path (cspace/compiled/_fast.c, _build.c, _cells.c,
_chords.c, _gjk.c, _nearest.c, _se2motion.c, _carmotion.c, _carwords.c, _disccost.c and their header
_fast.h); everything else is in pyproject.toml.

``optional=True``: on a machine without a C compiler (or where the build fails) the
install goes on and cspace runs its pure-Python path, with the same answers.
"""
import sys

from setuptools import Extension, setup

# Each product rounded once, as the float filter's error bound assumes: no FMA contraction.
args = [] if sys.platform == "win32" else ["-O2", "-ffp-contract=off"]
sources = [f"cspace/compiled/{name}.c" for name in ("_fast", "_build", "_cells", "_chords", "_gjk", "_nearest", "_se2motion", "_carmotion", "_carwords", "_disccost")]
setup(ext_modules=[Extension("cspace.compiled._fast", sources, depends=["cspace/compiled/_fast.h"], optional=True,
                             extra_compile_args=args)])
