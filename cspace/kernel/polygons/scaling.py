"""Exact power-of-two rescaling, so that float algorithms see coordinates of moderate size.

GJK's and EPA's dot products and GEOS's triangulation and overlay multiply up to
four coordinates together: near 1e±100 and beyond, those products under- or
overflow and the answers go wrong without a word. Multiplying every coordinate by
one power of two is exact (unless a result is subnormal, which :func:`ldexp_exact`
reports), keeps every sign, ratio and exact predicate, and is undone exactly on the
results. Inputs already of moderate size pass through untouched.
"""
from __future__ import annotations

import math

import numpy as np

# Magnitudes within [2^-SAFE_EXPONENT, 2^SAFE_EXPONENT] are used as they are: fourth
# powers stay within 2^±400, far from the double range's ends (2^±1022).
SAFE_EXPONENT = 100
# rescale_exponent(x) is 0 exactly for SAFE_MIN <= x < SAFE_MAX (a test for hot paths).
SAFE_MIN, SAFE_MAX = 2.0 ** -(SAFE_EXPONENT + 1), 2.0**SAFE_EXPONENT


def rescale_exponent(extent: float, magnitude: float) -> int:
    """The power k to multiply by (0 for none) so that ``extent`` comes near 1.

    ``extent`` is the size the float algorithm works with (e.g. coordinates relative
    to a local origin), ``magnitude`` the largest absolute coordinate: when the
    extent itself overflowed (inf, from differences of coordinates near the double
    range's end), k brings the magnitude below 1 instead.

    >>> rescale_exponent(3.0, 3.0), rescale_exponent(1e-200, 1.0), rescale_exponent(float("inf"), 1e308)
    (0, 664, -1025)
    """
    if not math.isfinite(extent):
        return -math.frexp(magnitude)[1] - 1 if math.isfinite(magnitude) and magnitude > 0.0 else 0
    if extent == 0.0:
        return 0
    e = math.frexp(extent)[1]  # extent in [2^(e-1), 2^e)
    return 0 if -SAFE_EXPONENT <= e <= SAFE_EXPONENT else -e


def ldexp_exact(x: np.ndarray, k: int) -> np.ndarray | None:
    """``x * 2**k`` if that is exact for every entry (no subnormal or infinite result), else None.

    >>> ldexp_exact(np.array([1.5, -3.0]), 2).tolist()
    [6.0, -12.0]
    >>> ldexp_exact(np.array([1.0, 1e-300]), -100) is None
    True
    """
    with np.errstate(over="ignore", under="ignore"):
        y = np.ldexp(x, k)
    return y if np.array_equal(np.ldexp(y, -k), x) else None


def scaled_copies(arrays: list, extent: float) -> tuple[int, list] | None:
    """``(k, [x * 2**k for x in arrays])`` when ``extent`` (the size the float work sees)
    leaves the safe range and every copy is exact; None when the arrays are fine as
    they are or cannot be rescaled exactly. An infinite extent (differences that
    overflowed) is rescaled by the arrays' largest magnitude instead.

    >>> k, (a,) = scaled_copies([np.array([1e-200, 3e-200])], 3e-200)
    >>> k, a.tolist() == np.ldexp([1e-200, 3e-200], k).tolist()
    (662, True)
    >>> scaled_copies([np.array([1.0, 3.0])], 3.0) is None
    True
    """
    if SAFE_MIN <= extent < SAFE_MAX:
        return None
    magnitude = extent if math.isfinite(extent) else max(float(np.abs(x).max()) for x in arrays if len(x))
    k = rescale_exponent(extent, magnitude)
    if not k:
        return None
    copies = [ldexp_exact(x, k) for x in arrays]
    return None if any(c is None for c in copies) else (k, copies)

