/* The compiled car words: cspace/car/reeds_shepp.py's reeds_shepp_word and
   cspace/car/dubins.py's dubins_word, the same float operations in the same order (libm's
   sin, cos, atan2, asin, acos, sqrt, fmod, floor: the functions CPython's math module calls),
   so the same word and the same doubles. Inputs or intermediates that are not finite return
   None: the Python functions decide (and raise where they raise). No decision is certified
   here: the words only say which curve a motion is; its poses are certified elsewhere. */
#include "_fast.h"

#define HALF_PI (0.5 * PI)

/* ------------------------------------------------------------------ Reeds-Shepp */

static const double RS_ZERO = 10.0 * 2.220446049250313e-16;

static inline double angle_pi(double x)
{
    double v = fmod(x, TWO_PI);
    if (v < -PI) v += TWO_PI;
    else if (v > PI) v -= TWO_PI;
    return v;
}

/* One argument triple (x, y, phi) of the formulas, with what several of them compute alike
   from it, computed once: sin(phi) and cos(phi); the start's left centre to the goal's left
   centre (X, Y) = (x - sin phi, y - 1 + cos phi) in polar form (_lsl, _lrl, _lrsl); the
   goal's right centre (xi, eta) = (x + sin phi, y - 1 - cos phi) and its norm (_lsr, the
   CCCC pair, _lrsr, _lrslr: -eta squared is eta squared and a sum of two squares does not
   depend on their order, so _lrsr's norm is this one too); the angle of (xi, eta) when
   _lsr asks for it. The same expressions as the Python formulas, so the same doubles. */
typedef struct {
    double x, y, phi, sp, cp;
    double X, Y, rhoA, thA;
    double xi, eta, rhoB, thB;
    int have_thB;
} Triple;

static void triple(Triple *T, double x, double y, double phi, double sp, double cp)
{
    T->x = x, T->y = y, T->phi = phi, T->sp = sp, T->cp = cp;
    T->X = x - sp, T->Y = y - 1.0 + cp;
    T->rhoA = sqrt(T->X * T->X + T->Y * T->Y), T->thA = atan2(T->Y, T->X);
    T->xi = x + sp, T->eta = y - 1.0 - cp;
    T->rhoB = sqrt(T->xi * T->xi + T->eta * T->eta);
    T->have_thB = 0;
}

/* A candidate whose |u| alone is at least the bound cannot be taken: its cost |t| + |u| + |v|,
   summed in floats, is at least |u| (each rounding is monotone and |u| a float), and a
   candidate replaces the best only when its cost is below the bound. Finite u only: a
   non-finite length is the caller's to see (it declines the word). */
#define UNBEATEN(u, bound) (isfinite(u) && fabs(u) >= (bound))

/* Each formula: 1 with (t, u, v) written, 0 for None (or, given the bound to beat, where
   UNBEATEN says it cannot be taken: the caller would drop it). */
static int rs_lsl(Triple *T, double bound, double *o)
{
    double u = T->rhoA, t = T->thA;
    if (t >= -RS_ZERO) {
        double v = angle_pi(T->phi - t);
        if (v >= -RS_ZERO) {
            o[0] = t, o[1] = u, o[2] = v;
            return 1;
        }
    }
    return 0;
}

static int rs_lsr(Triple *T, double bound, double *o)
{
    double d = T->rhoB;
    double d2 = d * d;
    if (d2 < 4.0) return 0;
    double u = sqrt(d2 - 4.0);
    if (UNBEATEN(u, bound)) return 0;
    if (!T->have_thB) T->thB = atan2(T->eta, T->xi), T->have_thB = 1;
    double t = angle_pi(T->thB + atan2(2.0, u));
    double v = angle_pi(t - T->phi);
    if (!(t >= -RS_ZERO && v >= -RS_ZERO)) return 0;
    o[0] = t, o[1] = u, o[2] = v;
    return 1;
}

static int rs_lrl(Triple *T, double bound, double *o)
{
    double rho = T->rhoA, theta = T->thA;
    if (rho > 4.0) return 0;
    double u = -2.0 * asin(0.25 * rho);
    double t = angle_pi(theta + 0.5 * u + PI);
    double v = angle_pi(T->phi - t + u);
    if (!(t >= -RS_ZERO && u <= RS_ZERO)) return 0;
    o[0] = t, o[1] = u, o[2] = v;
    return 1;
}

static void tau_omega(double u, double v, double xi, double eta, double phi, double *tau, double *omega)
{
    double delta = angle_pi(u - v);
    double a = sin(u) - sin(delta);
    double b = cos(u) - cos(delta) - 1.0;
    double t1 = atan2(eta * a - xi * b, xi * a + eta * b);
    double t2 = 2.0 * (cos(delta) - cos(v) - cos(u)) + 3.0;
    double t = t2 < 0.0 ? angle_pi(t1 + PI) : angle_pi(t1);
    *tau = t;
    *omega = angle_pi(t - u + v - phi);
}

static int rs_lrlr_a(Triple *T, double bound, double *o)
{
    double rho = 0.25 * (2.0 + T->rhoB);
    if (rho > 1.0) return 0;
    double u = acos(rho), t, v;
    tau_omega(u, -u, T->xi, T->eta, T->phi, &t, &v);
    if (!(t >= -RS_ZERO && v <= RS_ZERO)) return 0;
    o[0] = t, o[1] = u, o[2] = v;
    return 1;
}

static int rs_lrlr_b(Triple *T, double bound, double *o)
{
    double xi = T->xi, eta = T->eta;
    double rho = (20.0 - xi * xi - eta * eta) / 16.0;
    if (!(0.0 <= rho && rho <= 1.0)) return 0;
    double u = -acos(rho), t, v;
    if (u < -HALF_PI) return 0;
    tau_omega(u, u, xi, eta, T->phi, &t, &v);
    if (!(t >= -RS_ZERO && v >= -RS_ZERO)) return 0;
    o[0] = t, o[1] = u, o[2] = v;
    return 1;
}

static int rs_lrsl(Triple *T, double bound, double *o)
{
    double rho = T->rhoA, theta = T->thA;
    if (rho < 2.0) return 0;
    double r = sqrt(rho * rho - 4.0);
    double u = 2.0 - r;
    if (UNBEATEN(u, bound)) return 0;
    double t = angle_pi(theta + atan2(r, -2.0));
    double v = angle_pi(T->phi - HALF_PI - t);
    if (!(t >= -RS_ZERO && u <= RS_ZERO && v <= RS_ZERO)) return 0;
    o[0] = t, o[1] = u, o[2] = v;
    return 1;
}

static int rs_lrsr(Triple *T, double bound, double *o)
{
    double rho = T->rhoB; /* the norm of (-eta, xi) */
    if (rho < 2.0) return 0;
    double u = 2.0 - rho;
    if (UNBEATEN(u, bound)) return 0;
    double t = atan2(T->xi, -T->eta);
    double v = angle_pi(t + HALF_PI - T->phi);
    if (!(t >= -RS_ZERO && u <= RS_ZERO && v <= RS_ZERO)) return 0;
    o[0] = t, o[1] = u, o[2] = v;
    return 1;
}

static int rs_lrslr(Triple *T, double bound, double *o)
{
    double xi = T->xi, eta = T->eta, rho = T->rhoB; /* (the Python formula's unused angle: not computed) */
    if (rho < 2.0) return 0;
    double u = 4.0 - sqrt(rho * rho - 4.0);
    if (u > RS_ZERO || UNBEATEN(u, bound)) return 0;
    double t = angle_pi(atan2((4.0 - u) * xi - 2.0 * eta, -2.0 * xi + (u - 4.0) * eta));
    double v = angle_pi(t - T->phi);
    if (!(t >= -RS_ZERO && v >= -RS_ZERO)) return 0;
    o[0] = t, o[1] = u, o[2] = v;
    return 1;
}

typedef int (*rs_solve)(Triple *, double, double *);

/* Layouts of GROUPS: the lengths from (t, u, v). */
enum { L_TUV, L_VUT, L_LRLR_A, L_LRLR_B, L_CCSC, L_CSCC, L_CCSCC };

typedef struct {
    rs_solve solve;
    const char *word, *mirror;
    int layout, backwards, lrlr;
} Formula;

static const Formula F_G0[] = {{rs_lsl, "LSL", "RSR", L_TUV, 0, 0}, {rs_lsr, "LSR", "RSL", L_TUV, 0, 0}};
static const Formula F_G1[] = {{rs_lrl, "LRL", "RLR", L_TUV, 0, 0}, {rs_lrl, "LRL", "RLR", L_VUT, 1, 0}};
static const Formula F_G2[] = {{rs_lrlr_a, "LRLR", "RLRL", L_LRLR_A, 0, 1}, {rs_lrlr_b, "LRLR", "RLRL", L_LRLR_B, 0, 1}};
static const Formula F_G3[] = {{rs_lrsl, "LRSL", "RLSR", L_CCSC, 0, 0},
                               {rs_lrsr, "LRSR", "RLSL", L_CCSC, 0, 0},
                               {rs_lrsl, "LSRL", "RSLR", L_CSCC, 1, 0},
                               {rs_lrsr, "RSRL", "LSLR", L_CSCC, 1, 0}};
static const Formula F_G4[] = {{rs_lrslr, "LRSLR", "RLSRL", L_CCSCC, 0, 0}};

typedef struct {
    double fixed;
    const Formula *f;
    int n;
} Group;

static int layout(int kind, const double *tuv, double *out)
{
    double t = tuv[0], u = tuv[1], v = tuv[2];
    switch (kind) {
    case L_TUV: out[0] = t, out[1] = u, out[2] = v; return 3;
    case L_VUT: out[0] = v, out[1] = u, out[2] = t; return 3;
    case L_LRLR_A: out[0] = t, out[1] = u, out[2] = -u, out[3] = v; return 4;
    case L_LRLR_B: out[0] = t, out[1] = u, out[2] = u, out[3] = v; return 4;
    case L_CCSC: out[0] = t, out[1] = -HALF_PI, out[2] = u, out[3] = v; return 4;
    case L_CSCC: out[0] = v, out[1] = u, out[2] = -HALF_PI, out[3] = t; return 4;
    default: out[0] = t, out[1] = -HALF_PI, out[2] = u, out[3] = -HALF_PI, out[4] = v; return 5;
    }
}

/* reeds_shepp_word: 1 with the word and lengths written, 0 none, -1 not finite. The formulas
   see 8 argument triples (4 symmetries, read forwards or backwards), each prepared once. */
static int rs_word(double x, double y, double phi, const char **word, double *best, int *nbest)
{
    const Group groups[5] = {{0.0, F_G0, 2}, {0.0, F_G1, 2}, {0.0, F_G2, 2}, {HALF_PI, F_G3, 4}, {PI, F_G4, 1}};
    double total = HUGE_VAL;
    int found = 0;
    double cp = cos(phi), sp = sin(phi), cm = cos(-phi), sm = sin(-phi);
    double bx = x * cp + y * sp, by = x * sp - y * cp;
    Triple tri[8];
    int ready[8] = {0};
    for (int g = 0; g < 5; g++) {
        double bound = total - groups[g].fixed;
        for (int k = 0; k < groups[g].n; k++) {
            const Formula *F = groups[g].f + k;
            double fx = F->backwards ? bx : x, fy = F->backwards ? by : y;
            const double gx[4] = {fx, -fx, fx, -fx}, gy[4] = {fy, fy, -fy, -fy}, gp[4] = {phi, -phi, -phi, phi};
            for (int s = 0; s < 4; s++) {
                double tuv[3];
                Triple *T = tri + 4 * F->backwards + s;
                if (!ready[4 * F->backwards + s]) {
                    int neg = s == 1 || s == 2;
                    triple(T, gx[s], gy[s], gp[s], neg ? sm : sp, neg ? cm : cp);
                    ready[4 * F->backwards + s] = 1;
                }
                if (!F->solve(T, bound, tuv)) continue;
                double t = tuv[0], u = tuv[1], v = tuv[2];
                if (!(isfinite(t) && isfinite(u) && isfinite(v))) return -1;
                double cost = F->lrlr ? fabs(t) + 2.0 * fabs(u) + fabs(v) : fabs(t) + fabs(u) + fabs(v);
                if (cost < bound) {
                    int n = layout(F->layout, tuv, best);
                    if (s == 1 || s == 3)
                        for (int i = 0; i < n; i++) best[i] = -best[i];
                    *nbest = n;
                    *word = s < 2 ? F->word : F->mirror;
                    bound = cost;
                    found = 1;
                }
            }
        }
        if (found) {
            double sum = 0.0;
            for (int i = 0; i < *nbest; i++) sum = sum + fabs(best[i]);
            total = sum;
        }
    }
    return found;
}

static PyObject *word_result(const char *word, const double *lengths, int n)
{
    PyObject *w = PyUnicode_FromString(word);
    if (!w) return NULL;
    PyObject *t = PyTuple_New(n);
    if (!t) {
        Py_DECREF(w);
        return NULL;
    }
    for (int i = 0; i < n; i++) {
        PyObject *f = PyFloat_FromDouble(lengths[i]);
        if (!f) {
            Py_DECREF(w);
            Py_DECREF(t);
            return NULL;
        }
        PyTuple_SET_ITEM(t, i, f);
    }
    PyObject *out = PyTuple_Pack(2, w, t);
    Py_DECREF(w);
    Py_DECREF(t);
    return out;
}

static int three_doubles(PyObject *const *args, Py_ssize_t nargs, double *q, const char *sig)
{
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, sig);
        return -1;
    }
    for (int i = 0; i < 3; i++) {
        q[i] = PyFloat_AsDouble(args[i]);
        if (q[i] == -1.0 && PyErr_Occurred()) return -1;
    }
    return 0;
}

/* reeds_shepp_word(x, y, phi) -> (word, lengths) or None (the Python function decides). */
PyObject *fast_reeds_shepp_word(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double q[3], best[5];
    const char *word = NULL;
    int n = 0;
    if (three_doubles(args, nargs, q, "reeds_shepp_word(x, y, phi)") < 0) return NULL;
    /* Finite and far from overflow (|x|^2 and the turns' arguments stay finite). */
    if (!(fabs(q[0]) < 1e150 && fabs(q[1]) < 1e150 && fabs(q[2]) < 1e150)) Py_RETURN_NONE;
    if (rs_word(q[0], q[1], q[2], &word, best, &n) != 1) Py_RETURN_NONE;
    return word_result(word, best, n);
}

/* ------------------------------------------------------------------ Dubins */

#define SNAP_BELOW 1e-7
#define SNAP_FULL 0.5e-6
#define DUBINS_NEAR 1e-6

static inline double turn_angle(double x)
{
    if (-SNAP_BELOW < x && x < 0.0) return 0.0;
    double m = x - TWO_PI * floor(x / TWO_PI);
    return TWO_PI - m < SNAP_FULL ? 0.0 : m;
}

static inline double nonneg(double p2) { return 0.0 > p2 ? 0.0 : p2; }

static int d_lsl(double d, double a, double b, double *o)
{
    double sa = sin(a), ca = cos(a), sb = sin(b), cb = cos(b);
    double p2 = 2.0 + d * d - 2.0 * (ca * cb + sa * sb) + 2.0 * d * (sa - sb);
    if (p2 < -SNAP_BELOW) return 0;
    double psi = atan2(cb - ca, d + sa - sb);
    o[0] = turn_angle(psi - a), o[1] = sqrt(nonneg(p2)), o[2] = turn_angle(b - psi);
    return 1;
}

static int d_rsr(double d, double a, double b, double *o)
{
    double sa = sin(a), ca = cos(a), sb = sin(b), cb = cos(b);
    double p2 = 2.0 + d * d - 2.0 * (ca * cb + sa * sb) + 2.0 * d * (sb - sa);
    if (p2 < -SNAP_BELOW) return 0;
    double psi = atan2(ca - cb, d - sa + sb);
    o[0] = turn_angle(a - psi), o[1] = sqrt(nonneg(p2)), o[2] = turn_angle(psi - b);
    return 1;
}

static int d_rsl(double d, double a, double b, double *o)
{
    double sa = sin(a), ca = cos(a), sb = sin(b), cb = cos(b);
    double p2 = d * d - 2.0 + 2.0 * (ca * cb + sa * sb) - 2.0 * d * (sa + sb);
    if (p2 < -SNAP_BELOW) return 0;
    double p = sqrt(nonneg(p2));
    double psi = atan2(ca + cb, d - sa - sb) - atan2(2.0, p);
    o[0] = turn_angle(a - psi), o[1] = p, o[2] = turn_angle(b - psi);
    return 1;
}

static int d_lsr(double d, double a, double b, double *o)
{
    double sa = sin(a), ca = cos(a), sb = sin(b), cb = cos(b);
    double p2 = d * d - 2.0 + 2.0 * (ca * cb + sa * sb) + 2.0 * d * (sa + sb);
    if (p2 < -SNAP_BELOW) return 0;
    double p = sqrt(nonneg(p2));
    double psi = atan2(-ca - cb, d + sa + sb) + atan2(2.0, p);
    o[0] = turn_angle(psi - a), o[1] = p, o[2] = turn_angle(psi - b);
    return 1;
}

static int d_rlr(double d, double a, double b, double *o)
{
    double sa = sin(a), ca = cos(a), sb = sin(b), cb = cos(b);
    double c = (6.0 - d * d + 2.0 * (ca * cb + sa * sb) + 2.0 * d * (sa - sb)) / 8.0;
    if (!(fabs(c) < 1.0)) return 0;
    double p = TWO_PI - acos(c);
    double psi = atan2(ca - cb, d - sa + sb);
    double t = turn_angle(a - psi + 0.5 * p);
    o[0] = t, o[1] = p, o[2] = turn_angle(a - b - t + p);
    return 1;
}

static int d_lrl(double d, double a, double b, double *o)
{
    double sa = sin(a), ca = cos(a), sb = sin(b), cb = cos(b);
    double c = (6.0 - d * d + 2.0 * (ca * cb + sa * sb) - 2.0 * d * (sa - sb)) / 8.0;
    if (!(fabs(c) < 1.0)) return 0;
    double p = TWO_PI - acos(c);
    double psi = atan2(cb - ca, d + sa - sb);
    double t = turn_angle(psi - a + 0.5 * p);
    o[0] = t, o[1] = p, o[2] = turn_angle(b - a - t + p);
    return 1;
}

/* dubins_word_pure's choice: 1 with the word and (t, p, q) written, 0 where the Python
   function must decide (huge or non-finite values). */
static int dubins_best(double d, double alpha, double beta, const char **word, double *best)
{
    static const char *words[6] = {"LSL", "RSR", "RSL", "LSR", "RLR", "LRL"};
    int (*solvers[6])(double, double, double, double *) = {d_lsl, d_rsr, d_rsl, d_lsr, d_rlr, d_lrl};
    double bsum = 0.0;
    best[0] = best[1] = best[2] = 0.0;
    if (!(fabs(d) < 1e150 && fabs(alpha) < 1e150 && fabs(beta) < 1e150)) return 0;
    if (d < DUBINS_NEAR && fabs(alpha - beta) < DUBINS_NEAR) {
        best[1] = d;
        *word = "LSL";
        return 1;
    }
    int found = -1;
    for (int w = 0; w < 6; w++) {
        double o[3];
        if (!solvers[w](d, alpha, beta, o)) continue;
        if (!(isfinite(o[0]) && isfinite(o[1]) && isfinite(o[2]))) return 0;
        double s = 0.0 + o[0] + o[1] + o[2];
        if (found < 0 || s < bsum) {
            found = w, bsum = s;
            best[0] = o[0], best[1] = o[1], best[2] = o[2];
        }
    }
    if (found < 0) return 0;
    *word = words[found];
    return 1;
}

/* dubins_word(d, alpha, beta) -> (word, (t, p, q)) or None (the Python function decides). */
PyObject *fast_dubins_word(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double q[3], best[3];
    const char *word = NULL;
    if (three_doubles(args, nargs, q, "dubins_word(d, alpha, beta)") < 0) return NULL;
    if (!dubins_best(q[0], q[1], q[2], &word, best)) Py_RETURN_NONE;
    return word_result(word, best, 3);
}

/* ------------------------------------------------------------------ segments */

/* car_curves.dubins_segments / reeds_shepp_segments for poses of three finite floats and a
   valid radius r, with the same doubles: the frame (dubins_frame / reeds_shepp_frame), the
   word, then each nonzero length times r. Writes up to 5 segments (kinds 'L' 'S' 'R') and
   returns their count, or -1 wherever the Python function would take another branch (a
   heading beyond 2^20 that it wraps first, a frame past 1e100 radii, a word the compiled
   one declines, a length that overflows): the caller then runs the Python function. */
int fast_car_segments(int dubins, const double *q0, const double *q1, double r, char *kinds, double *lengths)
{
    if (!(fabs(q0[2]) <= 0x1p20 && fabs(q1[2]) <= 0x1p20)) return -1;
    double dx = q1[0] - q0[0], dy = q1[1] - q0[1], best[5];
    const char *word = NULL;
    int n = 3;
    if (dubins) {
        double th = atan2(dy, dx);
        double d = sqrt(dx * dx + dy * dy) / r, alpha = turn_angle(q0[2] - th), beta = turn_angle(q1[2] - th);
        if (!(fabs(d) <= 1e100 && fabs(alpha) <= 1e100)) return -1;
        if (!dubins_best(d, alpha, beta, &word, best)) return -1;
    } else {
        double c = cos(q0[2]), s = sin(q0[2]);
        double x = (c * dx + s * dy) / r, y = (-s * dx + c * dy) / r, phi = q1[2] - q0[2];
        if (!(fabs(x) <= 1e100 && fabs(y) <= 1e100)) return -1;
        if (!(fabs(x) < 1e150 && fabs(y) < 1e150 && fabs(phi) < 1e150)) return -1;
        if (rs_word(x, y, phi, &word, best, &n) != 1) return -1;
    }
    int m = 0;
    for (int i = 0; i < n; i++) {
        if (best[i] == 0.0) continue;
        double v = best[i] * r;
        if (!isfinite(v)) return -1;
        kinds[m] = word[i], lengths[m++] = v;
    }
    return m;
}
