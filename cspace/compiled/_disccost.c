/* The clearance objective's motion cost in translation, compiled (cspace.compiled._fast).

   RRTstar asks its objective for the cost of ~100-250 motions per new state; a Python
   motionCost pays an interpreter frame, a few attribute and item lookups and a dict probe
   for each. This is planners/adapters/objectives.py's `_translation_functions` motion, the
   same doubles in the same order:

   - a state's clearance c (raw OMPL coordinates x, y, remembered per (x, y) in an open-
     addressing table, computed on a miss by the Python `at(x, y)`: the exact float distance
     from the reference point to the nearest C-obstacle piece, 0 where it is not free);
   - a motion's clearance: the disc bound of its ends (point_clearance.disc_bound: the
     segment of length d lies in the union of the discs of radius c1, c2 about its ends; the
     bound is the least distance from the segment to the discs' union's boundary, the half
     chord where the two circles cross), a certified lower bound of its exact clearance;
   - its cost: exp(-clearance / sigma) as OMPL's Cost (the soft minimum's term).

   The table is cleared when half full (as the Python cache restarts at CACHE_MAX). */
#include "_fast.h"

#define DC_NAME "cspace.compiled._fast.DiscCost"

typedef struct {
    double unit, inv_sigma;
    PyObject *cost_type, *at; /* ob.Cost; (x, y) -> clearance on a miss */
    PyObject *zero, *one;     /* the indices 0 and 1 */
    uint64_t *kx, *ky;        /* keys: the coordinates' bits; empty: kx == EMPTY */
    double *val;
    size_t mask, count;
    double lx, ly, lc; /* the second state met last and its clearance */
} DiscCost;

static const uint64_t EMPTY = 0x7ff8dead0000beefULL; /* a NaN's bits: never a state's coordinate */

static void dc_free(PyObject *cap)
{
    DiscCost *h = (DiscCost *)PyCapsule_GetPointer(cap, DC_NAME);
    if (!h) return;
    Py_XDECREF(h->cost_type);
    Py_XDECREF(h->at);
    Py_XDECREF(h->zero);
    Py_XDECREF(h->one);
    free(h->kx);
    free(h->ky);
    free(h->val);
    free(h);
}

static void dc_clear(DiscCost *h)
{
    for (size_t i = 0; i <= h->mask; i++) h->kx[i] = EMPTY;
    h->count = 0;
}

/* disc_cost_handle(unit, sigma, Cost, at, log2_slots): the motion cost's data. */
PyObject *fast_disc_cost_handle(PyObject *self, PyObject *args)
{
    double unit, sigma;
    PyObject *cost_type, *at;
    int bits;
    if (!PyArg_ParseTuple(args, "ddOOi", &unit, &sigma, &cost_type, &at, &bits)) return NULL;
    if (!(sigma > 0.0) || bits < 4 || bits > 26 || !PyCallable_Check(cost_type) || !PyCallable_Check(at)) {
        PyErr_SetString(PyExc_ValueError, "disc_cost_handle: sigma > 0, 4 <= log2_slots <= 26 and two callables");
        return NULL;
    }
    DiscCost *h = (DiscCost *)calloc(1, sizeof(DiscCost));
    if (!h) return PyErr_NoMemory();
    size_t n = (size_t)1 << bits;
    h->kx = malloc(n * sizeof(uint64_t));
    h->ky = malloc(n * sizeof(uint64_t));
    h->val = malloc(n * sizeof(double));
    h->zero = PyLong_FromLong(0);
    h->one = PyLong_FromLong(1);
    if (!h->kx || !h->ky || !h->val || !h->zero || !h->one) {
        Py_XDECREF(h->zero);
        Py_XDECREF(h->one);
        free(h->kx), free(h->ky), free(h->val), free(h);
        return PyErr_NoMemory();
    }
    h->mask = n - 1;
    h->unit = unit;
    h->inv_sigma = 1.0 / sigma;
    Py_INCREF(cost_type);
    Py_INCREF(at);
    h->cost_type = cost_type;
    h->at = at;
    h->lx = h->ly = NAN;
    dc_clear(h);
    PyObject *cap = PyCapsule_New(h, DC_NAME, dc_free);
    if (!cap) {
        Py_DECREF(cost_type), Py_DECREF(at), Py_DECREF(h->zero), Py_DECREF(h->one);
        free(h->kx), free(h->ky), free(h->val), free(h);
    }
    return cap;
}

static inline uint64_t bits_of(double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

/* The clearance of the state at (x, y): the table's, else at(x, y) (then remembered).
   Returns 0 and sets *c, or -1 with a Python error. */
static int dc_state(DiscCost *h, double x, double y, double *c)
{
    uint64_t bx = bits_of(x), by = bits_of(y);
    uint64_t k = (bx * 0x9E3779B97F4A7C15ULL) ^ (by * 0xC2B2AE3D27D4EB4FULL);
    size_t home = (size_t)(k ^ (k >> 31)) & h->mask, i = home;
    while (h->kx[i] != EMPTY) { /* linear probing */
        if (h->kx[i] == bx && h->ky[i] == by) {
            *c = h->val[i];
            return 0;
        }
        i = (i + 1) & h->mask;
    }
    PyObject *r = PyObject_CallFunction(h->at, "dd", x, y);
    if (!r) return -1;
    double v = PyFloat_AsDouble(r);
    Py_DECREF(r);
    if (v == -1.0 && PyErr_Occurred()) return -1;
    if (2 * (h->count + 1) > h->mask + 1) { /* half full: start over (its home slot is then empty) */
        dc_clear(h);
        i = home;
    }
    h->kx[i] = bx;
    h->ky[i] = by;
    h->val[i] = v;
    h->count++;
    *c = v;
    return 0;
}

/* Coordinate i of an OMPL state (its __getitem__), as a double; -1 and an error on failure. */
static int dc_coord(PyObject *s, PyObject *index, double *out)
{
    PyObject *v = PyObject_GetItem(s, index);
    if (!v) return -1;
    *out = PyFloat_AsDouble(v);
    Py_DECREF(v);
    return (*out == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

/* The disc bound of a segment of length d whose ends have clearances c1, c2 (objectives.py). */
static double disc_bound(double c1, double c2, double d)
{
    if (d >= c1 + c2) return 0.0; /* the discs apart */
    double m = c1 < c2 ? c1 : c2;
    if (d <= 0.0 || m == INFINITY) return m; /* one point (or no obstacles: both inf) */
    double a = (d * d + c1 * c1 - c2 * c2) / (2.0 * d); /* where the discs' boundaries cross */
    if (a <= 0.0) return c1;
    if (a >= d) return c2;
    double hh = c1 * c1 - a * a;
    hh = hh > 0.0 ? sqrt(hh) : 0.0;
    return hh < m ? hh : m;
}

/* disc_cost(handle, s1, s2): Cost(exp(-clearance(s1 -> s2) / sigma)). */
PyObject *fast_disc_cost(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "disc_cost(handle, s1, s2)");
        return NULL;
    }
    DiscCost *h = (DiscCost *)PyCapsule_GetPointer(args[0], DC_NAME);
    if (!h) return NULL;
    double x1, y1, x2, y2, c1, c2;
    if (dc_coord(args[2], h->zero, &x2) < 0 || dc_coord(args[2], h->one, &y2) < 0) return NULL;
    if (x2 == h->lx && y2 == h->ly) {
        c2 = h->lc;
    } else {
        if (dc_state(h, x2, y2, &c2) < 0) return NULL;
        h->lx = x2, h->ly = y2, h->lc = c2;
    }
    if (dc_coord(args[1], h->zero, &x1) < 0 || dc_coord(args[1], h->one, &y1) < 0) return NULL;
    if (dc_state(h, x1, y1, &c1) < 0) return NULL;
    double d = hypot(x2 - x1, y2 - y1) * h->unit;
    double c = disc_bound(c1, c2, d);
    return PyObject_CallFunction(h->cost_type, "d", exp(-c * h->inv_sigma));
}
