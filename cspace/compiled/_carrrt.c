/* A Reeds-Shepp car's bidirectional RRT (RRT-Connect, as OMPL's RRTConnect grows its trees)
   with its trees, its samples and its Reeds-Shepp metric here: cspace/car/connect.py's search.

   Nothing here is certified: every motion a tree takes is asked of the caller's motion check
   (a Python callable, the certified car motion test), and the path is re-checked by the caller.
   What is compiled is what OMPL spends its time on for a car: the nearest node by the
   Reeds-Shepp length. A node's straight-line distance to the target, and r times the turn
   between their headings, are each at most the length of any curve joining them (the
   reference point moves at unit speed; the heading turns at most 1/r per unit length), so
   a node whose bound is not below the best length so far is passed over without its word.

   The samples come from splitmix64 seeded with the caller's seed: the same seed, the same
   samples, the same trees and path on every run. */
#include "_fast.h"

typedef struct {
    double *q;   /* x, y, th per node */
    int64_t *up; /* parent index, -1 at the root */
    int64_t n, cap;
} Tree;

static int tree_add(Tree *T, const double *q, int64_t up)
{
    if (T->n == T->cap) {
        int64_t cap = T->cap ? 2 * T->cap : 256;
        double *nq = realloc(T->q, (size_t)cap * 3 * sizeof(double));
        if (!nq) return -1;
        T->q = nq;
        int64_t *nu = realloc(T->up, (size_t)cap * sizeof(int64_t));
        if (!nu) return -1;
        T->up = nu, T->cap = cap;
    }
    memcpy(T->q + 3 * T->n, q, 3 * sizeof(double));
    T->up[T->n++] = up;
    return 0;
}

static uint64_t splitmix(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static inline double unit(uint64_t *s) { return (double)(splitmix(s) >> 11) * (1.0 / 9007199254740992.0); }

/* The curve's length, or -1 where the compiled word declines (the node is then passed over). */
static double rs_length(const double *a, const double *b, double r, char *kinds, double *lengths, int *m)
{
    *m = fast_car_segments(0, a, b, r, kinds, lengths);
    if (*m < 0) return -1.0;
    double total = 0.0;
    for (int i = 0; i < *m; i++) total += fabs(lengths[i]);
    return total;
}

/* The node of T nearest q by the Reeds-Shepp length (-1: none measured), its length in *best. */
static int64_t nearest(const Tree *T, const double *q, double r, double *best)
{
    char kinds[5];
    double lengths[5];
    int m;
    int64_t at = -1;
    *best = HUGE_VAL;
    for (int64_t i = 0; i < T->n; i++) {
        const double *p = T->q + 3 * i;
        double dx = q[0] - p[0], dy = q[1] - p[1];
        double lb = sqrt(dx * dx + dy * dy), turn = r * fabs(wrap_angle(q[2] - p[2]));
        if (turn > lb) lb = turn;
        if (lb >= *best) continue;
        double d = rs_length(p, q, r, kinds, lengths, &m);
        if (d >= 0.0 && d < *best) *best = d, at = i;
    }
    return at;
}

/* The pose at distance s along the curve from a (its segments), heading wrapped to [-pi, pi). */
static void along(const double *a, const char *kinds, const double *lengths, int m, double r, double s, double *out)
{
    double x = a[0], y = a[1], th = a[2];
    for (int i = 0; i < m && s > 0.0; i++) {
        double ln = fabs(lengths[i]) <= s ? lengths[i] : copysign(s, lengths[i]);
        double v = ln / r;
        s -= fabs(ln);
        if (kinds[i] == 'L') {
            x += r * (sin(th + v) - sin(th)), y += r * (cos(th) - cos(th + v)), th += v;
        } else if (kinds[i] == 'R') {
            x += r * (sin(th) - sin(th - v)), y += r * (cos(th - v) - cos(th)), th -= v;
        } else {
            x += ln * cos(th), y += ln * sin(th);
        }
    }
    out[0] = x, out[1] = y, out[2] = wrap_angle(th);
}

enum { TRAPPED, ADVANCED, REACHED, FAILED };
#define MAX_CONNECT 100000 /* steps of one connection, at most (a guard: each is range closer) */

/* One step of T toward q: 0 TRAPPED, 1 ADVANCED, 2 REACHED (the new node is q), 3 an error set.
   The start tree drives from its node to the new pose, the goal tree from the new pose to its
   node: every motion is asked in the direction the path drives it. */
static int grow(Tree *T, int start, const double *q, double r, double range, PyObject *free_cb, int64_t *motions)
{
    double d, nq[3], lengths[5];
    char kinds[5];
    int m;
    int64_t i = nearest(T, q, r, &d);
    if (i < 0) return TRAPPED;
    const double *p = T->q + 3 * i;
    int reach = d <= range;
    if (reach) {
        memcpy(nq, q, sizeof nq);
    } else {
        if (rs_length(p, q, r, kinds, lengths, &m) < 0.0) return TRAPPED;
        along(p, kinds, lengths, m, r, range, nq);
        if (nq[0] == p[0] && nq[1] == p[1] && nq[2] == p[2]) return TRAPPED;
    }
    const double *a = start ? p : nq, *b = start ? nq : p;
    PyObject *got = PyObject_CallFunction(free_cb, "(ddd)(ddd)", a[0], a[1], a[2], b[0], b[1], b[2]);
    if (!got) return FAILED;
    int ok = PyObject_IsTrue(got);
    Py_DECREF(got);
    if (ok < 0) return FAILED;
    ++*motions;
    if (!ok) return TRAPPED;
    if (tree_add(T, nq, i) < 0) {
        PyErr_NoMemory();
        return FAILED;
    }
    return reach ? REACHED : ADVANCED;
}

/* Appends to `out` the poses of T from node i up to its root, as (x, y, th) tuples: 0, or -1
   with an error set. */
static int append_branch(PyObject *out, const Tree *T, int64_t i)
{
    for (; i >= 0; i = T->up[i]) {
        const double *q = T->q + 3 * i;
        PyObject *t = Py_BuildValue("(ddd)", q[0], q[1], q[2]);
        if (!t || PyList_Append(out, t) < 0) {
            Py_XDECREF(t);
            return -1;
        }
        Py_DECREF(t);
    }
    return 0;
}

/* The path: the start tree's root to node a, then the goal tree's node b (the same pose) to
   its root, as a list of (x, y, th) tuples. */
static PyObject *join(const Tree *S, int64_t a, const Tree *G, int64_t b)
{
    PyObject *out = PyList_New(0);
    if (!out) return NULL;
    if (append_branch(out, S, a) < 0 || PyList_Reverse(out) < 0 || append_branch(out, G, G->up[b]) < 0) {
        Py_DECREF(out);
        return NULL;
    }
    return out;
}

/* car_connect(x0, y0, th0, x1, y1, th1, radius, xmin, xmax, ymin, ymax, range, seed, iterations,
   motion_free) -> (path or None, iterations, motions asked). See cspace/car/connect.py. */
PyObject *fast_car_connect(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double v[12];
    if (nargs != 15) {
        PyErr_SetString(PyExc_TypeError, "car_connect(x0, y0, th0, x1, y1, th1, radius, xmin, xmax, ymin, ymax, "
                                         "range, seed, iterations, motion_free)");
        return NULL;
    }
    for (int i = 0; i < 12; i++) {
        v[i] = PyFloat_AsDouble(args[i]);
        if (v[i] == -1.0 && PyErr_Occurred()) return NULL;
        if (!isfinite(v[i])) {
            PyErr_SetString(PyExc_ValueError, "car_connect: arguments must be finite");
            return NULL;
        }
    }
    uint64_t seed = PyLong_AsUnsignedLongLongMask(args[12]);
    long long iterations = PyLong_AsLongLong(args[13]);
    if ((iterations == -1 && PyErr_Occurred()) || (seed == (uint64_t)-1 && PyErr_Occurred())) return NULL;
    PyObject *free_cb = args[14];
    double r = v[6], range = v[11];
    if (!(r > 0.0 && range > 0.0 && v[7] <= v[8] && v[9] <= v[10])) {
        PyErr_SetString(PyExc_ValueError, "car_connect: radius and range must be positive, bounds ordered");
        return NULL;
    }
    Tree trees[2] = {{0}, {0}};
    PyObject *result = NULL, *path = NULL;
    int64_t motions = 0;
    long long it = 0;
    if (tree_add(&trees[0], v, -1) < 0 || tree_add(&trees[1], v + 3, -1) < 0) {
        PyErr_NoMemory();
        goto done;
    }
    int from_start = 1; /* the tree sampled towards this iteration: start, goal, start, ... */
    for (; it < iterations && !path; it++, from_start = !from_start) {
        double q[3]; /* x, y, then theta: drawn in this order (an initializer's order is unspecified) */
        q[0] = v[7] + unit(&seed) * (v[8] - v[7]);
        q[1] = v[9] + unit(&seed) * (v[10] - v[9]);
        q[2] = -PI + unit(&seed) * TWO_PI;
        Tree *A = &trees[!from_start], *B = &trees[from_start];
        int g = grow(A, from_start, q, r, range, free_cb, &motions);
        if (g == FAILED) goto done;
        if (g == TRAPPED) continue;
        double target[3];
        memcpy(target, A->q + 3 * (A->n - 1), sizeof target);
        int c = ADVANCED;
        for (int64_t k = 0; c == ADVANCED && k < MAX_CONNECT; k++)  /* each step range closer */
            c = grow(B, !from_start, target, r, range, free_cb, &motions);
        if (c == FAILED) goto done;
        if (c == REACHED) {
            path = from_start ? join(A, A->n - 1, B, B->n - 1) : join(B, B->n - 1, A, A->n - 1);
            if (!path) goto done;
        }
    }
    result = Py_BuildValue("(OLL)", path ? path : Py_None, it, (long long)motions);
done:
    Py_XDECREF(path);
    for (int k = 0; k < 2; k++) free(trees[k].q), free(trees[k].up);
    return result;
}
