"""Hypothesis strategies of convex pieces, shared by the pair-sum tests of the kernel
(tests/kernel/test_pairsums.py) and of the compiled path (tests/compiled/test_pairsums_compiled.py)."""
import numpy as np
from hypothesis import strategies as st

from cspace.kernel.polygons.hull import convex_hull


def convex_piece(draw, integer):
    k = draw(st.integers(3, 9))
    if integer:  # small integer grid: many parallel and collinear edges
        pts = draw(st.lists(st.tuples(st.integers(-6, 6), st.integers(-6, 6)), min_size=k, max_size=k))
        p = convex_hull(np.array(pts, dtype=np.float64))
    else:
        seed = draw(st.integers(0, 2**31))
        rng = np.random.default_rng(seed)
        a = np.sort(rng.uniform(0, 2 * np.pi, k))
        p = np.c_[np.cos(a), np.sin(a)] * rng.uniform(0.1, 10) + rng.uniform(-5, 5, 2)
        if draw(st.booleans()):  # a rotated rectangle: exactly parallel pairs after rounding are rare, near ones common
            t = rng.uniform(0, np.pi)
            u, v = np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])
            p = np.array([0 * u, 3 * u, 3 * u + v, v])
        p = convex_hull(p)
    return p


@st.composite
def piece_lists(draw):
    integer = draw(st.booleans())
    n, m = draw(st.integers(1, 4)), draw(st.integers(1, 4))
    return [convex_piece(draw, integer) for _ in range(n)], [convex_piece(draw, integer) for _ in range(m)]
