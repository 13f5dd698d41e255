/* The compiled SE(2) motion check: SE2Motions.motion_free's loop (cspace/se2/motion.py)
   in one call per motion, answering 1 free, 0 not free, -1 undecided (the Python path, the
   oracle, then decides the motion from scratch), or -2 - k: slab k's C-space is not built
   yet (Python builds it and calls again).

   The caller has wrapped both end angles and tested both end poses. Then, as the Python
   path does, with the same float operations:
   - the motion is split where its angle crosses a slab boundary (_split), each piece's
     slab is the one holding its middle angle (slab_of: the float index certified by two
     comparisons with the slab's interval widened by ANGLE_SLACK);
   - a piece whose reference segment is free in its slab's C-space is free (the compiled
     grid walk of _fast.c, the slab C-space's own segment test; "undecided" there goes on
     to the refinement below, which never answers "free" where that test's exact answer
     would be needed);
   - otherwise the piece is halved as _refine halves it (the same order, the same budget of
     MAX_REFINE sweeps per motion): a sub-motion is free when, for every robot piece, its
     swept hull conv(T) + [-d, d]^2 + seg(pa, pb) (T and d computed as slab_hull computes
     them) has a separating axis from every obstacle piece with a gap above
     MARGIN = 2^-42 (scale + radius) |n|_1, where |n|_1 = |nx| + |ny| (far above the
     float error of the support values, about 40 u (scale + radius) |n|_1, and of the
     rounding of the Python path's computed sweep polygon, 2 u of its coordinates);
     so a sweep separated here is separated from every obstacle piece by the Python
     path's exact separating-axis test too, and the halving here visits every node the
     Python halving visits. A middle pose in collision (the slab grid's point test, else
     _fast.c's certified filter of the exact pose test) is "not free" (the Python path
     finds the same pose or an earlier collision); the floor (size within 1e-6 relative
     of 1e-9 of the extent), the budget, a D = 0 (fixed angle) piece that needs the exact
     translational test, an undecided pose filter: -1.

   Hence "free" here implies "free" on the Python path, and "not free" implies "not free". */
#include "_fast.h"

typedef struct {
    int64_t K, n_obs, n_rob, max_refine, max_n;
    double *slab_lo, *slab_hi;    /* per slab: its hull interval (slab range +- ANGLE_SLACK) */
    int64_t *o_off, *r_off;       /* obstacle / robot piece k: vertices off[k] .. off[k+1]-1 */
    double *o_xy, *o_nrm, *o_box; /* obstacle vertices; edge normals (x, y); boxes x0 y0 x1 y1 */
    double *r_xy;                 /* body-frame robot vertices */
    double scale, radius, floor_len, slack, margin;
    PyObject *se2;                /* _fast.c's SE(2) pose filter capsule */
    PyObject *checks;             /* the C-space's counters (a dict) */
    double *T, *hull_nrm, *hull_lo, *hull_hi; /* scratch: 3 max_n points; normals and T's intervals */
    int64_t *idx;                 /* scratch: the hull's chain */
    double *stack;                /* scratch: (sa, sb) pairs */
    int64_t stack_cap;
} Motion;

static void motion_release(Motion *h)
{
    PyMem_Free(h->slab_lo);
    PyMem_Free(h->slab_hi);
    PyMem_Free(h->o_off);
    PyMem_Free(h->r_off);
    PyMem_Free(h->o_xy);
    PyMem_Free(h->o_nrm);
    PyMem_Free(h->o_box);
    PyMem_Free(h->r_xy);
    PyMem_Free(h->T);
    PyMem_Free(h->hull_nrm);
    PyMem_Free(h->hull_lo);
    PyMem_Free(h->hull_hi);
    PyMem_Free(h->idx);
    PyMem_Free(h->stack);
    Py_XDECREF(h->se2);
    Py_XDECREF(h->checks);
    PyMem_Free(h);
}

static void motion_free_cap(PyObject *cap)
{
    Motion *h = (Motion *)PyCapsule_GetPointer(cap, "cspace.compiled._fast.SE2Motion");
    if (h) motion_release(h);
}

/* se2_motion_handle(se2, checks, slab_lo, slab_hi, o_off, o_xy, r_off, r_xy, K, n_obs, n_rob,
   max_refine, scale, radius, floor_len, slack) -> capsule (copies the arrays). */
PyObject *fast_se2_motion_handle(PyObject *self, PyObject *args)
{
    PyObject *se2, *checks, *a[6];
    Py_ssize_t K, n_obs, n_rob, max_refine;
    double scale, radius, floor_len, slack;
    if (!PyArg_ParseTuple(args, "OO!OOOOOOnnnndddd", &se2, &PyDict_Type, &checks, &a[0], &a[1], &a[2], &a[3], &a[4],
                          &a[5], &K, &n_obs, &n_rob, &max_refine, &scale, &radius, &floor_len, &slack))
        return NULL;
    if (!PyCapsule_IsValid(se2, "cspace.compiled._fast.SE2")) {
        PyErr_SetString(PyExc_TypeError, "_fast.se2_motion_handle: not an SE(2) handle");
        return NULL;
    }
    if (K < 1 || n_obs < 0 || n_rob < 1 || max_refine < 1
        || !(isfinite(scale) && isfinite(radius) && isfinite(floor_len) && scale >= 0 && radius >= 0)) {
        PyErr_SetString(PyExc_ValueError, "_fast.se2_motion_handle: bad sizes");
        return NULL;
    }
    Motion *h = PyMem_Calloc(1, sizeof(Motion));
    if (!h) return PyErr_NoMemory();
    Py_INCREF(se2);
    Py_INCREF(checks);
    h->se2 = se2, h->checks = checks;
    h->K = K, h->n_obs = n_obs, h->n_rob = n_rob, h->max_refine = max_refine;
    h->scale = scale, h->radius = radius, h->floor_len = floor_len, h->slack = slack;
    /* The gap a separating axis needs, per unit of |n|_1 (see the file's comment). */
    h->margin = 0x1p-42 * (scale + radius) + 0x1p-900;
    if (!(h->slab_lo = fast_copy_buffer(a[0], 8, K, "slab_lo"))) goto fail;
    if (!(h->slab_hi = fast_copy_buffer(a[1], 8, K, "slab_hi"))) goto fail;
    if (!(h->o_off = fast_copy_buffer(a[2], 8, n_obs + 1, "o_off"))) goto fail;
    if (!(h->r_off = fast_copy_buffer(a[4], 8, n_rob + 1, "r_off"))) goto fail;
    if ((h->max_n = piece_offsets_max(h->o_off, n_obs, h->r_off, n_rob)) < 0) goto bad;
    int64_t no = h->o_off[n_obs], nr = h->r_off[n_rob];
    if (!(h->o_xy = fast_copy_buffer(a[3], 16, no, "o_xy"))) goto fail;
    if (!(h->r_xy = fast_copy_buffer(a[5], 16, nr, "r_xy"))) goto fail;
    h->o_nrm = PyMem_Malloc(16 * (size_t)(no ? no : 1));
    h->o_box = PyMem_Malloc(32 * (size_t)(n_obs ? n_obs : 1));
    size_t t = 3 * (size_t)h->max_n + 2;
    h->T = PyMem_Malloc(16 * t);
    h->hull_nrm = PyMem_Malloc(16 * (t + 2));
    h->hull_lo = PyMem_Malloc(8 * (t + 2));
    h->hull_hi = PyMem_Malloc(8 * (t + 2));
    h->idx = PyMem_Malloc(8 * (2 * t + 2));
    h->stack_cap = 2 * max_refine + 64;
    h->stack = PyMem_Malloc(16 * (size_t)h->stack_cap);
    if (!h->o_nrm || !h->o_box || !h->T || !h->hull_nrm || !h->hull_lo || !h->hull_hi || !h->idx || !h->stack) {
        PyErr_NoMemory();
        goto fail;
    }
    if (piece_boxes(h->o_xy, h->o_off, n_obs, h->o_box) < 0) goto bad;
    for (int64_t i = 0; i < n_obs; i++) {
        int64_t s = h->o_off[i], e = h->o_off[i + 1];
        for (int64_t v = s; v < e; v++) {
            int64_t p = v == s ? e - 1 : v - 1; /* the edge ending at v: any direction is an axis */
            h->o_nrm[2 * v] = h->o_xy[2 * v + 1] - h->o_xy[2 * p + 1];
            h->o_nrm[2 * v + 1] = h->o_xy[2 * p] - h->o_xy[2 * v];
        }
    }
    PyObject *cap = PyCapsule_New(h, "cspace.compiled._fast.SE2Motion", motion_free_cap);
    if (cap) return cap;
    goto fail;
bad:
    PyErr_SetString(PyExc_ValueError, "_fast.se2_motion_handle: inconsistent arrays");
fail:
    motion_release(h);
    return NULL;
}

/* Float convex hull (Andrew's chain) of n points: the indices of its vertices in idx, CCW;
   returns their count. Only a source of candidate axes: any direction is a valid axis. */
static int64_t float_hull(const double *p, int64_t n, int64_t *order, int64_t *out)
{
    for (int64_t i = 0; i < n; i++) order[i] = i;
    for (int64_t i = 1; i < n; i++) { /* insertion sort by (x, y): n is small */
        int64_t v = order[i], j = i - 1;
        while (j >= 0 && (p[2 * order[j]] > p[2 * v] || (p[2 * order[j]] == p[2 * v] && p[2 * order[j] + 1] > p[2 * v + 1]))) {
            order[j + 1] = order[j];
            j--;
        }
        order[j + 1] = v;
    }
    int64_t k = 0;
    for (int pass = 0; pass < 2; pass++) {
        int64_t start = k;
        for (int64_t t = 0; t < n; t++) {
            int64_t i = pass == 0 ? order[t] : order[n - 1 - t];
            while (k >= start + 2) {
                const double *a = p + 2 * out[k - 2], *b = p + 2 * out[k - 1], *c = p + 2 * i;
                if ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0) break;
                k--;
            }
            out[k++] = i;
        }
        k--; /* the last point starts the other chain */
    }
    return k;
}

/* Does some robot piece's hull over [lo, hi], swept along pa-pb, possibly meet an obstacle
   piece? 0 certainly not (every pair has a separating axis with a gap above the margin),
   1 maybe. T and d as cspace.kernel.slabs.slab.slab_hull computes them. */
static int sweep_hits(Motion *h, double pax, double pay, double pbx, double pby, double lo, double hi)
{
    double half = 0.5 * (hi - lo), m = lo + half;
    double c0 = cos(lo), s0 = sin(lo), c1 = cos(hi), s1 = sin(hi), cm = cos(m), sm = sin(m), ch = cos(half);
    double sxlo = pax < pbx ? pax : pbx, sxhi = pax < pbx ? pbx : pax;
    double sylo = pay < pby ? pay : pby, syhi = pay < pby ? pby : pay;
    double segnx = pby - pay, segny = pax - pbx; /* the segment's normal (zero for a point) */
    double segA = segnx * pax + segny * pay, segB = segnx * pbx + segny * pby;
    double M = h->margin;
    for (int64_t j = 0; j < h->n_rob; j++) {
        int64_t n = h->r_off[j + 1] - h->r_off[j];
        const double *v = h->r_xy + 2 * h->r_off[j];
        double *T = h->T, r = 0.0;
        for (int64_t u = 0; u < n; u++) {
            double x = v[2 * u], y = v[2 * u + 1];
            T[2 * u] = x * c0 - y * s0 + 0.0;
            T[2 * u + 1] = x * s0 + y * c0 + 0.0;
            T[2 * (n + u)] = x * c1 - y * s1 + 0.0;
            T[2 * (n + u) + 1] = x * s1 + y * c1 + 0.0;
            double ax = (x * cm - y * sm + 0.0) / ch, ay = (x * sm + y * cm + 0.0) / ch;
            T[2 * (2 * n + u)] = ax;
            T[2 * (2 * n + u) + 1] = ay;
            if (fabs(ax) > r) r = fabs(ax);
            if (fabs(ay) > r) r = fabs(ay);
        }
        int64_t nt = 3 * n;
        r = r * sqrt(2.0);
        double d = 0x1p-44 * (r > h->scale ? r : h->scale) + 0x1p-900; /* slab_pad(max(r, scale)) */
        if (!(isfinite(d) && isfinite(ch) && ch > 0.0)) return 1;
        /* The sweep's box (the axes of the square), and its hull's normals with T's intervals. */
        double tx0, tx1, ty0, ty1;
        dot_interval(T, nt, 1.0, 0.0, &tx0, &tx1);
        dot_interval(T, nt, 0.0, 1.0, &ty0, &ty1);
        double bx0 = tx0 - d + sxlo, bx1 = tx1 + d + sxhi, by0 = ty0 - d + sylo, by1 = ty1 + d + syhi;
        int64_t *chain = h->idx + (3 * h->max_n + 2);
        int64_t nh = float_hull(T, nt, h->idx, chain);
        int64_t na = 0;
        for (int64_t e = 0; e < nh; e++) {
            const double *a = T + 2 * chain[e], *b = T + 2 * chain[(e + 1) % nh];
            double nx = b[1] - a[1], ny = a[0] - b[0];
            if (nx == 0.0 && ny == 0.0) continue;
            h->hull_nrm[2 * na] = nx, h->hull_nrm[2 * na + 1] = ny;
            double tlo, thi;
            dot_interval(T, nt, nx, ny, &tlo, &thi);
            double pa = nx * pax + ny * pay, pb = nx * pbx + ny * pby, w = d * (fabs(nx) + fabs(ny));
            h->hull_lo[na] = tlo - w + (pa < pb ? pa : pb);
            h->hull_hi[na] = thi + w + (pa < pb ? pb : pa);
            na++;
        }
        if (segnx != 0.0 || segny != 0.0) { /* the segment's own normal */
            double tlo, thi;
            dot_interval(T, nt, segnx, segny, &tlo, &thi);
            double w = d * (fabs(segnx) + fabs(segny));
            h->hull_nrm[2 * na] = segnx, h->hull_nrm[2 * na + 1] = segny;
            h->hull_lo[na] = tlo - w + (segA < segB ? segA : segB);
            h->hull_hi[na] = thi + w + (segA < segB ? segB : segA);
            na++;
        }
        for (int64_t i = 0; i < h->n_obs; i++) {
            const double *B = h->o_box + 4 * i;
            if (B[0] > bx1 + M || bx0 > B[2] + M || B[1] > by1 + M || by0 > B[3] + M) continue; /* box axes */
            int64_t o0 = h->o_off[i], no = h->o_off[i + 1] - o0;
            const double *O = h->o_xy + 2 * o0;
            int sep = 0;
            for (int64_t a = 0; a < na && !sep; a++) { /* the sweep's normals */
                double nx = h->hull_nrm[2 * a], ny = h->hull_nrm[2 * a + 1], olo, ohi;
                double g = M * (fabs(nx) + fabs(ny));
                dot_interval(O, no, nx, ny, &olo, &ohi);
                if (h->hull_hi[a] + g < olo || ohi + g < h->hull_lo[a]) sep = 1;
            }
            for (int64_t e = 0; e < no && !sep; e++) { /* the obstacle's normals */
                double nx = h->o_nrm[2 * (o0 + e)], ny = h->o_nrm[2 * (o0 + e) + 1], olo, ohi, tlo, thi;
                if (nx == 0.0 && ny == 0.0) continue;
                double w = fabs(nx) + fabs(ny), g = M * w;
                dot_interval(O, no, nx, ny, &olo, &ohi);
                dot_interval(T, nt, nx, ny, &tlo, &thi);
                double pa = nx * pax + ny * pay, pb = nx * pbx + ny * pby;
                double slo = tlo - d * w + (pa < pb ? pa : pb), shi = thi + d * w + (pa < pb ? pb : pa);
                if (shi + g < olo || ohi + g < slo) sep = 1;
            }
            if (!sep) return 1;
        }
    }
    return 0;
}

/* The pose (x, y, th) (th wrapped): 1 free, 0 in collision, -1 undecided, -2 error. */
static int pose_test(Motion *h, PyObject *grids, double x, double y, double th)
{
    int64_t k = slab_index(h->slab_lo, h->slab_hi, h->K, th);
    if (k >= 0 && k < PyList_GET_SIZE(grids)) {
        PyObject *g = PyList_GET_ITEM(grids, k);
        if (g != Py_None) {
            int r = fast_grid_point(g, x, y);
            if (r == 1) return 1; /* free in the slab's C-space: free at every angle of it */
            if (r == -2) return -2;
        }
    }
    return fast_se2_filter(h->se2, x, y, cos(th), sin(th));
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* se2_motion(handle, grids, x0, y0, a0, x1, y1, a1) -> 1 free, 0 not free, -1 undecided,
   -2 - k: slab k is not built (grids[k] is None). a0 and a1 wrapped, both end poses free. */
PyObject *fast_se2_motion(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double q[6];
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError, "se2_motion(handle, grids, x0, y0, a0, x1, y1, a1)");
        return NULL;
    }
    Motion *h = (Motion *)PyCapsule_GetPointer(args[0], "cspace.compiled._fast.SE2Motion");
    if (!h) return NULL;
    PyObject *grids = args[1];
    if (!PyList_Check(grids) || PyList_GET_SIZE(grids) != h->K) {
        PyErr_SetString(PyExc_TypeError, "se2_motion: grids must be a list of one entry per slab");
        return NULL;
    }
    for (int i = 0; i < 6; i++) {
        q[i] = PyFloat_AsDouble(args[2 + i]);
        if (q[i] == -1.0 && PyErr_Occurred()) return NULL;
    }
    double x0 = q[0], y0 = q[1], a0 = q[2], x1 = q[3], y1 = q[4], a1 = q[5];
    if (!(isfinite(x0) && isfinite(y0) && isfinite(a0) && isfinite(x1) && isfinite(y1) && isfinite(a1)))
        return PyLong_FromLong(-1);
    /* turn_arc */
    double D = a1 - a0;
    if (!(fabs(D) <= PI)) D = D > 0.0 ? D - TWO_PI : D + TWO_PI;
    /* _split: fractions where the angle a0 + D t crosses a slab boundary */
    double ts[72];
    int64_t nts = 0;
    ts[nts++] = 0.0;
    if (!(D == 0.0 || h->K == 1)) {
        double w = TWO_PI / (double)h->K, e = a0 + D;
        double lo = a0 < e ? a0 : e, hi = a0 < e ? e : a0;
        double j0 = floor((lo + PI) / w) + 1.0, j1 = ceil((hi + PI) / w) - 1.0;
        if (j1 - j0 > 64.0) return PyLong_FromLong(-1); /* never: |D| <= pi, K <= 128 */
        double cuts[72];
        int64_t nc = 0;
        for (double j = j0; j <= j1; j += 1.0) {
            double c = (-PI + j * w - a0) / D;
            c = c > 0.0 ? c : 0.0;
            c = c < 1.0 ? c : 1.0;
            cuts[nc++] = c;
        }
        qsort(cuts, (size_t)nc, sizeof(double), cmp_double);
        for (int64_t t = 0; t < nc; t++)
            if (0.0 < cuts[t] && cuts[t] < 1.0 && cuts[t] != ts[nts - 1]) ts[nts++] = cuts[t];
    }
    ts[nts++] = 1.0;
    long n_sub = 0, n_cert = 0, n_ref = 0, n_sweeps = 0, n_coll = 0;
    int64_t budget = h->max_refine;
    int result = 1;
    for (int64_t p = 0; p + 1 < nts && result == 1; p++) {
        double ta = ts[p], tb = ts[p + 1];
        n_sub++;
        double pax = ta == 0.0 ? x0 : x0 + (x1 - x0) * ta, pay = ta == 0.0 ? y0 : y0 + (y1 - y0) * ta;
        double pbx = tb == 1.0 ? x1 : x0 + (x1 - x0) * tb, pby = tb == 1.0 ? y1 : y0 + (y1 - y0) * tb;
        double mid = wrap_angle(a0 + D * (0.5 * (ta + tb)));
        int64_t k = slab_index(h->slab_lo, h->slab_hi, h->K, mid);
        if (k < 0) return PyLong_FromLong(-1);
        PyObject *g = PyList_GET_ITEM(grids, k);
        if (g == Py_None) return PyLong_FromLong(-2 - (long)k);
        int r = fast_grid_segment(g, pax, pay, pbx, pby);
        if (r == -2) return NULL;
        if (r == 1 || r == 3) {
            n_cert++;
            continue;
        }
        /* _refine(ta, tb): halving with swept hulls */
        n_ref++;
        int64_t top = 0;
        h->stack[0] = ta, h->stack[1] = tb;
        top = 1;
        while (top > 0) {
            top--;
            double sa = h->stack[2 * top], sb = h->stack[2 * top + 1];
            double qax = sa == 0.0 ? x0 : x0 + (x1 - x0) * sa, qay = sa == 0.0 ? y0 : y0 + (y1 - y0) * sa;
            double qbx = sb == 1.0 ? x1 : x0 + (x1 - x0) * sb, qby = sb == 1.0 ? y1 : y0 + (y1 - y0) * sb;
            if (D == 0.0) return PyLong_FromLong(-1); /* the exact fixed-angle test: Python's */
            double fa = a0 + D * sa, fb = a0 + D * sb;
            double lo = (fa < fb ? fa : fb) - h->slack, hi = (fa < fb ? fb : fa) + h->slack;
            budget--;
            n_sweeps++;
            if (!sweep_hits(h, qax, qay, qbx, qby, lo, hi)) continue;
            double sm = 0.5 * (sa + sb);
            double xm = x0 + (x1 - x0) * sm, ym = y0 + (y1 - y0) * sm, am = wrap_angle(a0 + D * sm);
            int pr = pose_test(h, grids, xm, ym, am);
            if (pr == -2) return NULL;
            if (pr == 0) {
                n_coll++;
                result = 0; /* a real collision */
                break;
            }
            if (pr < 0) return PyLong_FromLong(-1);
            double size = h->radius * (hi - lo) + hypot(qbx - qax, qby - qay);
            if (size <= h->floor_len * (1.0 + 1e-6) || budget <= 0 || !(sa < sm && sm < sb))
                return PyLong_FromLong(-1); /* the floor: the Python path counts and answers it */
            if (top + 2 > h->stack_cap) return PyLong_FromLong(-1);
            h->stack[2 * top] = sm, h->stack[2 * top + 1] = sb;
            h->stack[2 * top + 2] = sa, h->stack[2 * top + 3] = sm;
            top += 2;
        }
    }
    PyObject *d = h->checks;
    if (fast_add_count(d, "submotions", n_sub) < 0 || fast_add_count(d, "slab_certified", n_cert) < 0
        || fast_add_count(d, "refined", n_ref) < 0 || fast_add_count(d, "sweeps", n_sweeps) < 0
        || fast_add_count(d, "motion_collisions", n_coll) < 0)
        return NULL;
    return PyLong_FromLong(result);
}
