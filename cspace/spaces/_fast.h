/* Shared by the C files of cspace's optional compiled fast path (cspace.spaces._fast):
   _fast.c (grid queries, SE(2) filter, the module), _build.c (the C-space build's pair
   sums and containment), _cells.c (the grid build's cell classification), _chords.c
   (chord polygons), _gjk.c (the GJK loop of min_clearance), _nearest.c (min_clearance's
   search over its pairs).

   The one certified predicate they share: the sign of a cross product of two edge
   vectors, decided only where floats certify it (Shewchuk's stage-A filter, the same
   bound as cspace/kernel/predicates.py; an exact zero when a factor of each product is
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

int fast_grid_segment(PyObject *grid, double ax, double ay, double bx, double by); /* _fast.c */
int fast_grid_point(PyObject *grid, double x, double y);                         /* _fast.c */
int fast_se2_filter(PyObject *se2, double x, double y, double c, double s);      /* _fast.c */
PyObject *fast_se2_motion_handle(PyObject *self, PyObject *args);              /* _se2motion.c */
PyObject *fast_se2_motion(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _se2motion.c */
PyObject *fast_car_handle(PyObject *self, PyObject *args);                     /* _carmotion.c */
PyObject *fast_car_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _carmotion.c */
PyObject *fast_reeds_shepp_word(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _carwords.c */
PyObject *fast_dubins_word(PyObject *self, PyObject *const *args, Py_ssize_t nargs); /* _carwords.c */

#endif
