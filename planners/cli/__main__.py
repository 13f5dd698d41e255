"""``python -m planners.cli``: the ``cspace`` command, as ``python -m planners``."""
try:
    from . import console
except KeyboardInterrupt:  # Ctrl-C while the package's names load: as console() answers it
    import sys

    sys.stderr.write("interrupted\n")
    raise SystemExit(130) from None

console()
