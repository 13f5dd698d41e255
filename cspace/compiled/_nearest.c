/* min_clearance's search over (sweep, obstacle piece) pairs, compiled (part of
   cspace.compiled._fast; cspace/translation/clearance.py's path_clearance calls it).

   path_clearance visits its candidate pairs by increasing lower bound and measures each
   with GJK until the bound reaches the best distance found. clearance_scan walks that
   queue in C and decides each pair as Python's search would, where the answer is GJK's
   float one: the loop separates the pair (origin outside, extent in the safe range) and
   the distance, math.hypot of the closest points' difference, is beyond the exact band.
   Then the pair loses (distance >= the best) or becomes the best, with its distance and
   B's closest point as gjk.py computes them. sqrt(dx^2 + dy^2) is within 2^-51 of
   math.hypot (relative), so it decides alone a loss outside a window of 2^-48 around the
   best and the band; elsewhere math.hypot itself is called (ties: a path with a margin
   runs at one distance along many segments). The scan stops at the first pair Python
   must see (a contact, the exact band, an input the pure path rescales), at the pair
   where the bounds stop the search, or when it has measured the pairs it was allowed:
   Python goes on from there, with the answers it would have found walking every pair
   itself (the pure path is the oracle).

   pack_boxes packs convex pieces and their bounding boxes in one pass (path_clearance's
   obstacles, each call); box_gaps gives the distances between two sets of boxes (the
   pairs' lower bounds). */
#include "_fast.h"

#define ABOVE (1.0 + 0x1p-48) /* sqrt(dx^2 + dy^2) this far above a value: so is math.hypot */

/* A contiguous 1-d buffer of the given item size, or -1 with an exception. */
static int flat_view(PyObject *obj, Py_buffer *view, Py_ssize_t itemsize, const char *name)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) return -1;
    if (view->itemsize != itemsize) {
        PyErr_Format(PyExc_ValueError, "_fast: %s has items of %zd bytes, not %zd", name,
                     view->itemsize, itemsize);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* A block without the closing repeat of its first point (as gjk.py's _open). */
static inline Py_ssize_t open_count(const double *p, Py_ssize_t n)
{
    return n > 1 && p[0] == p[2 * n - 2] && p[1] == p[2 * n - 1] ? n - 1 : n;
}

/* clearance_scan(placed, npoints, still, xy, off, queue, pairs, lbs, no, pos, best, slack,
                  budget, max_iterations, safe_min, safe_max, band, hypot)
   -> (pos, measured, None or (best, id, bx, by))

   placed: one C-contiguous float64 (npoints * nv_j, 2) array per robot piece j (the piece
   at every path point); still: uint8 per segment (1: one point, the piece itself);
   xy, off: the obstacle pieces packed (piece k: rows off[k] .. off[k + 1]); queue: int64
   positions into lbs in visiting order; pairs: int64 pair ids per position, or None (the
   position is the id); id = (segment * nr + j) * no + k. From queue[pos], measures pairs
   (at most budget, if budget >= 0) while their answer is GJK's float one; returns the
   position where Python goes on, the pairs measured, and the last new best if any: its
   distance, pair id and the obstacle's closest point. hypot: math.hypot. */
PyObject *fast_clearance_scan(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 18) {
        PyErr_SetString(PyExc_TypeError, "clearance_scan takes 18 arguments");
        return NULL;
    }
    PyObject *placed = args[0];
    if (!PyList_Check(placed) || PyList_GET_SIZE(placed) < 1) {
        PyErr_SetString(PyExc_TypeError, "clearance_scan: placed must be a non-empty list");
        return NULL;
    }
    Py_ssize_t nr = PyList_GET_SIZE(placed), npoints = PyLong_AsSsize_t(args[1]), no = PyLong_AsSsize_t(args[8]);
    Py_ssize_t pos = PyLong_AsSsize_t(args[9]), budget = PyLong_AsSsize_t(args[12]);
    Py_ssize_t max_it = PyLong_AsSsize_t(args[13]);
    double best = PyFloat_AsDouble(args[10]), slack = PyFloat_AsDouble(args[11]);
    double safe_min = PyFloat_AsDouble(args[14]), safe_max = PyFloat_AsDouble(args[15]), band = PyFloat_AsDouble(args[16]);
    if (PyErr_Occurred()) return NULL;
    if (npoints < 1 || no < 1 || pos < 0) {
        PyErr_SetString(PyExc_ValueError, "clearance_scan: npoints and no must be positive, pos not negative");
        return NULL;
    }
    Py_buffer *pv = PyMem_Calloc((size_t)nr, sizeof(Py_buffer));
    Py_buffer vs = {0}, vxy = {0}, voff = {0}, vq = {0}, vp = {0}, vl = {0};
    Py_ssize_t got = 0, measured = 0;
    int have_pairs = args[6] != Py_None, fail = 0;
    PyObject *result = NULL;
    if (!pv) return PyErr_NoMemory();
    for (; got < nr; got++) {
        if (PyObject_GetBuffer(PyList_GET_ITEM(placed, got), &pv[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) goto done;
        if (!xy_view(&pv[got]) || pv[got].shape[0] % npoints) {
            PyErr_SetString(PyExc_ValueError, "clearance_scan: placed[j] must be (npoints * nv, 2) float64");
            PyBuffer_Release(&pv[got]);
            goto done;
        }
    }
    fail = flat_view(args[2], &vs, 1, "still") < 0 || flat_view(args[3], &vxy, 8, "xy") < 0
           || flat_view(args[4], &voff, 8, "off") < 0 || flat_view(args[5], &vq, 8, "queue") < 0
           || (have_pairs && flat_view(args[6], &vp, 8, "pairs") < 0) || flat_view(args[7], &vl, 8, "lbs") < 0;
    if (fail) goto done;
    const unsigned char *still = vs.buf;
    const double *xy = vxy.buf, *lbs = vl.buf;
    const int64_t *off = voff.buf, *queue = vq.buf, *pairs = have_pairs ? vp.buf : NULL;
    Py_ssize_t nq = vq.len / 8, nseg = vs.len, nlb = vl.len / 8, noff = voff.len / 8, npairs = vp.len / 8;
    PyObject *hypot = args[17];
    int64_t won = -1;
    double won_x = 0.0, won_y = 0.0;
    for (; pos < nq && (budget < 0 || measured < budget); pos++) {
        int64_t c = queue[pos];
        if (c < 0 || c >= nlb || (have_pairs && c >= npairs)) break; /* Python reports it */
        if (lbs[c] >= best - slack) break;                           /* the search ends here */
        int64_t id = have_pairs ? pairs[c] : c;
        int64_t row = id / no, k = id % no, i = row / nr, j = row % nr;
        if (id < 0 || i >= nseg || k + 1 >= noff) break;
        Py_ssize_t nv = pv[j].shape[0] / npoints, na = (still[i] ? 1 : 2) * nv;
        if (i * nv + na > pv[j].shape[0] || off[k] < 0 || off[k + 1] > vxy.len / 16 || off[k + 1] <= off[k] || !na) break;
        const double *a = (const double *)pv[j].buf + 2 * i * nv, *b = xy + 2 * off[k];
        double dx, dy, bx, by, extent;
        if (gjk_gap(a, open_count(a, na), b, open_count(b, off[k + 1] - off[k]), max_it, safe_min, safe_max, &dx, &dy,
                    &bx, &by, &extent) < 0)
            break; /* Python's: a contact, or the pure path's input */
        double gap = sqrt(dx * dx + dy * dy), floor = band * extent;
        if (!(gap >= best * ABOVE && gap > floor * ABOVE)) { /* not a clear loss: Python's hypot decides */
            PyObject *h = PyObject_CallFunction(hypot, "dd", dx, dy);
            double dist = h ? PyFloat_AsDouble(h) : -1.0;
            Py_XDECREF(h);
            if (PyErr_Occurred()) goto done;
            if (!(dist > floor)) break; /* the exact band: Python's */
            if (dist < best) best = dist, won = id, won_x = bx, won_y = by;
        }
        measured++;
    }
    if (won >= 0)
        result = Py_BuildValue("(nn(dLdd))", pos, measured, best, (long long)won, won_x, won_y);
    else
        result = Py_BuildValue("(nnO)", pos, measured, Py_None);
done:
    for (Py_ssize_t t = 0; t < got; t++) PyBuffer_Release(&pv[t]);
    PyMem_Free(pv);
    if (vs.obj) PyBuffer_Release(&vs);
    if (vxy.obj) PyBuffer_Release(&vxy);
    if (voff.obj) PyBuffer_Release(&voff);
    if (vq.obj) PyBuffer_Release(&vq);
    if (vp.obj) PyBuffer_Release(&vp);
    if (vl.obj) PyBuffer_Release(&vl);
    return result;
}

/* pack_boxes(pieces) -> (xy bytes, off bytes, lo bytes, hi bytes, scale) or None

   pieces: a list of (n, 2) float64 arrays (any strides, n >= 0). xy: their points one
   piece after another (float64 pairs), off: int64 n + 1 row offsets, lo and hi: each
   piece's box (float64 pairs; an empty piece's is +inf, -inf, as polygon.piece_boxes),
   scale: max(hi.max(), -lo.min()) over the boxes (-inf without points). None when an
   item is not such an array or a coordinate is not finite (the caller packs in numpy). */
PyObject *fast_pack_boxes(PyObject *self, PyObject *args)
{
    PyObject *list;
    if (!PyArg_ParseTuple(args, "O!", &PyList_Type, &list)) return NULL;
    Py_ssize_t n = PyList_GET_SIZE(list), got = 0, total = 0;
    Py_buffer *v = PyMem_Calloc((size_t)n + 1, sizeof(Py_buffer));
    PyObject *xy = NULL, *off = NULL, *lo = NULL, *hi = NULL, *result = NULL;
    if (!v) return PyErr_NoMemory();
    for (; got < n; got++) {
        if (PyObject_GetBuffer(PyList_GET_ITEM(list, got), &v[got], PyBUF_RECORDS_RO) < 0) {
            PyErr_Clear();
            result = Py_NewRef(Py_None);
            goto done;
        }
        if (!xy_view(&v[got])) {
            PyBuffer_Release(&v[got]);
            result = Py_NewRef(Py_None);
            goto done;
        }
        total += v[got].shape[0];
    }
    xy = PyBytes_FromStringAndSize(NULL, 16 * total);
    off = PyBytes_FromStringAndSize(NULL, 8 * (n + 1));
    lo = PyBytes_FromStringAndSize(NULL, 16 * n);
    hi = PyBytes_FromStringAndSize(NULL, 16 * n);
    if (!xy || !off || !lo || !hi) goto done;
    double *pxy = (double *)PyBytes_AS_STRING(xy), *plo = (double *)PyBytes_AS_STRING(lo);
    double *phi = (double *)PyBytes_AS_STRING(hi), scale = -HUGE_VAL;
    int64_t *poff = (int64_t *)PyBytes_AS_STRING(off), row = 0;
    for (Py_ssize_t k = 0; k < n; k++) {
        const char *base = v[k].buf;
        Py_ssize_t s0 = v[k].strides[0], s1 = v[k].strides[1];
        double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
        int finite = 1;
        poff[k] = row;
        for (Py_ssize_t i = 0; i < v[k].shape[0]; i++, row++) {
            double x = *(const double *)(base + i * s0), y = *(const double *)(base + i * s0 + s1);
            pxy[2 * row] = x, pxy[2 * row + 1] = y;
            finite &= isfinite(x) && isfinite(y); /* (the comparisons below then decide alone) */
            x0 = x < x0 ? x : x0, y0 = y < y0 ? y : y0, x1 = x > x1 ? x : x1, y1 = y > y1 ? y : y1;
        }
        if (!finite) {
            result = Py_NewRef(Py_None); /* NaN or an infinity: numpy's reductions decide */
            goto done;
        }
        plo[2 * k] = x0, plo[2 * k + 1] = y0, phi[2 * k] = x1, phi[2 * k + 1] = y1;
        scale = fmax(scale, fmax(fmax(x1, y1), fmax(-x0, -y0)));
    }
    poff[n] = row;
    result = Py_BuildValue("(OOOOd)", xy, off, lo, hi, scale);
done:
    Py_XDECREF(xy);
    Py_XDECREF(off);
    Py_XDECREF(lo);
    Py_XDECREF(hi);
    for (Py_ssize_t t = 0; t < got; t++) PyBuffer_Release(&v[t]);
    PyMem_Free(v);
    return result;
}

/* box_gaps(lo, hi, olo, ohi, out): out[r, k] = the distance between box r (lo[r], hi[r])
   and box k (olo[k], ohi[k]), 0 where they meet: hypot of the per-axis gaps
   max(olo - hi, lo - ohi, 0), the doubles of path_clearance's numpy expression (libm's
   hypot, as numpy's). All C-contiguous float64: lo, hi (n, 2), olo, ohi (m, 2), out (n, m). */
PyObject *fast_box_gaps(PyObject *self, PyObject *args)
{
    PyObject *obj[5];
    Py_buffer v[5];
    int got = 0;
    PyObject *result = NULL;
    if (!PyArg_ParseTuple(args, "OOOOO", &obj[0], &obj[1], &obj[2], &obj[3], &obj[4])) return NULL;
    for (; got < 5; got++)
        if (flat_view(obj[got], &v[got], 8, "box_gaps' arrays") < 0) goto done;
    Py_ssize_t n = v[0].len / 16, m = v[2].len / 16;
    if (v[1].len != v[0].len || v[3].len != v[2].len || v[4].len != 8 * n * m || v[4].readonly) {
        PyErr_SetString(PyExc_ValueError, "box_gaps: lo, hi (n, 2), olo, ohi (m, 2) and a writable out (n, m)");
        goto done;
    }
    const double *lo = v[0].buf, *hi = v[1].buf, *olo = v[2].buf, *ohi = v[3].buf;
    double *out = v[4].buf;
    for (Py_ssize_t r = 0; r < n; r++)
        for (Py_ssize_t k = 0; k < m; k++) {
            double gx = olo[2 * k] - hi[2 * r], bx = lo[2 * r] - ohi[2 * k];
            double gy = olo[2 * k + 1] - hi[2 * r + 1], by = lo[2 * r + 1] - ohi[2 * k + 1];
            gx = gx >= bx ? gx : bx, gy = gy >= by ? gy : by;
            out[r * m + k] = hypot(gx >= 0.0 ? gx : 0.0, gy >= 0.0 ? gy : 0.0);
        }
    result = Py_NewRef(Py_None);
done:
    for (int t = 0; t < got; t++) PyBuffer_Release(&v[t]);
    return result;
}
