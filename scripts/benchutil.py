"""Helpers shared by the bench scripts (they are scripts, not a package: each puts this
folder on ``sys.path`` before importing it)."""
from __future__ import annotations

import statistics
import time


def median_time(fn, reps: int) -> float:
    """Median wall seconds of ``fn()`` over ``reps`` calls.

    >>> median_time(lambda: None, 3) >= 0
    True
    """
    out = []
    for _ in range(reps):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return statistics.median(out)


def coal_peer(wanted: bool) -> bool:
    """Whether the OMPL + coal peer runs: ``wanted`` and coal importable (a line says why not).

    >>> coal_peer(False)
    False
    """
    import importlib.util

    if not wanted:
        return False
    if importlib.util.find_spec("coal") is None:
        print("coal is not installed (pip install coal, or the bench extra): the peer is skipped")
        return False
    return True
