"""``python -m planners``: the ``cspace`` command."""
try:
    from .cli import console
except KeyboardInterrupt:  # Ctrl-C while the command's package loads: as console() answers it
    import sys

    sys.stderr.write("interrupted\n")
    raise SystemExit(130) from None

console()
