/* The compiled chord polygons of the grid build (part of cspace.compiled._fast).

   chords(): cspace/kernel/polygons/chords.py's chord_polygons, piece by piece, with the same
   float operations in the same order, so the same chord polygons and sagittas (the
   numpy route refines all pieces together, but a piece whose chords all pass stops
   changing, so refining each piece on its own until it passes gives the same result).
   A piece's chord polygon starts from eight of its vertices and both ends of every
   edge longer than long_edge (L1); while a chord's sagitta (the largest n . v - c over
   the vertices of the arc it cuts off) exceeds the tolerance and the arc has more than
   one edge, the arc's middle vertex is added. No decision here needs certifying: the
   grid's classification uses the sagittas as the numpy route does.
*/
#include "_fast.h"

/* One piece: q (s vertices), keep (s flags, the start set) -> out (n vertices), sag (n); returns n.
   Each chord's unit outward normal and offset (n . x <= c) go to nrm (3 x n: x, y, c) if given:
   the grid's half-planes of the chord polygon, as half_planes would compute them again. */
static int64_t chord_piece(const double *q, int64_t s, char *keep, double limit, int64_t *idx, double *out,
                           double *sag, double *const nrm[3])
{
    for (;;) {
        int64_t n = 0;
        for (int64_t v = 0; v < s; v++)
            if (keep[v]) idx[n++] = v;
        int added = 0;
        for (int64_t c = 0; c < n; c++) {
            int64_t a = idx[c], b = idx[c + 1 < n ? c + 1 : 0];
            double dx = q[2 * b] - q[2 * a], dy = q[2 * b + 1] - q[2 * a + 1];
            double h = hypot(dy, -dx);
            double nx = dy / h, ny = -dx / h;
            double cc = nx * q[2 * a] + ny * q[2 * a + 1];
            if (nrm) nrm[0][c] = nx, nrm[1][c] = ny, nrm[2][c] = cc;
            /* the arc of chord c: its own vertex up to the next kept one (the last: to the end) */
            int64_t stop = c + 1 < n ? b : s;
            double m = -HUGE_VAL;
            for (int64_t v = a; v < stop; v++) {
                double r = nx * q[2 * v];
                r += ny * q[2 * v + 1];
                r -= cc;
                m = (isnan(m) || isnan(r)) ? NAN : (r > m ? r : m); /* NaN propagates, as np.maximum */
            }
            sag[c] = isnan(m) ? m : (m > 0.0 ? m : 0.0);
            int64_t span = ((b - a) % s + s) % s;
            if (sag[c] > limit && span > 1) {
                keep[(a + span / 2) % s] = 1;
                added = 1;
            }
        }
        if (!added) {
            for (int64_t c = 0; c < n; c++) out[2 * c] = q[2 * idx[c]], out[2 * c + 1] = q[2 * idx[c] + 1];
            return n;
        }
    }
}

/* One piece's chord polygon: q (s vertices) -> out (n vertices), sag (n), nrm (its
   half-planes, if not NULL); returns n. The start set: eight vertices, and both ends of
   every edge longer than long_edge (L1). Scratch: keep (s bytes), idx (s). */
int64_t chord_polygon(const double *q, int64_t s, double long_edge, double limit, char *keep, int64_t *idx,
                      double *out, double *sag, double *const nrm[3])
{
    int64_t step = s / 8 > 1 ? s / 8 : 1;
    /* Each edge's length once: edge v (v -> v + 1) long keeps both its ends. */
    int lu = fabs(q[0] - q[2 * (s - 1)]) + fabs(q[1] - q[2 * (s - 1) + 1]) > long_edge; /* edge s - 1 */
    for (int64_t v = 0, t = 0; v < s; v++, t = t + 1 < step ? t + 1 : 0) {
        int64_t w = v + 1 < s ? v + 1 : 0;
        int lv = fabs(q[2 * w] - q[2 * v]) + fabs(q[2 * w + 1] - q[2 * v + 1]) > long_edge;
        keep[v] = (char)(lv | lu | (t == 0)); /* t = v mod step */
        lu = lv;
    }
    return chord_piece(q, s, keep, limit, idx, out, sag, nrm);
}

/* chords(Q, sizes, long_edge, tolerance, out_R, out_n, out_sag) -> None

   Q: float64 K x E x 2 padded vertices; sizes: int64 K; out_R: float64 K x E x 2 (row k's
   first out_n[k] vertices are its chord polygon, the rest is left as it was); out_n:
   int64 K; out_sag: float64 K x E (row k's first out_n[k] entries; the rest set to 0). */
PyObject *fast_chords(PyObject *self, PyObject *args)
{
    PyObject *o[5];
    double long_edge, limit;
    if (!PyArg_ParseTuple(args, "OOddOOO", &o[0], &o[1], &long_edge, &limit, &o[2], &o[3], &o[4])) return NULL;
    Py_buffer b[5];
    int got = 0, ok = 0;
    char *keep = NULL;
    int64_t *idx = NULL;
    for (; got < 5; got++) {
        int flags = got >= 2 ? (PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) : PyBUF_C_CONTIGUOUS;
        if (PyObject_GetBuffer(o[got], &b[got], flags) < 0) goto done;
    }
    const double *Q = b[0].buf;
    const int64_t *sizes = b[1].buf;
    double *R = b[2].buf, *sag = b[4].buf;
    int64_t *nout = b[3].buf;
    Py_ssize_t K = b[1].len / 8, E = K ? b[0].len / 16 / K : 0;
    if (b[0].len != 16 * K * E || b[2].len != b[0].len || b[3].len != 8 * K || b[4].len != 8 * K * E) {
        PyErr_SetString(PyExc_ValueError, "_fast.chords: inconsistent array sizes");
        goto done;
    }
    keep = PyMem_Malloc(E ? E : 1);
    idx = PyMem_Malloc(8 * (E ? E : 1));
    if (!keep || !idx) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t k = 0; k < K; k++) {
        int64_t s = sizes[k];
        const double *q = Q + 2 * k * E;
        if (s < 1 || s > E) {
            PyErr_SetString(PyExc_ValueError, "_fast.chords: a size out of range");
            goto done;
        }
        double *sg = sag + k * E;
        for (Py_ssize_t c = 0; c < E; c++) sg[c] = 0.0;
        nout[k] = chord_polygon(q, s, long_edge, limit, keep, idx, R + 2 * k * E, sg, NULL);
    }
    ok = 1;
done:
    PyMem_Free(keep);
    PyMem_Free(idx);
    for (int k = 0; k < got; k++) PyBuffer_Release(&b[k]);
    if (!ok) return NULL;
    Py_RETURN_NONE;
}
