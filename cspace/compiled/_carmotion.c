/* The compiled car curve check: CarMotions.curve_free's loop (cspace/car/motion.py)
   in one call per curve, answering 1 free, 0 not free, -1 undecided (the Python path, the
   oracle, then decides the curve from scratch), or -2 - k: slab k's C-space is not built
   yet (Python builds it and calls again). The join of the curve's end to q1 (an SE(2)
   motion, within rounding) is the caller's (itself compiled: _se2motion.c), except where
   car_motion is asked to join and one slab's segment test certifies it (join_end: 2).

   The caller has taken the start pose as floats, its angle wrapped. Then, as the Python
   path does, with the same float operations in the same order (so the same doubles):
   - the start pose, then the knots (car_curves.advance of each segment, angles wrapped) and
     each segment's middle pose are tested (the slab grid's point test, else _fast.c's
     certified filter of the exact pose test; undecided: -1). A pose in collision: 0.
   - a straight segment is a translation at its one angle: free when the slab C-space's
     compiled segment test (the grid walk of _fast.c) certifies it; otherwise its robot
     pieces at that angle (rotate()'s doubles) swept along halved sub-segments are
     separated from the obstacle pieces by axes with a gap above the margin M |n|_1 below,
     or a middle pose in collision gives 0; the floor or a budget: -1.
   - an arc is cut into the Python path's intervals and halved in its order; an interval
     is bounds-checked exactly as _arc_in_bounds (floats, OMPL's bounds: out is 0); its
     bound is _turn_hits' (the same 3 points per vertex, the same pad d), separated by the
     same axes (obstacle edge normals, the robot's normals turned to a, m and b) with the
     Python path's gap PLUS M |n|_1 and against a superset of its candidates (box overlap
     widened by M), so an interval separated here is separated on the Python path too;
     a middle pose in collision gives 0 (the Python path cannot certify an interval whose
     pose, within rounding of the arc, lies inside an obstacle by more than the filter's
     margin: it answers 0 by a collision or the floor); the floor, the budget of hulls or a
     rotated robot piece whose convexity floats cannot certify (Python would take an exact
     hull): -1.
   M = 2^-42 (the Python path's scale of the arc + radius): about 2048 units of roundoff
   of the coordinates, far above the rounding of the projections here and of the exact
   tests' computed sums (the same bound as _se2motion.c).

   Hence "free" here implies "free" on the Python path, and "not free" implies "not free". */
#include "_fast.h"

#define MAX_SEGMENTS 16
#define STRAIGHT_BUDGET 512

typedef struct {
    int64_t K, n_obs, n_rob, max_n, max_hulls;
    double *slab_lo, *slab_hi;
    int64_t *o_off, *r_off;
    double *o_xy, *o_edge, *o_box; /* vertices; edge planes nx ny off ln (edge_planes); boxes x0 y0 x1 y1 */
    double *r_xy;                  /* body-frame robot vertices */
    double scale, radius, floor_len, arc_chunk, xmin, xmax, ymin, ymax, margin;
    PyObject *se2, *checks;
    double *P, *N;     /* scratch: robot pieces about the centre, their normals */
    double *pts;       /* scratch: 3 points per vertex of one piece */
    double *axes;      /* scratch: turned normals ax ay top g */
    int64_t *near;     /* scratch: obstacle pieces near an arc */
    double *stack;
    int64_t stack_cap;
} Car;

static void car_release(Car *h)
{
    PyMem_Free(h->slab_lo);
    PyMem_Free(h->slab_hi);
    PyMem_Free(h->o_off);
    PyMem_Free(h->r_off);
    PyMem_Free(h->o_xy);
    PyMem_Free(h->o_edge);
    PyMem_Free(h->o_box);
    PyMem_Free(h->r_xy);
    PyMem_Free(h->P);
    PyMem_Free(h->N);
    PyMem_Free(h->pts);
    PyMem_Free(h->axes);
    PyMem_Free(h->near);
    PyMem_Free(h->stack);
    Py_XDECREF(h->se2);
    Py_XDECREF(h->checks);
    PyMem_Free(h);
}

static void car_free_cap(PyObject *cap)
{
    Car *h = (Car *)PyCapsule_GetPointer(cap, "cspace.compiled._fast.Car");
    if (h) car_release(h);
}

/* car_handle(se2, checks, slab_lo, slab_hi, o_off, o_xy, o_edge, r_off, r_xy, K, n_obs, n_rob,
   max_hulls, scale, radius, floor_len, arc_chunk, xmin, xmax, ymin, ymax) -> capsule. */
PyObject *fast_car_handle(PyObject *self, PyObject *args)
{
    PyObject *se2, *checks, *a[7];
    Py_ssize_t K, n_obs, n_rob, max_hulls;
    double scale, radius, floor_len, chunk, xmin, xmax, ymin, ymax;
    if (!PyArg_ParseTuple(args, "OO!OOOOOOOnnnndddddddd", &se2, &PyDict_Type, &checks, &a[0], &a[1], &a[2], &a[3],
                          &a[4], &a[5], &a[6], &K, &n_obs, &n_rob, &max_hulls, &scale, &radius, &floor_len, &chunk,
                          &xmin, &xmax, &ymin, &ymax))
        return NULL;
    if (!PyCapsule_IsValid(se2, "cspace.compiled._fast.SE2")) {
        PyErr_SetString(PyExc_TypeError, "_fast.car_handle: not an SE(2) handle");
        return NULL;
    }
    if (K < 1 || n_obs < 0 || n_rob < 1 || max_hulls < 1
        || !(isfinite(scale) && isfinite(radius) && isfinite(floor_len) && scale >= 0 && radius >= 0)
        || !(chunk > 0.0 && chunk <= PI / 4) || !(xmin <= xmax && ymin <= ymax)) {
        PyErr_SetString(PyExc_ValueError, "_fast.car_handle: bad sizes");
        return NULL;
    }
    Car *h = PyMem_Calloc(1, sizeof(Car));
    if (!h) return PyErr_NoMemory();
    Py_INCREF(se2);
    Py_INCREF(checks);
    h->se2 = se2, h->checks = checks;
    h->K = K, h->n_obs = n_obs, h->n_rob = n_rob, h->max_hulls = max_hulls;
    h->scale = scale, h->radius = radius, h->floor_len = floor_len, h->arc_chunk = chunk;
    h->xmin = xmin, h->xmax = xmax, h->ymin = ymin, h->ymax = ymax;
    h->margin = 0x1p-42 * (scale + radius) + 0x1p-900;
    if (!(h->slab_lo = fast_copy_buffer(a[0], 8, K, "slab_lo"))) goto fail;
    if (!(h->slab_hi = fast_copy_buffer(a[1], 8, K, "slab_hi"))) goto fail;
    if (!(h->o_off = fast_copy_buffer(a[2], 8, n_obs + 1, "o_off"))) goto fail;
    if (!(h->r_off = fast_copy_buffer(a[5], 8, n_rob + 1, "r_off"))) goto fail;
    if ((h->max_n = piece_offsets_max(h->o_off, n_obs, h->r_off, n_rob)) < 0) goto bad;
    int64_t no = h->o_off[n_obs], nr = h->r_off[n_rob];
    if (!(h->o_xy = fast_copy_buffer(a[3], 16, no, "o_xy"))) goto fail;
    if (!(h->o_edge = fast_copy_buffer(a[4], 32, no, "o_edge"))) goto fail;
    if (!(h->r_xy = fast_copy_buffer(a[6], 16, nr, "r_xy"))) goto fail;
    h->o_box = PyMem_Malloc(32 * (size_t)(n_obs ? n_obs : 1));
    h->P = PyMem_Malloc(16 * (size_t)nr);
    h->N = PyMem_Malloc(16 * (size_t)nr);
    h->pts = PyMem_Malloc(48 * (size_t)h->max_n);
    h->axes = PyMem_Malloc(96 * (size_t)h->max_n);
    h->near = PyMem_Malloc(8 * (size_t)(n_obs ? n_obs : 1));
    h->stack_cap = 2 * (max_hulls > STRAIGHT_BUDGET ? max_hulls : STRAIGHT_BUDGET) + 64;
    h->stack = PyMem_Malloc(16 * (size_t)h->stack_cap);
    if (!h->o_box || !h->P || !h->N || !h->pts || !h->axes || !h->near || !h->stack) {
        PyErr_NoMemory();
        goto fail;
    }
    if (piece_boxes(h->o_xy, h->o_off, n_obs, h->o_box) < 0) goto bad;
    PyObject *cap = PyCapsule_New(h, "cspace.compiled._fast.Car", car_free_cap);
    if (cap) return cap;
    goto fail;
bad:
    PyErr_SetString(PyExc_ValueError, "_fast.car_handle: inconsistent arrays");
fail:
    car_release(h);
    return NULL;
}

/* Undecided / slab k unbuilt / error codes of the helpers below. */
#define R_UNDECIDED (-1)
#define R_ERROR (-2)
#define R_SLAB(k) (-3 - (k))

/* The pose (th wrapped): 1 free, 0 not free, R_UNDECIDED, R_SLAB(k), R_ERROR. */
static int64_t car_pose(Car *h, PyObject *grids, double x, double y, double th)
{
    int64_t k = slab_index(h->slab_lo, h->slab_hi, h->K, th);
    if (k < 0) return R_UNDECIDED;
    PyObject *g = PyList_GET_ITEM(grids, k);
    if (g == Py_None) return R_SLAB(k);
    int r = fast_grid_point(g, x, y);
    if (r == 1) return 1;
    if (r == -2) return R_ERROR;
    r = fast_se2_filter(h->se2, x, y, cos(th), sin(th));
    if (r == -2) return R_ERROR;
    return r < 0 ? R_UNDECIDED : r;
}

/* car_curves.advance: the pose after one segment (th not wrapped). */
static void advance(double x, double y, double th, char kind, double length, double r, double *out)
{
    double v = length / r, dx, dy, t1;
    if (kind == 'L') {
        dx = 0.0 + sin(th + v) - sin(th);
        dy = 0.0 - cos(th + v) + cos(th);
        t1 = th + v;
    } else if (kind == 'R') {
        dx = 0.0 - sin(th - v) + sin(th);
        dy = 0.0 + cos(th - v) - cos(th);
        t1 = th - v;
    } else {
        dx = 0.0 + v * cos(th);
        dy = 0.0 + v * sin(th);
        t1 = th;
    }
    out[0] = x + dx * r;
    out[1] = y + dy * r;
    out[2] = t1;
}

/* The robot pieces at the angle (c, s) as rotate() turns them, plus (rx, ry), into h->P, and
   their edge normals (_normals) into h->N. 0, or -1 when floats cannot certify that every
   turn of the rotated piece is a strict left turn (rotate_piece would take an exact hull). */
static int place_pieces(Car *h, double c, double s, double rx, double ry)
{
    for (int64_t j = 0; j < h->n_rob; j++) {
        int64_t o = h->r_off[j], n = h->r_off[j + 1] - o;
        const double *v = h->r_xy + 2 * o;
        double *R = h->P + 2 * o;
        for (int64_t u = 0; u < n; u++) {
            double x = v[2 * u], y = v[2 * u + 1];
            R[2 * u] = x * c - y * s + 0.0;
            R[2 * u + 1] = x * s + y * c + 0.0;
        }
        if (n >= 3) { /* strict left turns, by Shewchuk's stage-A filter */
            for (int64_t u = 0; u < n; u++) {
                const double *A = R + 2 * u, *B = R + 2 * ((u + 1) % n), *C = R + 2 * ((u + 2) % n);
                double l = (B[0] - A[0]) * (C[1] - A[1]), r = (B[1] - A[1]) * (C[0] - A[0]);
                double det = l - r;
                if (!(det > ERRBOUND_A * (fabs(l) + fabs(r)) && det > UNDERFLOW_GUARD)) return -1;
            }
        }
        for (int64_t u = 0; u < n; u++) {
            R[2 * u] = R[2 * u] + rx;
            R[2 * u + 1] = R[2 * u + 1] + ry;
        }
        double *N = h->N + 2 * o;
        for (int64_t u = 0; u < n; u++) {
            int64_t w = (u + 1) % n;
            double ex = R[2 * w] - R[2 * u], ey = R[2 * w + 1] - R[2 * u + 1];
            N[2 * u] = ey;
            N[2 * u + 1] = -ex;
        }
    }
    return 0;
}

/* _arc_in_bounds, the same float operations. */
static int arc_in_bounds(const Car *h, double cx, double cy, double rx, double ry, double a, double b)
{
    double rho = hypot(rx, ry), phi0 = atan2(ry, rx);
    double xlo = HUGE_VAL, xhi = -HUGE_VAL, ylo = HUGE_VAL, yhi = -HUGE_VAL;
    double angs[2] = {a, b};
    for (int t = 0; t < 2; t++) {
        double c = cos(angs[t]), s = sin(angs[t]);
        double x = cx + rx * c - ry * s, y = cy + rx * s + ry * c;
        if (x < xlo) xlo = x;
        if (x > xhi) xhi = x;
        if (y < ylo) ylo = y;
        if (y > yhi) yhi = y;
    }
    static const double DX[4] = {1, 0, -1, 0}, DY[4] = {0, 1, 0, -1};
    for (int q = 0; q < 4; q++) {
        double target = (double)q * 0.5 * PI;
        double k = ceil((phi0 + a - target) / (2.0 * PI));
        if (!isfinite(k)) return -1;
        if (target + 2.0 * PI * k <= phi0 + b) {
            double x = cx + DX[q] * rho, y = cy + DY[q] * rho;
            if (x < xlo) xlo = x;
            if (x > xhi) xhi = x;
            if (y < ylo) ylo = y;
            if (y > yhi) yhi = y;
        }
    }
    if (xlo != xlo || ylo != ylo || xhi != xhi || yhi != yhi) return -1;
    return h->xmin <= xlo && xhi <= h->xmax && h->ymin <= ylo && yhi <= h->ymax;
}

/* _turn_hits for every robot piece over [a, b] about (cx, cy): 0 when every (piece, obstacle)
   pair of the candidates is separated with the Python gap plus M |n|_1; 1 maybe. */
static int turn_hits(Car *h, double cx, double cy, double a, double b, double scale, double M, int64_t n_near)
{
    double hh = 0.5 * (b - a), m = a + hh, k = 1.0 / cos(hh);
    double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cm = cos(m), sm = sin(m);
    if (!(isfinite(k) && k > 0.0)) return 1;
    for (int64_t j = 0; j < h->n_rob; j++) {
        int64_t o = h->r_off[j], n = h->r_off[j + 1] - o, np = 3 * n;
        const double *R = h->P + 2 * o, *Nr = h->N + 2 * o;
        double *pts = h->pts;
        double x0 = HUGE_VAL, x1 = -HUGE_VAL, y0 = HUGE_VAL, y1 = -HUGE_VAL;
        for (int64_t u = 0; u < n; u++) {
            double x = R[2 * u], y = R[2 * u + 1];
            double *p = pts + 6 * u;
            p[0] = x * ca - y * sa + cx;
            p[1] = x * sa + y * ca + cy;
            p[2] = x * cb - y * sb + cx;
            p[3] = x * sb + y * cb + cy;
            p[4] = (x * cm - y * sm) * k + cx;
            p[5] = (x * sm + y * cm) * k + cy;
            for (int t = 0; t < 3; t++) {
                double px = p[2 * t], py = p[2 * t + 1];
                if (px < x0) x0 = px;
                if (px > x1) x1 = px;
                if (py < y0) y0 = py;
                if (py > y1) y1 = py;
            }
        }
        if (!(isfinite(x0) && isfinite(x1) && isfinite(y0) && isfinite(y1))) return 1;
        double mag = -x0;
        if (x1 > mag) mag = x1;
        if (-y0 > mag) mag = -y0;
        if (y1 > mag) mag = y1;
        mag = mag * 1.5;
        if (scale > mag) mag = scale;
        double d = 0x1p-44 * mag + 0x1p-900; /* slab_pad */
        double bx0 = x0 - d - M, bx1 = x1 + d + M, by0 = y0 - d - M, by1 = y1 + d + M;
        int have_axes = 0;
        for (int64_t t = 0; t < n_near; t++) {
            int64_t i = h->near[t];
            const double *B = h->o_box + 4 * i;
            if (!(B[0] <= bx1 && B[2] >= bx0 && B[1] <= by1 && B[3] >= by0)) continue;
            int64_t o0 = h->o_off[i], no = h->o_off[i + 1] - o0;
            int sep = 0;
            for (int64_t e = 0; e < no && !sep; e++) { /* beyond one of the obstacle's edges */
                const double *E = h->o_edge + 4 * (o0 + e);
                double nx = E[0], ny = E[1], off = E[2], ln = E[3];
                double lo = HUGE_VAL;
                for (int64_t q = 0; q < np; q++) {
                    double v = nx * pts[2 * q] + ny * pts[2 * q + 1];
                    if (v < lo) lo = v;
                }
                double w = fabs(nx) + fabs(ny);
                if (lo - off > d * (w + ln) + M * w) sep = 1;
            }
            if (sep) continue;
            if (!have_axes) { /* the piece's normals turned to a, m and b */
                double cs[6] = {ca, sa, cm, sm, cb, sb};
                for (int64_t u = 0; u < n; u++) {
                    double nx = Nr[2 * u], ny = Nr[2 * u + 1];
                    for (int t3 = 0; t3 < 3; t3++) {
                        double c = cs[2 * t3], s = cs[2 * t3 + 1];
                        double ax = nx * c - ny * s, ay = nx * s + ny * c;
                        double g = d * (fabs(ax) + fabs(ay) + hypot(ax, ay));
                        double top = -HUGE_VAL;
                        for (int64_t q = 0; q < np; q++) {
                            double v = ax * pts[2 * q] + ay * pts[2 * q + 1];
                            if (v > top) top = v;
                        }
                        double *A = h->axes + 4 * (3 * u + t3);
                        A[0] = ax, A[1] = ay, A[2] = top + g, A[3] = g + M * (fabs(ax) + fabs(ay));
                    }
                }
                have_axes = 1;
            }
            const double *O = h->o_xy + 2 * o0;
            for (int64_t t3 = 0; t3 < 3 * n && !sep; t3++) {
                const double *A = h->axes + 4 * t3;
                double lo = HUGE_VAL;
                for (int64_t q = 0; q < no; q++) {
                    double v = A[0] * O[2 * q] + A[1] * O[2 * q + 1];
                    if (v < lo) lo = v;
                }
                if (lo - A[2] > A[3]) sep = 1;
            }
            if (!sep) return 1;
        }
    }
    return 0;
}

/* Might a robot piece at the angle whose rotated pieces (about the origin) are in h->P,
   normals in h->N, swept along a-b, meet an obstacle piece? 0 certainly not (every pair
   has a separating axis with a gap above M |n|_1), 1 maybe. */
static int fixed_hits(Car *h, double ax, double ay, double bx, double by)
{
    double M = h->margin;
    double snx = by - ay, sny = ax - bx;
    for (int64_t j = 0; j < h->n_rob; j++) {
        int64_t o = h->r_off[j], n = h->r_off[j + 1] - o;
        const double *R = h->P + 2 * o, *Nr = h->N + 2 * o;
        double tx0, tx1, ty0, ty1;
        dot_interval(R, n, 1.0, 0.0, &tx0, &tx1);
        dot_interval(R, n, 0.0, 1.0, &ty0, &ty1);
        double bx0 = tx0 + (ax < bx ? ax : bx) - M, bx1 = tx1 + (ax < bx ? bx : ax) + M;
        double by0 = ty0 + (ay < by ? ay : by) - M, by1 = ty1 + (ay < by ? by : ay) + M;
        for (int64_t i = 0; i < h->n_obs; i++) {
            const double *B = h->o_box + 4 * i;
            if (B[0] > bx1 || bx0 > B[2] || B[1] > by1 || by0 > B[3]) continue;
            int64_t o0 = h->o_off[i], no = h->o_off[i + 1] - o0;
            const double *O = h->o_xy + 2 * o0;
            int sep = 0;
            for (int64_t e = 0; e < n + no + 1 && !sep; e++) {
                double nx, ny;
                if (e < n) nx = Nr[2 * e], ny = Nr[2 * e + 1];
                else if (e < n + no) nx = h->o_edge[4 * (o0 + e - n)], ny = h->o_edge[4 * (o0 + e - n) + 1];
                else nx = snx, ny = sny;
                if (nx == 0.0 && ny == 0.0) continue;
                double tlo, thi, olo, ohi;
                dot_interval(R, n, nx, ny, &tlo, &thi);
                dot_interval(O, no, nx, ny, &olo, &ohi);
                double pa = nx * ax + ny * ay, pb = nx * bx + ny * by, g = M * (fabs(nx) + fabs(ny));
                double slo = tlo + (pa < pb ? pa : pb), shi = thi + (pa < pb ? pb : pa);
                if (shi + g < olo || ohi + g < slo) sep = 1;
            }
            if (!sep) return 1;
        }
    }
    return 0;
}

typedef struct {
    double sx, sy, st; /* start pose (st wrapped) */
    double ex, ey, et; /* end pose (et wrapped) */
    double length;
    char kind;
} Link;

/* The robot at the one angle th (th wrapped, its slab's grid in `grids`) translated from (x0, y0)
   to (x1, y1), past the slab's segment test: its pieces swept along halved sub-segments
   separated by fixed_hits (1), a middle pose in collision (0), or an R_ code. */
static int64_t fixed_sweep(Car *h, PyObject *grids, double x0, double y0, double x1, double y1, double th)
{
    if (place_pieces(h, cos(th), sin(th), 0.0, 0.0) < 0) return R_UNDECIDED;
    int64_t top = 1, budget = STRAIGHT_BUDGET;
    h->stack[0] = 0.0, h->stack[1] = 1.0;
    while (top > 0) {
        top--;
        double sa = h->stack[2 * top], sb = h->stack[2 * top + 1];
        double qax = sa == 0.0 ? x0 : x0 + (x1 - x0) * sa, qay = sa == 0.0 ? y0 : y0 + (y1 - y0) * sa;
        double qbx = sb == 1.0 ? x1 : x0 + (x1 - x0) * sb, qby = sb == 1.0 ? y1 : y0 + (y1 - y0) * sb;
        if (!fixed_hits(h, qax, qay, qbx, qby)) continue;
        double sm = 0.5 * (sa + sb);
        int64_t pr = car_pose(h, grids, x0 + (x1 - x0) * sm, y0 + (y1 - y0) * sm, th);
        if (pr != 1) return pr; /* 0: a real collision; else undecided, unbuilt, error */
        if (--budget <= 0 || hypot(qbx - qax, qby - qay) <= h->floor_len || !(sa < sm && sm < sb)
            || top + 2 > h->stack_cap)
            return R_UNDECIDED;
        h->stack[2 * top] = sm, h->stack[2 * top + 1] = sb;
        h->stack[2 * top + 2] = sa, h->stack[2 * top + 3] = sm;
        top += 2;
    }
    return 1;
}

/* A straight segment at the angle th from (x0, y0) to (x1, y1): 1, 0 or an R_ code. */
static int64_t straight(Car *h, PyObject *grids, double x0, double y0, double x1, double y1, double th)
{
    int64_t k = slab_index(h->slab_lo, h->slab_hi, h->K, th);
    if (k < 0) return R_UNDECIDED;
    PyObject *g = PyList_GET_ITEM(grids, k);
    if (g == Py_None) return R_SLAB(k);
    int r = fast_grid_segment(g, x0, y0, x1, y1);
    if (r == -2) return R_ERROR;
    if (r == 1 || r == 3) return 1;
    return fixed_sweep(h, grids, x0, y0, x1, y1, th);
}

/* One arc (_arc_free): 1, 0 or an R_ code; *budget is the curve's budget of hulls. */
static int64_t arc(Car *h, PyObject *grids, const Link *L, double radius, int64_t *budget, long *n_sweeps)
{
    double x = L->sx, y = L->sy, th = L->st;
    double cx, cy;
    if (L->kind == 'L') cx = x - radius * sin(th), cy = y + radius * cos(th);
    else cx = x + radius * sin(th), cy = y - radius * cos(th);
    double A = L->kind == 'L' ? L->length / radius : -L->length / radius;
    double rx = x - cx, ry = y - cy;
    if (place_pieces(h, cos(th), sin(th), rx, ry) < 0) return R_UNDECIDED;
    double reach = hypot(rx, ry) + h->radius;
    double scale = h->scale + fabs(cx) + fabs(cy) + reach;
    double M = 0x1p-42 * (scale + h->radius) + 0x1p-900;
    /* The obstacle pieces whose boxes meet the box of radius 1.1 reach (+ pads) about c: every
       point _turn_hits takes lies within reach / cos(chunk / 2) < 1.02 reach of c (+ rounding). */
    double R = 1.1 * reach + 0x1p-40 * scale + 2.0 * M;
    int64_t n_near = 0;
    for (int64_t i = 0; i < h->n_obs; i++) {
        const double *B = h->o_box + 4 * i;
        if (B[0] <= cx + R && B[2] >= cx - R && B[1] <= cy + R && B[3] >= cy - R) h->near[n_near++] = i;
    }
    double lo = 0.0 < A ? 0.0 : A, hi = 0.0 < A ? A : 0.0;
    double fn = ceil((hi - lo) / h->arc_chunk);
    if (!(fn >= 0.0 && fn < 1e6)) return R_UNDECIDED;
    int64_t n = fn < 1.0 ? 1 : (int64_t)fn;
    if (n + 2 > h->stack_cap) return R_UNDECIDED;
    int64_t top = 0;
    for (int64_t i = n - 1; i >= 0; i--) {
        h->stack[2 * top] = lo + (hi - lo) * ((double)i / (double)n);
        h->stack[2 * top + 1] = lo + (hi - lo) * ((double)(i + 1) / (double)n);
        top++;
    }
    /* stack[0] holds i = n - 1 ... stack[top - 1] i = 0: the Python list, popped from its end */
    while (top > 0) {
        top--;
        double a = h->stack[2 * top], b = h->stack[2 * top + 1];
        int ib = arc_in_bounds(h, cx, cy, rx, ry, a, b);
        if (ib < 0) return R_UNDECIDED;
        if (!ib) return 0; /* the reference point leaves the bounds */
        --*budget;
        ++*n_sweeps;
        if (!turn_hits(h, cx, cy, a, b, scale, M, n_near)) continue;
        double m = 0.5 * (a + b), c = cos(m), s = sin(m);
        int64_t pr = car_pose(h, grids, cx + rx * c - ry * s, cy + rx * s + ry * c, wrap_angle(th + m));
        if (pr != 1) return pr;
        if (reach * (b - a) <= h->floor_len || *budget <= 0 || !(a < m && m < b) || top + 2 > h->stack_cap)
            return R_UNDECIDED; /* the floor: the Python path counts and answers it */
        h->stack[2 * top] = m, h->stack[2 * top + 1] = b;
        h->stack[2 * top + 2] = a, h->stack[2 * top + 3] = m;
        top += 2;
    }
    return 1;
}

/* One segment appended to the chain from its end (px, py, pt): 1, or R_UNDECIDED where the
   knot is not finite. A zero length adds nothing (as the Python path drops it). */
static int64_t link_segment(Link *chain, int *nl, double *p, char kind, double length, double radius)
{
    if (length == 0.0) return 1;
    Link *L = chain + (*nl)++;
    double e[3];
    advance(p[0], p[1], p[2], kind, length, radius, e);
    if (!(isfinite(e[0]) && isfinite(e[1]) && isfinite(e[2]))) return R_UNDECIDED;
    L->sx = p[0], L->sy = p[1], L->st = p[2], L->kind = kind, L->length = length;
    L->ex = e[0], L->ey = e[1], L->et = wrap_angle(e[2]);
    p[0] = L->ex, p[1] = L->ey, p[2] = L->et;
    return 1;
}

/* The chain from q (res 1 so far) certified: the probe, straight segments, then arcs, counted
   as the Python path counts; (r, x, y, th) with (x, y, th) = p, the chain's end. */
/* The join of a free chain's end p to q1 (both angles wrapped), as the caller would certify it
   (SE2CSpace.motion_free): 1 when p is q1, or when the motion, its angles between p's and
   q1's, stays within one slab's hull interval and the slab C-space's segment test (the grid
   walk) certifies its reference segment free -- free at every angle of the interval, so at
   every pose of the motion -- or, the join at one angle (p's heading is q1's, the usual join:
   the curve's end differs from q1 by rounding of x and y only), when the robot at that angle
   swept along it is separated from every obstacle piece with the margin (fixed_sweep, as a
   straight segment of the curve: where the slab's hull is too coarse, near an obstacle, the
   Python path's exact translational test would say free too); 0 otherwise (the caller joins
   them, its "not free" included), R_ERROR. The caller's counts of that motion are made here. */
static int64_t join_end(Car *h, PyObject *grids, const double *p, const double *q1)
{
    if (p[0] == q1[0] && p[1] == q1[1] && p[2] == q1[2]) return 1;
    double a0 = p[2], a1 = q1[2];
    if (!(fabs(a1 - a0) <= PI)) return 0; /* across the wrap (or not finite): the caller's */
    if (!(h->xmin <= p[0] && p[0] <= h->xmax && h->ymin <= p[1] && p[1] <= h->ymax && h->xmin <= q1[0]
          && q1[0] <= h->xmax && h->ymin <= q1[1] && q1[1] <= h->ymax))
        return 0;
    int64_t k = slab_index(h->slab_lo, h->slab_hi, h->K, a0);
    if (k < 0 || !(h->slab_lo[k] <= a1 && a1 <= h->slab_hi[k])) return 0;
    PyObject *g = PyList_GET_ITEM(grids, k);
    if (g == Py_None) return 0;
    int r = fast_grid_segment(g, p[0], p[1], q1[0], q1[1]);
    if (r == -2) return R_ERROR;
    const char *how = "slab_certified";
    if (!(r == 1 || r == 3)) {
        if (a0 != a1) return 0; /* a turn past the slab's test: the caller's */
        int64_t f = fixed_sweep(h, grids, p[0], p[1], q1[0], q1[1], a0);
        if (f == R_ERROR) return R_ERROR;
        if (f != 1) return 0; /* a collision, the floor, undecided: the caller decides */
        how = "refined";
    }
    PyObject *d = h->checks;
    if (fast_add_count(d, "motions", 1) < 0 || fast_add_count(d, "submotions", 1) < 0
        || fast_add_count(d, how, 1) < 0)
        return R_ERROR;
    return 1;
}

static PyObject *check_chain(Car *h, PyObject *grids, const double *q, const Link *chain, int nl, int64_t res,
                             const double *p, double radius, const double *q1)
{
    long n_arcs = 0, n_sweeps = 0, n_coll = 0;
    if (res == 1) {
        res = car_pose(h, grids, q[0], q[1], q[2]);
        if (res == 0) n_coll++;
    }
    for (int i = 0; i < nl && res == 1; i++) { /* the probe: each knot and each segment's middle */
        const Link *L = chain + i;
        double mid[3];
        res = car_pose(h, grids, L->ex, L->ey, L->et);
        if (res == 1) {
            advance(L->sx, L->sy, L->st, L->kind, 0.5 * L->length, radius, mid);
            res = car_pose(h, grids, mid[0], mid[1], wrap_angle(mid[2]));
        }
        if (res == 0) n_coll++;
    }
    for (int i = 0; i < nl && res == 1; i++) /* straight segments */
        if (chain[i].kind == 'S') {
            res = straight(h, grids, chain[i].sx, chain[i].sy, chain[i].ex, chain[i].ey, chain[i].st);
            if (res == 0) n_coll++;
        }
    int64_t budget = h->max_hulls;
    for (int i = 0; i < nl && res == 1; i++) /* arcs */
        if (chain[i].kind != 'S') {
            n_arcs++;
            res = arc(h, grids, chain + i, radius, &budget, &n_sweeps);
            if (res == 0) n_coll++;
        }
    if (res == R_ERROR) return NULL;
    if (res >= 0) { /* decided: count as the Python path counts */
        PyObject *d = h->checks;
        if (fast_add_count(d, "arcs", n_arcs) < 0 || fast_add_count(d, "arc_sweeps", n_sweeps) < 0
            || fast_add_count(d, "motion_collisions", n_coll) < 0)
            return NULL;
    }
    long code = res >= 0 ? (long)res : (res == R_UNDECIDED ? -1 : (long)(-2 - (-3 - res)));
    if (code == 1 && q1) { /* 2: the join to q1 is certified too */
        int64_t j = join_end(h, grids, p, q1);
        if (j == R_ERROR) return NULL;
        if (j == 1) code = 2;
    }
    return Py_BuildValue("(lddd)", code, p[0], p[1], p[2]);
}

static Car *car_args(PyObject *const *args, const char *sig)
{
    Car *h = (Car *)PyCapsule_GetPointer(args[0], "cspace.compiled._fast.Car");
    if (!h) return NULL;
    if (!PyList_Check(args[1]) || PyList_GET_SIZE(args[1]) != h->K) {
        PyErr_Format(PyExc_TypeError, "%s: grids must be a list of one entry per slab", sig);
        return NULL;
    }
    return h;
}

static int doubles(PyObject *const *args, int n, double *out)
{
    for (int i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(args[i]);
        if (out[i] == -1.0 && PyErr_Occurred()) return -1;
    }
    return 0;
}

/* car_curve(handle, grids, x, y, th, segments, radius) -> (r, x, y, th): r 1 free, 0 not free,
   -1 undecided, -2 - k slab k not built; (x, y, th) the chain's end (th wrapped). */
PyObject *fast_car_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 7) {
        PyErr_SetString(PyExc_TypeError, "car_curve(handle, grids, x, y, th, segments, radius)");
        return NULL;
    }
    Car *h = car_args(args, "car_curve");
    if (!h) return NULL;
    double q[3], radius;
    if (doubles(args + 2, 3, q) < 0 || doubles(args + 6, 1, &radius) < 0) return NULL;
    int64_t res = 1;
    Link chain[MAX_SEGMENTS];
    int nl = 0;
    double p[3] = {q[0], q[1], q[2]};
    PyObject *seq = PySequence_Fast(args[5], "car_curve: segments must be a sequence");
    if (!seq) return NULL;
    Py_ssize_t ns = PySequence_Fast_GET_SIZE(seq);
    if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]) && isfinite(radius) && radius > 0.0) || ns > MAX_SEGMENTS)
        res = R_UNDECIDED;
    for (Py_ssize_t i = 0; i < ns && res == 1; i++) {
        PyObject *it = PySequence_Fast_GET_ITEM(seq, i);
        if (!PyTuple_Check(it) || PyTuple_GET_SIZE(it) != 2 || !PyUnicode_Check(PyTuple_GET_ITEM(it, 0))) {
            res = R_UNDECIDED;
            break;
        }
        Py_ssize_t klen;
        const char *ks = PyUnicode_AsUTF8AndSize(PyTuple_GET_ITEM(it, 0), &klen);
        if (!ks) {
            Py_DECREF(seq);
            return NULL;
        }
        double length = PyFloat_AsDouble(PyTuple_GET_ITEM(it, 1));
        if (length == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            res = R_UNDECIDED;
            break;
        }
        if (klen != 1 || (ks[0] != 'L' && ks[0] != 'S' && ks[0] != 'R') || !isfinite(length)) {
            res = R_UNDECIDED;
            break;
        }
        res = link_segment(chain, &nl, p, ks[0], length, radius);
    }
    Py_DECREF(seq);
    return check_chain(h, args[1], q, chain, nl, res, p, radius, NULL);
}

/* car_motion(handle, grids, x0, y0, th0, x1, y1, th1, radius, dubins, longest, turns[, join]) -> (r, x, y, th):
   the car's shortest curve from q0 to q1 (fast_car_segments: car_curves' segments, the same
   doubles) checked as car_curve checks it from q0 with its angle wrapped. -1 (undecided) also
   where the Python segments would differ in branch or fail pose_checks.curve_segments' bounds
   (a length above `longest`, an arc above `turns`): the caller runs the Python path. With
   `join` true, r is 2 where the chain is free and its end's join to q1 is certified here too
   (join_end: one slab's segment test), 1 where the chain is free and the join is the caller's. */
PyObject *fast_car_motion(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 12 && nargs != 13) {
        PyErr_SetString(PyExc_TypeError,
                        "car_motion(handle, grids, x0, y0, th0, x1, y1, th1, radius, dubins, longest, turns[, join])");
        return NULL;
    }
    Car *h = car_args(args, "car_motion");
    if (!h) return NULL;
    double v[9];
    if (doubles(args + 2, 7, v) < 0 || doubles(args + 10, 2, v + 7) < 0) return NULL;
    int dubins = PyObject_IsTrue(args[9]);
    if (dubins < 0) return NULL;
    int joined = nargs == 13 ? PyObject_IsTrue(args[12]) : 0;
    if (joined < 0) return NULL;
    const double *q0 = v, *q1 = v + 3;
    double radius = v[6], longest = v[7], turns = v[8];
    char kinds[5];
    double lengths[5];
    int64_t res = 1;
    int ns = -1, nl = 0;
    for (int i = 0; i < 6; i++)
        if (!isfinite(v[i])) res = R_UNDECIDED;
    if (!(isfinite(radius) && radius > 0.0)) res = R_UNDECIDED;
    if (res == 1) ns = fast_car_segments(dubins, q0, q1, radius, kinds, lengths);
    if (ns < 0) res = R_UNDECIDED;
    double q[3] = {q0[0], q0[1], wrap_angle(q0[2])};
    double p[3] = {q[0], q[1], q[2]};
    Link chain[MAX_SEGMENTS];
    for (int i = 0; i < ns && res == 1; i++) {
        if (!(fabs(lengths[i]) <= longest) || (kinds[i] != 'S' && fabs(lengths[i]) > turns)) {
            res = R_UNDECIDED;
            break;
        }
        res = link_segment(chain, &nl, p, kinds[i], lengths[i], radius);
    }
    double q1w[3] = {q1[0], q1[1], wrap_angle(q1[2])};
    return check_chain(h, args[1], q, chain, nl, res, p, radius, joined ? q1w : NULL);
}
