/* The compiled GJK loop of min_clearance (part of cspace.compiled._fast; cspace.compiled.fastpath.gjk_loop).

   The loop of cspace/kernel/distance/gjk.py's _gjk, operation for operation.

   gjk(a, b, max_iterations) runs _gjk(al, bl, max_iterations) on the local frame
   al = a - a[0], bl = b - a[0] (each coordinate x - ox: the doubles Python computes)
   with the same IEEE operations in the same order, so the same doubles come out:
   _support keeps the first of equal maxima (strict >), a support pair already in the
   simplex ends the loop, as does v.v - v.w <= REL_TOL v.v; _solve2 and _solve3 take
   the same branches (a flat triangle: the first best of its three edges by _norm2, as
   Python's min), and _combine sums as Python does (x = l0 p + l1 q, then x += l2 r).
   No FMA contraction (_fast.h; setup.py). The hypot of the points and the
   "deep" test are left to Python (its math.hypot need not be libm's).

   Returns None when a local coordinate is not finite (the caller then runs the pure
   path, which rescales), else (pax, pay, pbx, pby, iterations, inside, simplex, extent):
   the closest points before hypot, inside as a bool, simplex a tuple of (ia, ib, wx, wy),
   extent the largest |local coordinate| (1.0 if all are 0, as _scale). */
#include "_fast.h"

#define GJK_REL_TOL 1e-14 /* gjk.REL_TOL */
#define GJK_STACK 512     /* doubles of local coordinates kept on the stack */

typedef struct {
    Py_ssize_t ia, ib;
    double x, y;
} GVert;

/* A simplex and its weights (1 to 3 vertices). */
typedef struct {
    int n;
    GVert v[3];
    double lam[3];
} GSimplex;

/* _combine(lam, simplex, 2, 3): the point sum(lam[k] w[k]). */
static inline void gjk_combine(const GSimplex *s, double *x, double *y)
{
    if (s->n == 1) {
        *x = s->v[0].x, *y = s->v[0].y;
        return;
    }
    double px = s->lam[0] * s->v[0].x + s->lam[1] * s->v[1].x;
    double py = s->lam[0] * s->v[0].y + s->lam[1] * s->v[1].y;
    if (s->n == 3) {
        px += s->lam[2] * s->v[2].x;
        py += s->lam[2] * s->v[2].y;
    }
    *x = px, *y = py;
}

/* _combine(lam, [pts[ia or ib]], 0, 1): the closest point of A (which == 0) or of B. */
static inline void gjk_point(const GSimplex *s, const double *pts, int which, double *x, double *y)
{
    const double *p = pts + 2 * (which ? s->v[0].ib : s->v[0].ia);
    if (s->n == 1) {
        *x = p[0], *y = p[1];
        return;
    }
    const double *q = pts + 2 * (which ? s->v[1].ib : s->v[1].ia);
    double px = s->lam[0] * p[0] + s->lam[1] * q[0];
    double py = s->lam[0] * p[1] + s->lam[1] * q[1];
    if (s->n == 3) {
        const double *r = pts + 2 * (which ? s->v[2].ib : s->v[2].ia);
        px += s->lam[2] * r[0];
        py += s->lam[2] * r[1];
    }
    *x = px, *y = py;
}

/* _norm2: |combine|^2 of a solved simplex. */
static inline double gjk_norm2(const GSimplex *s)
{
    double x, y;
    gjk_combine(s, &x, &y);
    return x * x + y * y;
}

/* _solve2(s1, s2) into out. */
static void gjk_solve2(GVert s1, GVert s2, GSimplex *out)
{
    double ex = s2.x - s1.x, ey = s2.y - s1.y;
    double d2 = -(s1.x * ex + s1.y * ey);
    if (d2 <= 0.0) {
        out->n = 1, out->v[0] = s1, out->lam[0] = 1.0;
        return;
    }
    double d1 = s2.x * ex + s2.y * ey;
    if (d1 <= 0.0) {
        out->n = 1, out->v[0] = s2, out->lam[0] = 1.0;
        return;
    }
    double inv = 1.0 / (d1 + d2);
    out->n = 2, out->v[0] = s1, out->v[1] = s2, out->lam[0] = d1 * inv, out->lam[1] = d2 * inv;
}

/* An edge (a, b) of the triangle and its weights into out. */
static inline void gjk_edge(GVert a, GVert b, double da, double db, GSimplex *out)
{
    double inv = 1.0 / (da + db);
    out->n = 2, out->v[0] = a, out->v[1] = b, out->lam[0] = da * inv, out->lam[1] = db * inv;
}

/* _solve3(s1, s2, s3) into out (Box2D's b2SolveSimplex3, the branches of gjk.py). */
static void gjk_solve3(GVert s1, GVert s2, GVert s3, GSimplex *out)
{
    double x1 = s1.x, y1 = s1.y, x2 = s2.x, y2 = s2.y, x3 = s3.x, y3 = s3.y;
    double e12x = x2 - x1, e12y = y2 - y1;
    double d12_1 = x2 * e12x + y2 * e12y;
    double d12_2 = -(x1 * e12x + y1 * e12y);
    double e13x = x3 - x1, e13y = y3 - y1;
    double d13_1 = x3 * e13x + y3 * e13y;
    double d13_2 = -(x1 * e13x + y1 * e13y);
    double e23x = x3 - x2, e23y = y3 - y2;
    double d23_1 = x3 * e23x + y3 * e23y;
    double d23_2 = -(x2 * e23x + y2 * e23y);
    double n123 = e12x * e13y - e12y * e13x;
    double d123_1 = n123 * (x2 * y3 - y2 * x3);
    double d123_2 = n123 * (x3 * y1 - y3 * x1);
    double d123_3 = n123 * (x1 * y2 - y1 * x2);
    if (d12_2 <= 0.0 && d13_2 <= 0.0) {
        out->n = 1, out->v[0] = s1, out->lam[0] = 1.0;
        return;
    }
    if (d12_1 > 0.0 && d12_2 > 0.0 && d123_3 <= 0.0) {
        gjk_edge(s1, s2, d12_1, d12_2, out);
        return;
    }
    if (d13_1 > 0.0 && d13_2 > 0.0 && d123_2 <= 0.0) {
        gjk_edge(s1, s3, d13_1, d13_2, out);
        return;
    }
    if (d12_1 <= 0.0 && d23_2 <= 0.0) {
        out->n = 1, out->v[0] = s2, out->lam[0] = 1.0;
        return;
    }
    if (d13_1 <= 0.0 && d23_1 <= 0.0) {
        out->n = 1, out->v[0] = s3, out->lam[0] = 1.0;
        return;
    }
    if (d23_1 > 0.0 && d23_2 > 0.0 && d123_1 <= 0.0) {
        gjk_edge(s2, s3, d23_1, d23_2, out);
        return;
    }
    double total = d123_1 + d123_2 + d123_3;
    if (total == 0.0 || !(d123_1 > 0.0 && d123_2 > 0.0 && d123_3 > 0.0)) {
        /* A flat or degenerate triangle: its best edge, the first of equals (Python's min:
           a candidate replaces the best only if its key is < the best's). */
        GSimplex c[3];
        gjk_solve2(s1, s2, &c[0]);
        gjk_solve2(s1, s3, &c[1]);
        gjk_solve2(s2, s3, &c[2]);
        int best = 0;
        double nb = gjk_norm2(&c[0]);
        for (int k = 1; k < 3; k++) {
            double nk = gjk_norm2(&c[k]);
            if (nk < nb) best = k, nb = nk;
        }
        *out = c[best];
        return;
    }
    double inv = 1.0 / total;
    out->n = 3, out->v[0] = s1, out->v[1] = s2, out->v[2] = s3;
    out->lam[0] = d123_1 * inv, out->lam[1] = d123_2 * inv, out->lam[2] = d123_3 * inv;
}

/* _support: index of a vertex maximising (dx, dy) . p, the first of equals. */
static inline Py_ssize_t gjk_support(const double *pts, Py_ssize_t n, double dx, double dy)
{
    double best = -HUGE_VAL;
    Py_ssize_t bi = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        double s = pts[2 * i] * dx + pts[2 * i + 1] * dy;
        if (s > best) best = s, bi = i;
    }
    return bi;
}

/* An (n, 2) float64 buffer (any strides), or -1 with an exception. */
static int gjk_view(PyObject *obj, Py_buffer *view, const char *name)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_RECORDS_RO) < 0) return -1;
    if (!xy_view(view) || view->shape[0] < 1) {
        PyErr_Format(PyExc_ValueError, "_fast.gjk: %s must be a non-empty (n, 2) float64 array", name);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* The local-frame coordinates (x - ox, y - oy) of n points, the point i at base + i s0
   (its y at + s1), into out, the largest |coordinate| raised into *extent; 0 if one is
   not finite. */
static int local_frame(const char *base, Py_ssize_t s0, Py_ssize_t s1, Py_ssize_t n, double ox, double oy,
                       double *out, double *extent)
{
    double m = *extent;
    for (Py_ssize_t i = 0; i < n; i++) {
        double x = *(const double *)(base + i * s0) - ox, y = *(const double *)(base + i * s0 + s1) - oy;
        if (!(isfinite(x) && isfinite(y))) return 0;
        out[2 * i] = x, out[2 * i + 1] = y;
        if (fabs(x) > m) m = fabs(x);
        if (fabs(y) > m) m = fabs(y);
    }
    *extent = m;
    return 1;
}

/* local_frame of a view's points. */
static int gjk_local(const Py_buffer *v, double ox, double oy, double *out, double *extent)
{
    return local_frame(v->buf, v->strides[0], v->strides[1], v->shape[0], ox, oy, out, extent);
}

/* _loop on local-frame coordinates al (na points) and bl (nb): the final simplex in *S,
   the iterations in *it; returns 1 when the origin is inside (the loop's inside flag). */
static int gjk_run(const double *al, Py_ssize_t na, const double *bl, Py_ssize_t nb, Py_ssize_t max_it,
                   GSimplex *out, Py_ssize_t *it_out)
{
    GSimplex S = {1, {{0, 0, al[0] - bl[0], al[1] - bl[1]}}, {1.0}};
    Py_ssize_t it = 0;
    int inside = 0;
    while (it < max_it) {
        it++;
        if (S.n == 1) {
            S.lam[0] = 1.0;
        } else if (S.n == 2) {
            gjk_solve2(S.v[0], S.v[1], &S);
        } else {
            gjk_solve3(S.v[0], S.v[1], S.v[2], &S);
        }
        if (S.n == 3) {
            inside = 1;
            break;
        }
        double vx, vy;
        gjk_combine(&S, &vx, &vy);
        double vv = vx * vx + vy * vy;
        if (vv == 0.0) {
            inside = 1;
            break;
        }
        Py_ssize_t ia = gjk_support(al, na, -vx, -vy), ib = gjk_support(bl, nb, vx, vy);
        int seen = 0;
        for (int k = 0; k < S.n; k++) seen |= S.v[k].ia == ia && S.v[k].ib == ib;
        if (seen) break; /* the support is already in the simplex: converged (or cycling) */
        double wx = al[2 * ia] - bl[2 * ib], wy = al[2 * ia + 1] - bl[2 * ib + 1];
        if (vv - (vx * wx + vy * wy) <= GJK_REL_TOL * vv) break; /* no progress */
        S.v[S.n] = (GVert){ia, ib, wx, wy};
        S.lam[S.n] = 0.0;
        S.n++;
    }
    *out = S;
    *it_out = it;
    return inside;
}

/* GJK's float answer on the hulls of a (na points, xy interleaved, contiguous) and b, as
   Python's gjk_distance_below reads it: the local frame at a[0], the loop, then the
   difference of the closest points (A's minus B's) into *dx, *dy, B's closest point in
   the input's frame into *bx, *by (gjk.py's point_b), the extent into *extent. Returns 0,
   or -1 where that answer says nothing (a coordinate not finite, the origin inside, the
   extent outside [safe_min, safe_max)). */
int gjk_gap(const double *a, Py_ssize_t na, const double *b, Py_ssize_t nb, Py_ssize_t max_it, double safe_min,
            double safe_max, double *dx, double *dy, double *bx, double *by, double *extent)
{
    double stack[GJK_STACK], *al = stack;
    if (2 * (na + nb) > GJK_STACK && !(al = malloc(sizeof(double) * 2 * (size_t)(na + nb)))) return -1;
    double *bl = al + 2 * na, ox = a[0], oy = a[1], m = 0.0;
    int ok = local_frame((const char *)a, 16, 8, na, ox, oy, al, &m) && local_frame((const char *)b, 16, 8, nb, ox, oy, bl, &m);
    int result = -1;
    if (!(m > 0.0)) m = 1.0;
    if (ok && m >= safe_min && m < safe_max) {
        GSimplex S;
        Py_ssize_t it;
        if (!gjk_run(al, na, bl, nb, max_it, &S, &it)) {
            double pax, pay, pbx, pby;
            gjk_point(&S, al, 0, &pax, &pay);
            gjk_point(&S, bl, 1, &pbx, &pby);
            *dx = pax - pbx, *dy = pay - pby, *bx = pbx + ox, *by = pby + oy, *extent = m;
            result = 0;
        }
    }
    if (al != stack) free(al);
    return result;
}

PyObject *fast_gjk(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "gjk(a, b, max_iterations)");
        return NULL;
    }
    Py_ssize_t max_it = PyLong_AsSsize_t(args[2]);
    if (max_it == -1 && PyErr_Occurred()) return NULL;
    Py_buffer va, vb;
    if (gjk_view(args[0], &va, "a") < 0) return NULL;
    if (gjk_view(args[1], &vb, "b") < 0) {
        PyBuffer_Release(&va);
        return NULL;
    }
    Py_ssize_t na = va.shape[0], nb = vb.shape[0];
    double stack[GJK_STACK], *al = stack;
    PyObject *result = NULL;
    if (2 * (na + nb) > GJK_STACK && !(al = PyMem_Malloc(sizeof(double) * 2 * (size_t)(na + nb)))) {
        PyErr_NoMemory();
        goto done;
    }
    double *bl = al + 2 * na;
    const double *a0 = va.buf;
    double ox = a0[0], oy = *(const double *)((const char *)va.buf + va.strides[1]);
    double extent = 0.0;
    if (!gjk_local(&va, ox, oy, al, &extent) || !gjk_local(&vb, ox, oy, bl, &extent)) {
        result = Py_NewRef(Py_None); /* not finite: the pure path's case */
        goto done;
    }
    if (!(extent > 0.0)) extent = 1.0;
    GSimplex S;
    Py_ssize_t it;
    int inside = gjk_run(al, na, bl, nb, max_it, &S, &it);
    double pax, pay, pbx, pby;
    gjk_point(&S, al, 0, &pax, &pay);
    gjk_point(&S, bl, 1, &pbx, &pby);
    PyObject *simplex = PyTuple_New(S.n);
    if (!simplex) goto done;
    for (int k = 0; k < S.n; k++) {
        PyObject *v = Py_BuildValue("(nndd)", S.v[k].ia, S.v[k].ib, S.v[k].x, S.v[k].y);
        if (!v) {
            Py_DECREF(simplex);
            goto done;
        }
        PyTuple_SET_ITEM(simplex, k, v);
    }
    result = Py_BuildValue("(ddddnNNd)", pax, pay, pbx, pby, it, PyBool_FromLong(inside), simplex, extent);
done:
    if (al != stack) PyMem_Free(al);
    PyBuffer_Release(&va);
    PyBuffer_Release(&vb);
    return result;
}
