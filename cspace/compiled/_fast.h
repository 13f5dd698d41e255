/* Shared by the C files of cspace's optional compiled fast path (cspace.compiled._fast):
   _fast.c (grid queries, SE(2) filter, the module), _build.c (the C-space build's pair
   sums and containment), _cells.c (the grid build's cell classification), _chords.c
   (chord polygons), _gjk.c (the GJK loop of min_clearance), _nearest.c (min_clearance's
   search over its pairs), _se2motion.c and _carmotion.c (the compiled SE(2) motion and car
   curve checks: they share the angle wrap, the slab lookup and the handles' helpers below),
   _carwords.c (Dubins and Reeds-Shepp words), _carrrt.c (a Reeds-Shepp car's RRT-Connect), _disccost.c (the clearance objective's motion
   cost in translation).

   The one certified predicate they share: the sign of a cross product of two edge
   vectors, decided only where floats certify it (Shewchuk's stage-A filter, the same
   bound as cspace/kernel/polygons/predicates.py; an exact zero when a factor of each product is
   an exact zero difference; or all six operations exact, by Knuth's TwoSum and Dekker's
   TwoProduct, as error_free_cross_sign), "undecided" otherwise, for the pure path to
   answer in rationals. FP contraction (FMA) is off so that each product is rounded
   once, as the bound assumes (GCC: -ffp-contract=off, from setup.py). */
#ifndef CSPACE_FAST_H
#define CSPACE_FAST_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(__clang__)
#pragma clang fp contract(off)
#elif !defined(__GNUC__)
#pragma STDC FP_CONTRACT OFF
#endif

#define EPS (1.0 / 9007199254740992.0) /* 2^-53 */
#define ERRBOUND_A ((3.0 + 16.0 * EPS) * EPS)
#define UNDERFLOW_GUARD 1e-280
#define UNDECIDED 2
#define SPLIT 134217729.0 /* 2^27 + 1, Dekker's splitter */
#define PI 3.141592653589793
#define TWO_PI (2.0 * PI)

/* Knuth's TwoSum error of s = fl(a + b). */
static inline double sum_err(double a, double b, double s)
{
    double bv = s - a, av = s - bv;
    return (a - av) + (b - bv);
}

/* Dekker's TwoProduct error of p = fl(a * b). */
static inline double prod_err(double a, double b, double p)
{
    double t = SPLIT * a, ah = t - (t - a), al = a - ah;
    t = SPLIT * b;
    double bh = t - (t - b), bl = b - bh;
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl;
}

#if defined(__GNUC__) || defined(__clang__)
#define ALWAYS_INLINE inline __attribute__((always_inline))
#define NOINLINE __attribute__((noinline, unused))
#else
#define ALWAYS_INLINE inline
#define NOINLINE
#endif

/* cross_sign's stages after the filter (out of line: rarely reached). */
static NOINLINE int cross_sign_rest(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy)
{
    double ux = bx - ax, uy = by - ay, vx = dx - cx, vy = dy - cy;
    double left = ux * vy, right = uy * vx;
    double det = left - right, detsum = fabs(left) + fabs(right);
    if (detsum == 0.0 && (ux == 0.0 || vy == 0.0) && (uy == 0.0 || vx == 0.0)) return 0;
    /* Every difference and product exact (far from under- and overflow): one rounding keeps the sign. */
    if (!(isfinite(ux) && isfinite(uy) && isfinite(vx) && isfinite(vy))) return UNDECIDED;
    if (!((fabs(left) > 0x1p-900 || ux == 0.0 || vy == 0.0) && fabs(left) < 0x1p1000)) return UNDECIDED;
    if (!((fabs(right) > 0x1p-900 || uy == 0.0 || vx == 0.0) && fabs(right) < 0x1p1000)) return UNDECIDED;
    if (sum_err(bx, -ax, ux) != 0.0 || sum_err(by, -ay, uy) != 0.0 || sum_err(dx, -cx, vx) != 0.0
        || sum_err(dy, -cy, vy) != 0.0 || prod_err(ux, vy, left) != 0.0 || prod_err(uy, vx, right) != 0.0)
        return UNDECIDED;
    return (det > 0.0) - (det < 0.0);
}

/* Certified sign of (b - a) x (d - c): +1, -1, 0, or UNDECIDED (cross_diff_cols's stages).
   The filter inline, the rest (exact zeros, error-free operations) a call. */
static ALWAYS_INLINE int cross_sign(double ax, double ay, double bx, double by, double cx, double cy, double dx,
                                     double dy)
{
    double ux = bx - ax, uy = by - ay, vx = dx - cx, vy = dy - cy;
    double left = ux * vy, right = uy * vx;
    double det = left - right, detsum = fabs(left) + fabs(right);
    if (detsum > UNDERFLOW_GUARD && detsum < HUGE_VAL) {
        double bound = ERRBOUND_A * detsum;
        if (det > bound) return 1;
        if (-det > bound) return -1;
    }
    return cross_sign_rest(ax, ay, bx, by, cx, cy, dx, dy);
}

/* Certified sign of orient2d(a, b, c) = (a - c) x (b - c): +1, -1, 0, or UNDECIDED. */
static inline int orient(double ax, double ay, double bx, double by, double cx, double cy)
{
    return cross_sign(cx, cy, ax, ay, cx, cy, bx, by);
}

/* Is the buffer an (n, 2) array of native float64 (any n, any strides)? Its format may
   carry a byte-order prefix ('@', '=' or '<'). */
static inline int xy_view(const Py_buffer *v)
{
    const char *f = v->format ? v->format : "B";
    if (*f == '@' || *f == '=' || *f == '<') f++;
    return v->ndim == 2 && v->shape[1] == 2 && v->itemsize == 8 && strcmp(f, "d") == 0;
}

/* OMPL's angle wrap (cspace.kernel.slabs.slab.wrap_angle). */
static inline double wrap_angle(double t)
{
    if (-PI <= t && t < PI) return t;
    double v = fmod(t, TWO_PI);
    if (v < -PI) v += TWO_PI;
    else if (v >= PI) v -= TWO_PI;
    return v;
}

/* slab_of(t, K) for t already wrapped, over the K slabs' hull intervals [lo[q], hi[q]]:
   the float index certified by two comparisons, else its neighbours; or -1 (never: a slab
   always covers it). */
static inline int64_t slab_index(const double *lo, const double *hi, int64_t K, double t)
{
    if (K == 1) return 0;
    if (t != t) return -1;
    double f = floor((t + PI) * ((double)K / TWO_PI));
    int64_t k = f < 0.0 ? 0 : (f > (double)(K - 1) ? K - 1 : (int64_t)f);
    int64_t cands[3] = {k, k - 1, k + 1};
    for (int c = 0; c < 3; c++) {
        int64_t q = cands[c];
        if (q >= 0 && q < K && lo[q] <= t && t <= hi[q]) return q;
    }
    return -1;
}

/* The interval [*lo, *hi] of n . x over the n points p (x y interleaved). */
static inline void dot_interval(const double *p, int64_t n, double nx, double ny, double *lo, double *hi)
{
    double a = HUGE_VAL, b = -HUGE_VAL;
    for (int64_t k = 0; k < n; k++) {
        double v = nx * p[2 * k] + ny * p[2 * k + 1];
        if (v < a) a = v;
        if (v > b) b = v;
    }
    *lo = a;
    *hi = b;
}

/* The piece offsets of a motion handle (_se2motion.c, _carmotion.c): obstacle piece i has
   vertices o_off[i] .. o_off[i + 1] - 1, at least a triangle (convex pieces), robot piece j
   r_off[j] .. r_off[j + 1] - 1, at least one; both start at 0. The largest robot piece's
   vertex count, or -1 when the offsets are inconsistent. */
static inline int64_t piece_offsets_max(const int64_t *o_off, int64_t n_obs, const int64_t *r_off, int64_t n_rob)
{
    if (o_off[0] != 0 || r_off[0] != 0) return -1;
    for (int64_t i = 0; i < n_obs; i++)
        if (o_off[i + 1] < o_off[i] + 3) return -1;
    int64_t max_n = 0;
    for (int64_t j = 0; j < n_rob; j++) {
        if (r_off[j + 1] <= r_off[j]) return -1;
        if (r_off[j + 1] - r_off[j] > max_n) max_n = r_off[j + 1] - r_off[j];
    }
    return max_n;
}

/* The boxes x0 y0 x1 y1 of the n pieces whose vertices (x y interleaved) piece i has at
   off[i] .. off[i + 1] - 1, into box; 0, or -1 when a vertex is not finite. */
static inline int piece_boxes(const double *xy, const int64_t *off, int64_t n, double *box)
{
    for (int64_t i = 0; i < n; i++) {
        double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
        for (int64_t v = off[i]; v < off[i + 1]; v++) {
            double x = xy[2 * v], y = xy[2 * v + 1];
            if (!(isfinite(x) && isfinite(y))) return -1;
            if (x < x0) x0 = x;
            if (x > x1) x1 = x;
            if (y < y0) y0 = y;
            if (y > y1) y1 = y;
        }
        box[4 * i] = x0, box[4 * i + 1] = y0, box[4 * i + 2] = x1, box[4 * i + 3] = y1;
    }
    return 0;
}

/* The routines of the other files, registered in _fast.c's method table. */
PyObject *fast_pair_sums(PyObject *self, PyObject *args);                     /* _build.c */
PyObject *fast_contained(PyObject *self, PyObject *args);                     /* _build.c */
PyObject *fast_chords(PyObject *self, PyObject *args);                        /* _chords.c */
int64_t chord_polygon(const double *q, int64_t s, double long_edge, double limit, char *keep, int64_t *idx,
                      double *out, double *sag, double *const nrm[3]);                          /* _chords.c */
PyObject *fast_entries(PyObject *self, PyObject *args);                       /* _cells.c */
PyObject *fast_assemble(PyObject *self, PyObject *args);                      /* _cells.c */
PyObject *fast_gjk(PyObject *self, PyObject *const *args, Py_ssize_t nargs);  /* _gjk.c */
int gjk_gap(const double *a, Py_ssize_t na, const double *b, Py_ssize_t nb, Py_ssize_t max_it, double safe_min,
            double safe_max, double *dx, double *dy, double *bx, double *by, double *extent); /* _gjk.c */
PyObject *fast_clearance_scan(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _nearest.c */
PyObject *fast_pack_boxes(PyObject *self, PyObject *args);                    /* _nearest.c */
PyObject *fast_box_gaps(PyObject *self, PyObject *args);                      /* _nearest.c */

void *fast_copy_buffer(PyObject *obj, Py_ssize_t size, Py_ssize_t count, const char *name); /* _fast.c */
int fast_add_count(PyObject *d, const char *key, long delta);                    /* _fast.c */
int fast_grid_segment(PyObject *grid, double ax, double ay, double bx, double by); /* _fast.c */
int fast_grid_point(PyObject *grid, double x, double y);                         /* _fast.c */
int fast_se2_filter(PyObject *se2, double x, double y, double c, double s);      /* _fast.c */
PyObject *fast_se2_motion_handle(PyObject *self, PyObject *args);              /* _se2motion.c */
PyObject *fast_se2_motion(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _se2motion.c */
PyObject *fast_car_handle(PyObject *self, PyObject *args);                     /* _carmotion.c */
PyObject *fast_car_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _carmotion.c */
PyObject *fast_car_motion(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _carmotion.c */
PyObject *fast_car_connect(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _carrrt.c */
int fast_car_segments(int dubins, const double *q0, const double *q1, double r, char *kinds, double *lengths); /* _carwords.c */
PyObject *fast_reeds_shepp_word(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _carwords.c */
PyObject *fast_dubins_word(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _carwords.c */
PyObject *fast_disc_cost_handle(PyObject *self, PyObject *args);               /* _disccost.c */
PyObject *fast_disc_cost(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _disccost.c */

#endif
