/* The optional compiled fast path of the C-space queries (cspace.compiled.fastpath loads it).

   It owns one thing: deciding, at float speed, the point and segment queries that a
   float filter can CERTIFY, and saying "undecided" (-1) for every other one, which
   the pure-Python path then answers exactly (rationals). It never guesses: every
   answer it gives is the exact answer, so the two paths answer identically.

   - orient() (_fast.h): Shewchuk's stage-A filter, the same bound as cspace/kernel/polygons/predicates.py
     (|fl(det) - det| <= (3 + 16 eps) eps (|left| + |right|), valid when no product
     underflows: detsum > 1e-280, and detsum finite), the exact zero when a factor of
     each product is an exact zero difference, and the sign of a determinant whose
     operations were all exact. Anything else: undecided. FP contraction (FMA) is
     switched off so each product is rounded once, as the bound assumes.
   - seg_piece(), point_piece(): the separating-axis narrow phase of cspace/kernel/polygons/pieces.py
     (a closed segment and a closed convex CCW piece are disjoint iff an edge line of
     the piece or the segment's own line separates them strictly), each axis decided
     only from certified signs; a certain separating axis proves "disjoint", all axes
     certainly non-separating prove "meet", anything else is undecided.
   - the grid walk: every cell that can hold a point of the segment (see walk_cells
     for why the cover is conservative); a FREE cell meets no piece, a BLOCKED cell
     lies inside its blocker, a MIXED cell lists every piece that may meet it. So
     every piece the segment meets is tested, each at most once (a stamp per piece).
*/
#include "_fast.h"

enum { FREE = 0, MIXED = 1, BLOCKED = 2 };

typedef struct {
    int64_t nx, ny, npieces;
    double x0, y0, iw, ih, cw, ch, m;  /* grid origin, 1 / cell size, cell size, margin */
    double xmin, xmax, ymin, ymax;      /* the C-space's bounds */
    uint8_t *state;                     /* per cell: FREE, MIXED, BLOCKED */
    int64_t *blocker, *starts, *cand;   /* BLOCKED cell's piece; MIXED cell's candidates */
    int64_t *offsets;                   /* piece k: vertices offsets[k] .. offsets[k+1] - 1 */
    double *xy;                         /* vertices, x y interleaved, CCW */
    uint32_t *stamp;                    /* per piece: the query that last tested it */
    uint32_t gen;
    Py_buffer view[6];                  /* the arrays above but stamp, held (read-only), not copied */
    int nview;
} Grid;

/* The cell of a floored grid coordinate f, clamped to 0 .. n - 1 (f is never NaN here). */
static inline int64_t clamp_cell(double f, int64_t n)
{
    return f < 0.0 ? 0 : (f > (double)(n - 1) ? n - 1 : (int64_t)f);
}

/* Does the closed segment a-b meet closed piece k? 1 yes, 0 no, UNDECIDED. */
static int seg_piece(const Grid *g, int64_t k, double ax, double ay, double bx, double by)
{
    const double *v = g->xy + 2 * g->offsets[k];
    int64_t n = g->offsets[k + 1] - g->offsets[k];
    int unknown = 0;
    double px = v[2 * (n - 1)], py = v[2 * (n - 1) + 1];
    for (int64_t e = 0; e < n; e++) {
        double qx = v[2 * e], qy = v[2 * e + 1];
        int sa = orient(px, py, qx, qy, ax, ay);
        int sb = orient(px, py, qx, qy, bx, by);
        if (sa == -1 && sb == -1) return 0; /* both ends strictly outside this edge */
        if (!(sa == 0 || sa == 1 || sb == 0 || sb == 1)) unknown = 1; /* maybe separating */
        px = qx;
        py = qy;
    }
    if (ax == bx && ay == by) return unknown ? UNDECIDED : 1; /* a point: edge axes only */
    /* The segment's line: separating iff every vertex is strictly on one side. */
    int all_left = 1, all_right = 1, maybe_left = 1, maybe_right = 1;
    for (int64_t e = 0; e < n; e++) {
        int s = orient(ax, ay, bx, by, v[2 * e], v[2 * e + 1]);
        if (s != 1) all_left = 0;
        if (s != -1) all_right = 0;
        if (s == 0 || s == -1) maybe_left = 0;
        if (s == 0 || s == 1) maybe_right = 0;
    }
    if (all_left || all_right) return 0;
    if (maybe_left || maybe_right) unknown = 1;
    return unknown ? UNDECIDED : 1;
}

/* Is (x, y) in closed piece k? 1 yes, 0 no, UNDECIDED. */
static int point_piece(const Grid *g, int64_t k, double x, double y)
{
    const double *v = g->xy + 2 * g->offsets[k];
    int64_t n = g->offsets[k + 1] - g->offsets[k];
    int unknown = 0;
    double px = v[2 * (n - 1)], py = v[2 * (n - 1) + 1];
    for (int64_t e = 0; e < n; e++) {
        double qx = v[2 * e], qy = v[2 * e + 1];
        int s = orient(px, py, qx, qy, x, y);
        if (s == -1) return 0; /* strictly outside this edge */
        if (s == UNDECIDED) unknown = 1;
        px = qx;
        py = qy;
    }
    return unknown ? UNDECIDED : 1;
}

static void grid_release(Grid *g)
{
    for (int k = 0; k < g->nview; k++) PyBuffer_Release(&g->view[k]);
    PyMem_Free(g->stamp);
    PyMem_Free(g);
}

static void grid_free(PyObject *cap)
{
    Grid *g = (Grid *)PyCapsule_GetPointer(cap, "cspace.compiled._fast.Grid");
    if (g) grid_release(g);
}

/* A private copy of a buffer of `count` items of `size` bytes (the caller owns the arrays;
   also the copy of _se2motion.c's and _carmotion.c's handles). */
void *fast_copy_buffer(PyObject *obj, Py_ssize_t size, Py_ssize_t count, const char *name)
{
    Py_buffer view;
    if (PyObject_GetBuffer(obj, &view, PyBUF_C_CONTIGUOUS) < 0) return NULL;
    void *out = NULL;
    if (view.len != size * count) {
        PyErr_Format(PyExc_ValueError, "_fast: %s has %zd bytes, expected %zd", name, view.len, size * count);
    } else {
        out = PyMem_Malloc(view.len ? view.len : 1);
        if (!out) PyErr_NoMemory();
        else memcpy(out, view.buf, view.len);
    }
    PyBuffer_Release(&view);
    return out;
}

/* The counters' keys as interned strings, made once per key (the callers pass string
   literals: the same pointer at every call), so that a count makes no string of its own. */
#define KEY_CACHE 32
static const char *key_names[KEY_CACHE];
static PyObject *key_objs[KEY_CACHE];

/* The key's string: borrowed from the cache, or (*owned = 1) a new reference when it is full. */
static PyObject *count_key(const char *key, int *owned)
{
    int i = 0;
    *owned = 0;
    for (; i < KEY_CACHE && key_names[i]; i++)
        if (key_names[i] == key) return key_objs[i];
    PyObject *k = PyUnicode_InternFromString(key);
    if (k && i < KEY_CACHE) { /* kept for the life of the process, as the literal is */
        key_names[i] = key;
        key_objs[i] = k;
    } else if (k) {
        *owned = 1;
    }
    return k;
}

/* d[key] += delta (a counter of the C-space's checks dict, 0 when absent); 0, or -1 on error. */
int fast_add_count(PyObject *d, const char *key, long delta)
{
    if (!delta) return 0;
    int owned, r = -1;
    PyObject *k = count_key(key, &owned);
    if (!k) return -1;
    PyObject *old = PyDict_GetItemWithError(d, k); /* borrowed */
    long v = old ? PyLong_AsLong(old) : 0;
    if (!(PyErr_Occurred() || (old && v == -1 && PyErr_Occurred()))) {
        PyObject *n = PyLong_FromLong(v + delta);
        if (n) {
            r = PyDict_SetItem(d, k, n);
            Py_DECREF(n);
        }
    }
    if (owned) Py_DECREF(k);
    return r;
}

/* A view of `count` items of `size` bytes held by g until its release (the caller hands
   over read-only arrays that live as long as the handle: no copy). */
static void *hold_buffer(Grid *g, PyObject *obj, Py_ssize_t size, Py_ssize_t count, const char *name)
{
    Py_buffer *view = &g->view[g->nview];
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS) < 0) return NULL;
    g->nview++;
    if (view->len != size * count) {
        PyErr_Format(PyExc_ValueError, "_fast.grid: %s has %zd bytes, expected %zd", name, view->len, size * count);
        return NULL;
    }
    static char empty[16];
    return view->len ? view->buf : (void *)empty;
}

/* grid(state, blocker, starts, cand, offsets, xy, nx, ny, x0, y0, iw, ih, cw, ch, margin,
        xmin, xmax, ymin, ymax) -> capsule. Arrays: uint8 cells, int64 cells, int64 cells + 1,
   int64 candidates, int64 pieces + 1, float64 2 x vertices; held, not copied: the caller
   makes them read-only (GridIndex and PieceSet do), and the handle keeps them alive. */
static PyObject *py_grid(PyObject *self, PyObject *args)
{
    PyObject *st, *bl, *sts, *ca, *of, *xy;
    Py_ssize_t nx, ny;
    double x0, y0, iw, ih, cw, ch, m, xmin, xmax, ymin, ymax;
    if (!PyArg_ParseTuple(args, "OOOOOOnnddddddddddd", &st, &bl, &sts, &ca, &of, &xy, &nx, &ny, &x0, &y0, &iw,
                          &ih, &cw, &ch, &m, &xmin, &xmax, &ymin, &ymax))
        return NULL;
    if (nx < 1 || ny < 1) {
        PyErr_SetString(PyExc_ValueError, "_fast.grid: empty grid");
        return NULL;
    }
    Grid *g = PyMem_Calloc(1, sizeof(Grid));
    if (!g) return PyErr_NoMemory();
    g->nx = nx, g->ny = ny, g->x0 = x0, g->y0 = y0, g->iw = iw, g->ih = ih, g->cw = cw, g->ch = ch, g->m = m;
    g->xmin = xmin, g->xmax = xmax, g->ymin = ymin, g->ymax = ymax;
    Py_ssize_t cells = nx * ny;
    Py_buffer ov, cv;
    if (PyObject_GetBuffer(of, &ov, PyBUF_C_CONTIGUOUS) < 0) goto fail;
    g->npieces = ov.len / 8 - 1;
    PyBuffer_Release(&ov);
    if (PyObject_GetBuffer(ca, &cv, PyBUF_C_CONTIGUOUS) < 0) goto fail;
    Py_ssize_t ncand = cv.len / 8;
    PyBuffer_Release(&cv);
    if (g->npieces < 0) {
        PyErr_SetString(PyExc_ValueError, "_fast.grid: offsets is empty");
        goto fail;
    }
    if (!(g->state = hold_buffer(g, st, 1, cells, "state"))) goto fail;
    if (!(g->blocker = hold_buffer(g, bl, 8, cells, "blocker"))) goto fail;
    if (!(g->starts = hold_buffer(g, sts, 8, cells + 1, "starts"))) goto fail;
    if (!(g->cand = hold_buffer(g, ca, 8, ncand, "cand"))) goto fail;
    if (!(g->offsets = hold_buffer(g, of, 8, g->npieces + 1, "offsets"))) goto fail;
    if (g->offsets[0] != 0 || g->offsets[g->npieces] < 0) {
        PyErr_SetString(PyExc_ValueError, "_fast.grid: offsets do not start at 0");
        goto fail;
    }
    if (!(g->xy = hold_buffer(g, xy, 16, g->offsets[g->npieces], "xy"))) goto fail;
    for (int64_t k = 0; k < g->npieces; k++) { /* every piece has a vertex; indices in range */
        if (g->offsets[k + 1] <= g->offsets[k]) {
            PyErr_SetString(PyExc_ValueError, "_fast.grid: a piece without vertices");
            goto fail;
        }
    }
    for (Py_ssize_t c = 0; c < cells; c++) {
        if ((g->state[c] == BLOCKED && (g->blocker[c] < 0 || g->blocker[c] >= g->npieces))
            || g->starts[c] < 0 || g->starts[c] > g->starts[c + 1] || g->starts[c + 1] > ncand) {
            PyErr_SetString(PyExc_ValueError, "_fast.grid: inconsistent cells");
            goto fail;
        }
    }
    for (Py_ssize_t t = 0; t < ncand; t++) {
        if (g->cand[t] < 0 || g->cand[t] >= g->npieces) {
            PyErr_SetString(PyExc_ValueError, "_fast.grid: a candidate out of range");
            goto fail;
        }
    }
    if (!(g->stamp = PyMem_Calloc(g->npieces ? g->npieces : 1, sizeof(uint32_t)))) {
        PyErr_NoMemory();
        goto fail;
    }
    PyObject *cap = PyCapsule_New(g, "cspace.compiled._fast.Grid", grid_free);
    if (cap) return cap;
fail:
    grid_release(g);
    return NULL;
}

static Grid *get_grid(PyObject *cap)
{
    return (Grid *)PyCapsule_GetPointer(cap, "cspace.compiled._fast.Grid");
}

/* A fast call's argument count: 0 if it is `want`, else -1 with a TypeError showing `usage`
   (checked before any argument is read: the handles first, then get_doubles). */
static inline int check_nargs(Py_ssize_t nargs, Py_ssize_t want, const char *usage)
{
    if (nargs == want) return 0;
    PyErr_SetString(PyExc_TypeError, usage);
    return -1;
}

static int get_doubles(PyObject *const *args, Py_ssize_t n, double *out)
{
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(args[i]);
        if (out[i] == -1.0 && PyErr_Occurred()) return -1;
    }
    return 0;
}

/* A new query: pieces tested by earlier queries count as untested again. */
static void next_stamp(Grid *g)
{
    if (++g->gen == 0) {
        memset(g->stamp, 0, (size_t)g->npieces * sizeof(uint32_t));
        g->gen = 1;
    }
}

/* Test the pieces of cell c not yet tested in this query: 0 a hit, 1 none, UNDECIDED. */
static int test_cell(Grid *g, int64_t c, double ax, double ay, double bx, double by, int *tested)
{
    uint8_t s = g->state[c];
    if (s == FREE) return 1;
    int64_t one = 0;
    const int64_t *ks;
    int64_t nk;
    if (s == BLOCKED) {
        one = g->blocker[c];
        ks = &one;
        nk = 1;
    } else {
        ks = g->cand + g->starts[c];
        nk = g->starts[c + 1] - g->starts[c];
    }
    int unknown = 0;
    for (int64_t t = 0; t < nk; t++) {
        int64_t k = ks[t];
        if (g->stamp[k] == g->gen) continue;
        g->stamp[k] = g->gen;
        *tested = 1;
        int r = seg_piece(g, k, ax, ay, bx, by);
        if (r == 1) return 0;
        if (r == UNDECIDED) unknown = 1;
    }
    return unknown ? UNDECIDED : 1;
}

/* segment(grid, ax, ay, bx, by) -> 1 free (no piece tested), 3 free (pieces tested),
   0 not free, -1 undecided. The caller has checked that both ends are finite and in
   the bounds (the bounds box is convex, so the whole segment is).

   The cells walked cover the segment (why the cover is conservative): for each grid
   column i0..i1 (the segment's x-range widened by the margin m), the segment's y-range
   over the column's x-interval widened by m, then its rows widened by m. The margin
   (1e-9 x extent + 64 eps x the largest coordinate) exceeds by far the rounding of
   every quantity here (column edges x0 + i cw, the slope, y at a column edge: each a
   few eps of the coordinates or of the extent), and of the cell location of the
   build's classification, so every cell holding a point of the segment is walked.
   Where y at a column edge is not finite (the slope overflowed), the column gets the
   segment's whole y-range. */
static int grid_segment(Grid *g, double ax, double ay, double bx, double by)
{
    double m = g->m;
    if (!(isfinite(ax) && isfinite(ay) && isfinite(bx) && isfinite(by))) return -1;
    if (!(g->xmin <= ax && ax <= g->xmax && g->ymin <= ay && ay <= g->ymax && g->xmin <= bx && bx <= g->xmax
          && g->ymin <= by && by <= g->ymax))
        return -1; /* the caller's case */
    next_stamp(g);
    double xlo = ax < bx ? ax : bx, xhi = ax < bx ? bx : ax;
    double ylo = ay < by ? ay : by, yhi = ay < by ? by : ay;
    double fi0 = floor((xlo - m - g->x0) * g->iw), fi1 = floor((xhi + m - g->x0) * g->iw);
    if (!(fi0 <= (double)(g->nx - 1) && fi1 >= 0.0)) return -1; /* off the grid: never in bounds */
    int64_t i0 = fi0 < 0.0 ? 0 : (int64_t)fi0;
    int64_t i1 = fi1 > (double)(g->nx - 1) ? g->nx - 1 : (int64_t)fi1;
    double slope = bx != ax ? (by - ay) / (bx - ax) : 0.0;
    int unknown = 0, tested = 0;
    for (int64_t i = i0; i <= i1; i++) {
        double lo = g->x0 + (double)i * g->cw - m, hi = g->x0 + (double)(i + 1) * g->cw + m;
        if (lo < xlo) lo = xlo;
        if (hi > xhi) hi = xhi;
        double y_lo = ylo, y_hi = yhi;
        if (bx != ax) {
            double ya = ay + (lo - ax) * slope, yb = ay + (hi - ax) * slope;
            /* A nearly vertical segment's slope can overflow (dx subnormal): 0 * inf is NaN,
               and the clipped range would walk no cell at all. Then the segment's whole
               y-range is walked, which is always a cover. */
            if (isfinite(ya) && isfinite(yb)) {
                double a = ya < yb ? ya : yb, b = ya < yb ? yb : ya;
                if (a > y_lo) y_lo = a;
                if (b < y_hi) y_hi = b;
            }
        }
        double fr0 = floor((y_lo - m - g->y0) * g->ih), fr1 = floor((y_hi + m - g->y0) * g->ih);
        if (!(fr0 == fr0 && fr1 == fr1)) return -1; /* NaN: never on finite input */
        int64_t r0 = clamp_cell(fr0, g->ny);
        int64_t r1 = clamp_cell(fr1, g->ny);
        for (int64_t r = r0; r <= r1; r++) {
            int res = test_cell(g, r * g->nx + i, ax, ay, bx, by, &tested);
            if (res == 0) return 0;
            if (res == UNDECIDED) unknown = 1;
        }
    }
    return unknown ? -1 : (tested ? 3 : 1);
}

static PyObject *py_segment(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double q[4];
    if (check_nargs(nargs, 5, "segment(grid, ax, ay, bx, by)") < 0) return NULL;
    Grid *g = get_grid(args[0]);
    if (!g || get_doubles(args + 1, 4, q) < 0) return NULL;
    return PyLong_FromLong(grid_segment(g, q[0], q[1], q[2], q[3]));
}

/* For _se2motion.c (declared in _fast.h): the segment and point tests on a grid capsule,
   -2 with an exception set when it is not one. */
int fast_grid_segment(PyObject *cap, double ax, double ay, double bx, double by)
{
    Grid *g = get_grid(cap);
    return g ? grid_segment(g, ax, ay, bx, by) : -2;
}

/* Is (x, y) a free state? 1 free, 0 not free, -1 undecided. */
static int point_test(const Grid *g, double x, double y)
{
    if (!(isfinite(x) && isfinite(y))) return -1;
    if (!(g->xmin <= x && x <= g->xmax && g->ymin <= y && y <= g->ymax)) return 0;
    double fi = floor((x - g->x0) * g->iw), fj = floor((y - g->y0) * g->ih);
    int64_t i = clamp_cell(fi, g->nx);
    int64_t j = clamp_cell(fj, g->ny);
    int64_t c = j * g->nx + i;
    uint8_t s = g->state[c];
    if (s == FREE) return 1;
    if (s == BLOCKED) return 0;
    int unknown = 0;
    for (int64_t t = g->starts[c]; t < g->starts[c + 1]; t++) {
        int r = point_piece(g, g->cand[t], x, y);
        if (r == 1) return 0;
        if (r == UNDECIDED) unknown = 1;
    }
    return unknown ? -1 : 1;
}

/* point(grid, x, y) -> 1 free, 0 not free, -1 undecided (non-finite, or a sign the
   filter cannot certify). Outside the closed bounds: not free. The cell is located as
   the build's classification covers it: the margin dwarfs the rounding of the index. */
static PyObject *py_point(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double q[2];
    if (check_nargs(nargs, 3, "point(grid, x, y)") < 0) return NULL;
    Grid *g = get_grid(args[0]);
    if (!g || get_doubles(args + 1, 2, q) < 0) return NULL;
    return PyLong_FromLong(point_test(g, q[0], q[1]));
}

int fast_grid_point(PyObject *cap, double x, double y)
{
    Grid *g = get_grid(cap);
    return g ? point_test(g, x, y) : -2;
}

/* orient(ax, ay, bx, by, cx, cy) -> the filter's sign, or 2 when it cannot certify one. */
static PyObject *py_orient(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double q[6];
    if (check_nargs(nargs, 6, "orient(ax, ay, bx, by, cx, cy)") < 0) return NULL;
    if (get_doubles(args, 6, q) < 0) return NULL;
    return PyLong_FromLong(orient(q[0], q[1], q[2], q[3], q[4], q[5]));
}

/* ---- SE(2): the float filter of the exact pose test (cspace/se2/cspace.py, _pair_filter) ----

   The same IEEE operations in the same order as the Python filter (so the same doubles
   and the same decisions, each certified there: a side is taken only with |g| above
   the slab pad times |n|, far above the float error of g). Pairs the filter leaves
   open, and anything unusual, make the routine answer "undecided": Python then runs
   its whole exact test, rational sums included. */

typedef struct {
    int64_t n_obs, n_rob, n, n_entries;
    double xmin, xmax, ymin, ymax, pad, gx0, gy0, giw, gih;
    int64_t *o_off;  /* obstacle i: edges and vertices o_off[i] .. o_off[i + 1] - 1 */
    double *o_edge;  /* per edge: outward normal x, y, offset, |n| */
    double *o_pt;    /* per vertex: x, y */
    int64_t *r_off;  /* robot piece j: vertices r_off[j] .. r_off[j + 1] - 1 */
    double *r_pt;    /* body-frame vertices x, y */
    double *r_nrm;   /* body-frame normal of the edge ending at each vertex: x, y, |n| */
    int64_t *starts; /* pair-grid cell c: entries starts[c] .. starts[c + 1] - 1 */
    int64_t *e_ij;   /* per entry: obstacle i, robot piece j */
    double *e_box;   /* per entry: the reach box x0, y0, x1, y1 */
    double *rot;     /* scratch: turned vertices x, y per robot vertex */
    double *axes;    /* scratch: per robot vertex nx, ny, rx, ry, |n| */
    uint32_t *stamp; /* per robot piece: the query that last turned it */
    uint32_t gen;
} SE2;

static void se2_release(SE2 *h)
{
    PyMem_Free(h->o_off);
    PyMem_Free(h->o_edge);
    PyMem_Free(h->o_pt);
    PyMem_Free(h->r_off);
    PyMem_Free(h->r_pt);
    PyMem_Free(h->r_nrm);
    PyMem_Free(h->starts);
    PyMem_Free(h->e_ij);
    PyMem_Free(h->e_box);
    PyMem_Free(h->rot);
    PyMem_Free(h->axes);
    PyMem_Free(h->stamp);
    PyMem_Free(h);
}

static void se2_free(PyObject *cap)
{
    SE2 *h = (SE2 *)PyCapsule_GetPointer(cap, "cspace.compiled._fast.SE2");
    if (h) se2_release(h);
}

/* se2(o_off, o_edge, o_pt, r_off, r_pt, r_nrm, starts, e_ij, e_box, n, n_obs, n_rob,
       n_entries, xmin, xmax, ymin, ymax, pad, gx0, gy0, giw, gih) -> capsule (copies). */
static PyObject *py_se2(PyObject *self, PyObject *args)
{
    PyObject *a[9];
    Py_ssize_t n, n_obs, n_rob, n_ent;
    double v[9];
    if (!PyArg_ParseTuple(args, "OOOOOOOOOnnnnddddddddd", &a[0], &a[1], &a[2], &a[3], &a[4], &a[5], &a[6], &a[7],
                          &a[8], &n, &n_obs, &n_rob, &n_ent, &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6],
                          &v[7], &v[8]))
        return NULL;
    SE2 *h = PyMem_Calloc(1, sizeof(SE2));
    if (!h) return PyErr_NoMemory();
    h->n = n, h->n_obs = n_obs, h->n_rob = n_rob, h->n_entries = n_ent;
    h->xmin = v[0], h->xmax = v[1], h->ymin = v[2], h->ymax = v[3], h->pad = v[4];
    h->gx0 = v[5], h->gy0 = v[6], h->giw = v[7], h->gih = v[8];
    if (n < 1 || n_obs < 0 || n_rob < 1 || n_ent < 0) {
        PyErr_SetString(PyExc_ValueError, "_fast.se2: bad sizes");
        goto fail;
    }
    if (!(h->o_off = fast_copy_buffer(a[0], 8, n_obs + 1, "o_off"))) goto fail;
    if (!(h->r_off = fast_copy_buffer(a[3], 8, n_rob + 1, "r_off"))) goto fail;
    int64_t no = h->o_off[n_obs], nr = h->r_off[n_rob];
    for (int64_t i = 0; i < n_obs; i++)
        if (h->o_off[i + 1] <= h->o_off[i]) goto bad;
    for (int64_t j = 0; j < n_rob; j++)
        if (h->r_off[j + 1] <= h->r_off[j]) goto bad;
    if (!(h->o_edge = fast_copy_buffer(a[1], 32, no, "o_edge"))) goto fail;
    if (!(h->o_pt = fast_copy_buffer(a[2], 16, no, "o_pt"))) goto fail;
    if (!(h->r_pt = fast_copy_buffer(a[4], 16, nr, "r_pt"))) goto fail;
    if (!(h->r_nrm = fast_copy_buffer(a[5], 24, nr, "r_nrm"))) goto fail;
    if (!(h->starts = fast_copy_buffer(a[6], 8, n * n + 1, "starts"))) goto fail;
    if (!(h->e_ij = fast_copy_buffer(a[7], 16, n_ent, "e_ij"))) goto fail;
    if (!(h->e_box = fast_copy_buffer(a[8], 32, n_ent, "e_box"))) goto fail;
    for (int64_t c = 0; c < n * n; c++)
        if (h->starts[c] < 0 || h->starts[c] > h->starts[c + 1] || h->starts[c + 1] > n_ent) goto bad;
    for (int64_t t = 0; t < n_ent; t++)
        if (h->e_ij[2 * t] < 0 || h->e_ij[2 * t] >= n_obs || h->e_ij[2 * t + 1] < 0 || h->e_ij[2 * t + 1] >= n_rob)
            goto bad;
    h->rot = PyMem_Malloc(16 * (size_t)nr);
    h->axes = PyMem_Malloc(40 * (size_t)nr);
    h->stamp = PyMem_Calloc((size_t)n_rob, sizeof(uint32_t));
    if (!h->rot || !h->axes || !h->stamp) {
        PyErr_NoMemory();
        goto fail;
    }
    PyObject *cap = PyCapsule_New(h, "cspace.compiled._fast.SE2", se2_free);
    if (cap) return cap;
    goto fail;
bad:
    PyErr_SetString(PyExc_ValueError, "_fast.se2: inconsistent arrays");
fail:
    se2_release(h);
    return NULL;
}

/* _pair_filter of cspace/se2/cspace.py: +1 outside, -1 inside, 0 unsure (same operations). */
static int pair_filter(const SE2 *h, int64_t i, int64_t j, double x, double y, double margin)
{
    int inside = 1;
    int64_t o0 = h->o_off[i], o1 = h->o_off[i + 1], r0 = h->r_off[j], r1 = h->r_off[j + 1];
    for (int64_t e = o0; e < o1; e++) { /* O's normals */
        const double *E = h->o_edge + 4 * e;
        double nx = E[0], ny = E[1], off = E[2], ln = E[3];
        double lo = HUGE_VAL;
        for (int64_t t = r0; t < r1; t++) {
            double vv = nx * h->rot[2 * t] + ny * h->rot[2 * t + 1];
            if (vv < lo) lo = vv;
        }
        double g = nx * x + ny * y - off + lo;
        double m = margin * ln;
        if (g > m) return 1;
        if (g >= -m) inside = 0;
    }
    for (int64_t t = r0; t < r1; t++) { /* -R''s normals */
        const double *A = h->axes + 5 * t;
        double nx = A[0], ny = A[1], rx = A[2], ry = A[3], ln = A[4];
        double hi = -HUGE_VAL;
        for (int64_t e = o0; e < o1; e++) {
            double vv = nx * h->o_pt[2 * e] + ny * h->o_pt[2 * e + 1];
            if (vv > hi) hi = vv;
        }
        double g = nx * x + ny * y - hi + (nx * rx + ny * ry);
        double m = margin * ln;
        if (g > m) return 1;
        if (g >= -m) inside = 0;
    }
    return inside ? -1 : 0;
}

static int se2_filter(SE2 *h, double x, double y, double c, double sn);

/* se2_pose(handle, x, y, c, s) -> 1 free, 0 not free, -1 undecided: the filter stage of
   SE2CSpace._exact at the angle whose math.cos and math.sin are c and s (computed by
   the caller, so the turned robot is the Python path's to the last bit). */
static PyObject *py_se2_pose(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double q[4];
    if (check_nargs(nargs, 5, "se2_pose(handle, x, y, c, s)") < 0) return NULL;
    SE2 *h = (SE2 *)PyCapsule_GetPointer(args[0], "cspace.compiled._fast.SE2");
    if (!h || get_doubles(args + 1, 4, q) < 0) return NULL;
    return PyLong_FromLong(se2_filter(h, q[0], q[1], q[2], q[3]));
}

/* se2_slow(slab grid, handle, x, y, c, s) -> the slow path of SE2CSpace.pose_test in
   one call: 1 free in the slab's C-space (free at every angle of the slab), else the
   filter stage of the exact test: 2 free, 0 not free; -1 undecided (Python decides). */
static PyObject *py_se2_slow(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double q[4];
    if (check_nargs(nargs, 6, "se2_slow(grid, handle, x, y, c, s)") < 0) return NULL;
    Grid *g = get_grid(args[0]);
    if (!g) return NULL;
    SE2 *h = (SE2 *)PyCapsule_GetPointer(args[1], "cspace.compiled._fast.SE2");
    if (!h || get_doubles(args + 2, 4, q) < 0) return NULL;
    if (point_test(g, q[0], q[1]) == 1) return PyLong_FromLong(1);
    int r = se2_filter(h, q[0], q[1], q[2], q[3]);
    return PyLong_FromLong(r == 1 ? 2 : r);
}

/* The filter stage of the exact pose test: 1 free, 0 not free, -1 undecided. */
static int se2_filter(SE2 *h, double x, double y, double c, double sn)
{
    if (!(isfinite(x) && isfinite(y) && isfinite(c) && isfinite(sn))) return -1;
    if (!(h->xmin <= x && x <= h->xmax && h->ymin <= y && y <= h->ymax)) return 0;
    if (++h->gen == 0) {
        memset(h->stamp, 0, (size_t)h->n_rob * sizeof(uint32_t));
        h->gen = 1;
    }
    double fi = floor((x - h->gx0) * h->giw), fj = floor((y - h->gy0) * h->gih);
    int64_t ci = clamp_cell(fi, h->n);
    int64_t cj = clamp_cell(fj, h->n);
    int64_t cell = cj * h->n + ci;
    int unknown = 0;
    for (int64_t t = h->starts[cell]; t < h->starts[cell + 1]; t++) {
        const double *B = h->e_box + 4 * t;
        if (x < B[0] || x > B[2] || y < B[1] || y > B[3]) continue; /* beyond this pair's reach */
        int64_t i = h->e_ij[2 * t], j = h->e_ij[2 * t + 1];
        if (h->stamp[j] != h->gen) { /* turn robot piece j: rotate() in scalars */
            h->stamp[j] = h->gen;
            for (int64_t u = h->r_off[j]; u < h->r_off[j + 1]; u++) {
                double vx = h->r_pt[2 * u], vy = h->r_pt[2 * u + 1];
                double rx = vx * c - vy * sn + 0.0, ry = vx * sn + vy * c + 0.0;
                const double *N = h->r_nrm + 3 * u;
                double *A = h->axes + 5 * u;
                h->rot[2 * u] = rx;
                h->rot[2 * u + 1] = ry;
                A[0] = -(N[0] * c - N[1] * sn);
                A[1] = -(N[0] * sn + N[1] * c);
                A[2] = rx;
                A[3] = ry;
                A[4] = N[2];
            }
        }
        int side = pair_filter(h, i, j, x, y, h->pad);
        if (side < 0) return 0; /* certainly inside a sum */
        if (side == 0) unknown = 1;
    }
    return unknown ? -1 : 1;
}

/* For _se2motion.c: the filter stage of the exact pose test on an SE(2) capsule (1 free,
   0 not free, -1 undecided; -2 with an exception set when it is not one). */
int fast_se2_filter(PyObject *cap, double x, double y, double c, double sn)
{
    SE2 *h = (SE2 *)PyCapsule_GetPointer(cap, "cspace.compiled._fast.SE2");
    return h ? se2_filter(h, x, y, c, sn) : -2;
}

static PyMethodDef methods[] = {
    {"grid", py_grid, METH_VARARGS, "Hold a grid index and its packed pieces (read-only); returns a handle."},
    {"segment", (PyCFunction)(void (*)(void))py_segment, METH_FASTCALL,
     "segment(grid, ax, ay, bx, by): 1 or 3 free, 0 not free, -1 undecided."},
    {"point", (PyCFunction)(void (*)(void))py_point, METH_FASTCALL,
     "point(grid, x, y): 1 free, 0 not free, -1 undecided."},
    {"orient", (PyCFunction)(void (*)(void))py_orient, METH_FASTCALL,
     "orient(ax, ay, bx, by, cx, cy): the float filter's sign of orient2d, 2 if undecided."},
    {"assemble", fast_assemble, METH_VARARGS,
     "assemble(cc, cp, cm, inside, npieces, state, blocker, starts, cand, masks): the grid from its entries (_cells.c)."},
    {"entries", fast_entries, METH_VARARGS, "The grid build's classified entries from packed pieces (cspace/compiled/_cells.c)."},
    {"pair_sums", fast_pair_sums, METH_VARARGS,
     "pair_sums(a_xy, a_off, b_xy, b_off, out_xy, out_count): the C-space build's pair sums (see _build.c)."},
    {"contained", fast_contained, METH_VARARGS,
     "contained(xy, off, qs, ps, out): the prune's containment test of candidate pairs (_build.c)."},
    {"chords", fast_chords, METH_VARARGS,
     "chords(Q, sizes, long_edge, tolerance, out_R, out_n, out_sag): the grid build's chord polygons (_chords.c)."},
    {"se2", py_se2, METH_VARARGS, "Copy the SE(2) pose filter's data; returns a handle."},
    {"se2_pose", (PyCFunction)(void (*)(void))py_se2_pose, METH_FASTCALL,
     "se2_pose(handle, x, y, c, s): 1 free, 0 not free, -1 undecided (the exact test's float filter)."},
    {"se2_slow", (PyCFunction)(void (*)(void))py_se2_slow, METH_FASTCALL,
     "se2_slow(grid, handle, x, y, c, s): 1 free in the slab, 2 free, 0 not free, -1 undecided."},
    {"se2_motion_handle", fast_se2_motion_handle, METH_VARARGS,
     "se2_motion_handle(...): the data of the compiled SE(2) motion check (_se2motion.c)."},
    {"se2_motion", (PyCFunction)(void (*)(void))fast_se2_motion, METH_FASTCALL,
     "se2_motion(handle, grids, x0, y0, a0, x1, y1, a1): 1 free, 0 not free, -1 undecided, -2-k slab k (_se2motion.c)."},
    {"car_handle", fast_car_handle, METH_VARARGS,
     "car_handle(...): the data of the compiled car curve check (_carmotion.c)."},
    {"car_curve", (PyCFunction)(void (*)(void))fast_car_curve, METH_FASTCALL,
     "car_curve(handle, grids, x, y, th, segments, radius): (r, x, y, th), r 1 free, 0 not, -1 undecided, -2-k slab k (_carmotion.c)."},
    {"car_motion", (PyCFunction)(void (*)(void))fast_car_motion, METH_FASTCALL,
     "car_motion(handle, grids, x0, y0, th0, x1, y1, th1, radius, dubins, longest, turns): car_curve of the "
     "shortest curve's segments, computed here with car_curves' doubles (_carmotion.c)."},
    {"car_connect", (PyCFunction)(void (*)(void))fast_car_connect, METH_FASTCALL,
     "car_connect(x0, y0, th0, x1, y1, th1, radius, xmin, xmax, ymin, ymax, range, seed, iterations, motion_free): "
     "(path or None, iterations, motions): a Reeds-Shepp car's RRT-Connect (_carrrt.c)."},
    {"reeds_shepp_word", (PyCFunction)(void (*)(void))fast_reeds_shepp_word, METH_FASTCALL,
     "reeds_shepp_word(x, y, phi): reeds_shepp.py's word and lengths, the same doubles, or None (_carwords.c)."},
    {"dubins_word", (PyCFunction)(void (*)(void))fast_dubins_word, METH_FASTCALL,
     "dubins_word(d, alpha, beta): dubins.py's word and lengths, the same doubles, or None (_carwords.c)."},
    {"disc_cost_handle", fast_disc_cost_handle, METH_VARARGS,
     "disc_cost_handle(unit, sigma, Cost, at, log2_slots): the clearance objective's motion cost data (_disccost.c)."},
    {"disc_cost", (PyCFunction)(void (*)(void))fast_disc_cost, METH_FASTCALL,
     "disc_cost(handle, s1, s2): Cost(exp(-disc bound of the motion / sigma)) (_disccost.c)."},
    {"gjk", (PyCFunction)(void (*)(void))fast_gjk, METH_FASTCALL,
     "gjk(a, b, max_iterations): the loop of cspace.kernel.distance.gjk._gjk on float64 (n, 2) arrays."},
    {"clearance_scan", (PyCFunction)(void (*)(void))fast_clearance_scan, METH_FASTCALL,
     "clearance_scan(...): min_clearance's search passing over losing pairs (_nearest.c)."},
    {"pack_boxes", fast_pack_boxes, METH_VARARGS, "pack_boxes(pieces): packed points, offsets, boxes, scale (_nearest.c)."},
    {"box_gaps", fast_box_gaps, METH_VARARGS, "box_gaps(lo, hi, olo, ohi, out): distances between boxes (_nearest.c)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_fast", "cspace's optional compiled fast path.", -1,
                                    methods};

#ifndef CSPACE_SOURCE_HASH
#define CSPACE_SOURCE_HASH ""  /* built without setup.py's fingerprint: fastpath treats it as stale */
#endif

PyMODINIT_FUNC PyInit__fast(void)
{
    PyObject *m = PyModule_Create(&module);
    if (m != NULL && PyModule_AddStringConstant(m, "source_hash", CSPACE_SOURCE_HASH) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
