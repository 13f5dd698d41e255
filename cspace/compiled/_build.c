/* The compiled fast path of the C-space build (part of cspace.compiled._fast): its pair sums
   and the prune's containment test.

   contained(): for candidate pairs (q, p) of convex pieces, is P inside Q? (every vertex
   of P on or left of every edge of Q, cspace_build._contained_pieces's test): 1 yes,
   0 no (a vertex certainly right of an edge), -1 not certified (the caller decides).

   pair_sums(): every Minkowski sum A_i ⊕ B_j of two lists of convex pieces, as
   cspace/kernel/minkowski/pairsums.py computes it, one angular merge per pair, O(|A_i| + |B_j|).
   Each piece is CCW from its lowest (then leftmost) vertex, so its edges come in
   angular order; the merge walks both edge lists and at each step takes the edge of
   smaller angle (half-plane first, then the sign of the cross product; equal
   directions are fused: one vertex). Every output vertex is A_i[k] + B_j[l] rounded
   once, as in the Python merges.

   It certifies, it never guesses. A pair is written only when:
   - both pieces are canonical (strictly convex by certified left turns, lowest then
     leftmost first, edge halves upper...lower once), as PackedPieces.ok requires;
   - every angular comparison is certified: Shewchuk's stage-A filter, the exact zero
     when a factor of each product is an exact zero, or all six operations of the
     cross product exact (TwoSum, Dekker's TwoProduct), as error_free_cross_sign;
   - its sums were exact (Fast2Sum test), or its rounded output turns left at every
     vertex by a certified sign, or every such turn is certified and the exact hull of
     the rounded vertices (the repair minkowski_sum makes: Andrew's monotone chain) is
     found with certified turns.
   Any other pair gets count -1 and the caller computes it with minkowski_sum (the
   pure path, exact, equal array for array). So both paths give the same arrays.
*/
#include "_fast.h"

/* Is the edge direction (dx, dy) in the lower half [pi, 2 pi)? (lower_half) */
static inline int lower(double dx, double dy)
{
    return dy < 0.0 || (dy == 0.0 && dx <= 0.0);
}

/* Is piece p (n vertices, x y interleaved) canonical, certified? */
static int canonical(const double *p, int64_t n)
{
    if (n < 3) return 0;
    double x0 = p[0], y0 = p[1];
    int prev_half = -1;
    for (int64_t k = 0; k < n; k++) {
        int64_t a = k ? k - 1 : n - 1, b = k + 1 < n ? k + 1 : 0;
        double x = p[2 * k], y = p[2 * k + 1];
        if (y < y0 || (y == y0 && x < x0)) return 0; /* not lowest-then-leftmost first */
        /* orient2d(prev, v, next) = (prev - next) x (v - next) */
        if (cross_sign(p[2 * b], p[2 * b + 1], p[2 * a], p[2 * a + 1], p[2 * b], p[2 * b + 1], x, y) != 1) return 0;
        int half = lower(p[2 * b] - x, p[2 * b + 1] - y);
        if (half < prev_half) return 0; /* the halves read upper...lower once */
        prev_half = half;
    }
    return 1;
}

static int lex_less(const double *p, const double *q)
{
    return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
}

static int lex_cmp(const void *a, const void *b)
{
    const double *p = a, *q = b;
    return lex_less(p, q) ? -1 : (lex_less(q, p) ? 1 : 0);
}

/* One monotone chain over the sorted points pts (n), appended to out (len *m): only strict
   left turns kept (certified); 0 if a turn is not certified. */
static int chain(const double *pts, int64_t n, int64_t step, double *out, int64_t *m)
{
    int64_t len = 0;
    for (int64_t t = 0; t < n; t++) {
        const double *p = pts + 2 * (step > 0 ? t : n - 1 - t);
        while (len >= 2) {
            const double *a = out + 2 * (len - 2), *b = out + 2 * (len - 1);
            int s = cross_sign(p[0], p[1], a[0], a[1], p[0], p[1], b[0], b[1]); /* orient2d(a, b, p) */
            if (s == UNDECIDED) return 0;
            if (s > 0) break;
            len--;
        }
        out[2 * len] = p[0], out[2 * len + 1] = p[1];
        len++;
    }
    *m = len;
    return 1;
}

/* The exact convex hull of the n points in out, in place, CCW from the lowest (then leftmost)
   vertex, as cspace.kernel.polygons.hull.convex_hull gives it; -1 if a turn is not certified, the
   hull is degenerate, or a coordinate is -0.0 (Python's dedup could keep either zero). */
static int64_t hull_in_place(double *out, int64_t n)
{
    for (int64_t v = 0; v < 2 * n; v++)
        if (out[v] == 0.0 && signbit(out[v])) return -1;
    double *pts = PyMem_Malloc(sizeof(double) * 2 * (3 * n + 2));
    if (!pts) return -1;
    memcpy(pts, out, sizeof(double) * 2 * n);
    qsort(pts, (size_t)n, 2 * sizeof(double), lex_cmp);
    int64_t u = 0; /* sorted and without repeats */
    for (int64_t t = 0; t < n; t++)
        if (u == 0 || pts[2 * t] != pts[2 * (u - 1)] || pts[2 * t + 1] != pts[2 * (u - 1) + 1])
            pts[2 * u] = pts[2 * t], pts[2 * u + 1] = pts[2 * t + 1], u++;
    double *lower = pts + 2 * n, *upper = pts + 4 * n + 2;
    int64_t nl = 0, nu = 0, h = -1;
    if (u >= 3 && chain(pts, u, 1, lower, &nl) && chain(pts, u, -1, upper, &nu) && nl + nu - 2 >= 3) {
        h = 0;
        for (int64_t t = 0; t < nl - 1; t++) out[2 * h] = lower[2 * t], out[2 * h + 1] = lower[2 * t + 1], h++;
        for (int64_t t = 0; t < nu - 1; t++) out[2 * h] = upper[2 * t], out[2 * h + 1] = upper[2 * t + 1], h++;
        int64_t lo = 0; /* lowest, then leftmost, first */
        for (int64_t t = 1; t < h; t++)
            if (out[2 * t + 1] < out[2 * lo + 1] || (out[2 * t + 1] == out[2 * lo + 1] && out[2 * t] < out[2 * lo])) lo = t;
        for (int64_t t = 0; t < h; t++) pts[2 * t] = out[2 * ((lo + t) % h)], pts[2 * t + 1] = out[2 * ((lo + t) % h) + 1];
        memcpy(out, pts, sizeof(double) * 2 * h);
    }
    PyMem_Free(pts);
    return h;
}

/* The merge of canonical A (na) and B (nb) into out; returns the vertex count, or -1 if a
   comparison or a rounded turn is not certified. Rounded vertices that do not turn left
   everywhere are replaced by their exact hull (minkowski_sum's repair). */
static int64_t merge(const double *A, int64_t na, const double *B, int64_t nb, double *out)
{
    int64_t k = 0, l = 0, n = 0;
    int inexact = 0;
    while (k < na || l < nb) {
        /* k <= na and l <= nb: vertex k % na is k, or 0 at the end (no division per step) */
        const double *va = A + 2 * (k < na ? k : 0), *vb = B + 2 * (l < nb ? l : 0);
        double sx = va[0] + vb[0], sy = va[1] + vb[1];
        if (sx - va[0] != vb[0] || sx - vb[0] != va[0] || sy - va[1] != vb[1] || sy - vb[1] != va[1]) inexact = 1;
        out[2 * n] = sx, out[2 * n + 1] = sy;
        n++;
        if (k == na) {
            l++;
            continue;
        }
        if (l == nb) {
            k++;
            continue;
        }
        const double *a1 = A + 2 * (k + 1 < na ? k + 1 : 0), *b1 = B + 2 * (l + 1 < nb ? l + 1 : 0);
        int ha = lower(a1[0] - va[0], a1[1] - va[1]), hb = lower(b1[0] - vb[0], b1[1] - vb[1]);
        int c = ha != hb ? (ha < hb ? 1 : -1) : cross_sign(va[0], va[1], a1[0], a1[1], vb[0], vb[1], b1[0], b1[1]);
        if (c == UNDECIDED) return -1;
        if (c >= 0) k++; /* a first (b turns CCW from a), or the same direction: fused */
        if (c <= 0) l++;
    }
    if (inexact) { /* rounded: accepted if every turn is certainly left, else the exact hull */
        int repair = 0;
        for (int64_t v = 0; v < n; v++) {
            const double *p = out + 2 * (v ? v - 1 : n - 1), *q = out + 2 * v, *r = out + 2 * (v + 1 < n ? v + 1 : 0);
            int s = cross_sign(r[0], r[1], p[0], p[1], r[0], r[1], q[0], q[1]);
            if (s == UNDECIDED) return -1;
            repair |= s != 1;
        }
        if (repair) return hull_in_place(out, n);
    }
    return n;
}

/* pair_sums(a_xy, a_off, b_xy, b_off, out_xy, out_count) -> vertices written

   a_xy, b_xy: float64 vertices (x y interleaved) of the pieces, piece i from a_off[i] to
   a_off[i + 1]; out_xy: float64, room for the sum over pairs of |A_i| + |B_j| vertices;
   out_count: int64, one per pair (i, j) in the order i * len(B) + j: the pair's vertex
   count, its vertices following the previous pair's, or -1 (not certified: the caller
   computes it). */
PyObject *fast_pair_sums(PyObject *self, PyObject *args)
{
    PyObject *o[6];
    if (!PyArg_ParseTuple(args, "OOOOOO", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5])) return NULL;
    Py_buffer b[6];
    int got = 0;
    Py_ssize_t written = -1;
    for (; got < 6; got++) {
        int flags = got >= 4 ? (PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) : PyBUF_C_CONTIGUOUS;
        if (PyObject_GetBuffer(o[got], &b[got], flags) < 0) goto done;
    }
    const double *axy = b[0].buf, *bxy = b[2].buf;
    const int64_t *aoff = b[1].buf, *boff = b[3].buf;
    double *out = b[4].buf;
    int64_t *count = b[5].buf;
    Py_ssize_t nA = b[1].len / 8 - 1, nB = b[3].len / 8 - 1, cap = b[4].len / 16;
    if (nA < 0 || nB < 0 || b[5].len != 8 * nA * nB || aoff[0] != 0 || boff[0] != 0
        || 16 * aoff[nA] != b[0].len || 16 * boff[nB] != b[2].len) {
        PyErr_SetString(PyExc_ValueError, "_fast.pair_sums: inconsistent array sizes");
        goto done;
    }
    for (Py_ssize_t i = 0; i < nA; i++)
        if (aoff[i + 1] < aoff[i]) goto bad_offsets;
    for (Py_ssize_t j = 0; j < nB; j++)
        if (boff[j + 1] < boff[j]) goto bad_offsets;
    char *okb = PyMem_Malloc(nB ? nB : 1);
    if (!okb) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t j = 0; j < nB; j++) okb[j] = (char)canonical(bxy + 2 * boff[j], boff[j + 1] - boff[j]);
    Py_ssize_t n = 0;
    for (Py_ssize_t i = 0; i < nA; i++) {
        int64_t na = aoff[i + 1] - aoff[i];
        int oka = canonical(axy + 2 * aoff[i], na);
        for (Py_ssize_t j = 0; j < nB; j++) {
            int64_t nb = boff[j + 1] - boff[j], got_n = -1;
            if (oka && okb[j]) {
                if (n + na + nb > cap) {
                    PyMem_Free(okb);
                    PyErr_SetString(PyExc_ValueError, "_fast.pair_sums: out_xy too small");
                    goto done;
                }
                got_n = merge(axy + 2 * aoff[i], na, bxy + 2 * boff[j], nb, out + 2 * n);
            }
            count[i * nB + j] = got_n;
            if (got_n > 0) n += got_n;
        }
    }
    PyMem_Free(okb);
    written = n;
    goto done;
bad_offsets:
    PyErr_SetString(PyExc_ValueError, "_fast.pair_sums: offsets must not decrease");
done:
    for (int k = 0; k < got; k++) PyBuffer_Release(&b[k]);
    return written < 0 ? NULL : PyLong_FromSsize_t(written);
}

/* contained(xy, off, qs, ps, out) -> None

   xy: float64 vertices of the pieces (x y interleaved), piece k from off[k] to off[k + 1];
   qs, ps: int64 candidate pairs; out: int8, per pair 1 (P inside Q), 0 (not), -1 (not
   certified). Signs are orient2d(s, e, v) = (s - v) x (e - v) for each edge s -> e of Q
   and vertex v of P, certified as in cross_sign. */
PyObject *fast_contained(PyObject *self, PyObject *args)
{
    PyObject *o[5];
    if (!PyArg_ParseTuple(args, "OOOOO", &o[0], &o[1], &o[2], &o[3], &o[4])) return NULL;
    Py_buffer b[5];
    int got = 0, ok = 0;
    for (; got < 5; got++) {
        int flags = got == 4 ? (PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) : PyBUF_C_CONTIGUOUS;
        if (PyObject_GetBuffer(o[got], &b[got], flags) < 0) goto done;
    }
    const double *xy = b[0].buf;
    const int64_t *off = b[1].buf, *qs = b[2].buf, *ps = b[3].buf;
    int8_t *out = b[4].buf;
    Py_ssize_t n = b[1].len / 8 - 1, m = b[2].len / 8;
    if (n < 0 || b[3].len != 8 * m || b[4].len != m || off[0] != 0 || 16 * off[n] != b[0].len) {
        PyErr_SetString(PyExc_ValueError, "_fast.contained: inconsistent array sizes");
        goto done;
    }
    for (Py_ssize_t k = 0; k < n; k++)
        if (off[k + 1] < off[k]) {
            PyErr_SetString(PyExc_ValueError, "_fast.contained: offsets must not decrease");
            goto done;
        }
    for (Py_ssize_t t = 0; t < m; t++) {
        if (qs[t] < 0 || qs[t] >= n || ps[t] < 0 || ps[t] >= n) {
            PyErr_SetString(PyExc_ValueError, "_fast.contained: a piece index out of range");
            goto done;
        }
        const double *Q = xy + 2 * off[qs[t]], *P = xy + 2 * off[ps[t]];
        int64_t nq = off[qs[t] + 1] - off[qs[t]], np_ = off[ps[t] + 1] - off[ps[t]];
        int answer = 1;
        for (int64_t v = 0; v < np_ && answer != 0; v++) {
            double vx = P[2 * v], vy = P[2 * v + 1];
            for (int64_t i = 0; i < nq; i++) {
                const double *s = Q + 2 * i, *e = Q + 2 * (i + 1 < nq ? i + 1 : 0);
                int sg = cross_sign(vx, vy, s[0], s[1], vx, vy, e[0], e[1]);
                if (sg == UNDECIDED) {
                    answer = -1;
                } else if (sg < 0) {
                    answer = 0;
                    break;
                }
            }
        }
        out[t] = (int8_t)answer;
    }
    ok = 1;
done:
    for (int k = 0; k < got; k++) PyBuffer_Release(&b[k]);
    if (!ok) return NULL;
    Py_RETURN_NONE;
}
