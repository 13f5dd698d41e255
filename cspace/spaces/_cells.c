/* The grid build (part of cspace.spaces._fast): classify() is CellClassifier's
   numpy route (cspace/spaces/cellclass.py, _classify_many and its evaluate) in C, with
   the same float operations in the same order, so the same grid.

   Each piece's edge i -> i+1 (padded vertices Q, local frame) is a half-plane
   n . x <= c with n = (e_y, -e_x) / hypot(e_y, -e_x), c = n_x Q_x + n_y Q_y; over a cell
   the signed distance of its corners ranges over d + lo .. d + hi with
   hi = max(n_x, 0) cw + max(n_y, 0) ch, lo = min(n_x, 0) cw + min(n_y, 0) ch (less the
   chord's sagitta for chord polygons), d = (x_off + i cw) n_x + (y_off + j ch) n_y - c.
   A cell is inside when d <= -m - hi for every edge, separated when d >= m - lo for one;
   its mask sums the weights (bit (i + 1) mod size, 0 for wide pieces) of the edges it is
   not strictly inside. Cells not separated are written (piece id, cell j nx + i, inside,
   mask; WIDE_MASK for wide pieces), piece by piece, row-major: the entries
   CellClassifier._gathered makes of the numpy route's. No filter and no rounding argument
   of its own: the numpy route's doubles. NaN normals (a piece rounded to a point) propagate as numpy's maximum and
   minimum propagate them: no cell is inside or separated by such an edge.

   Three shortcuts change no output: a separated cell is not written, so its remaining
   edges are skipped; a piece's padded slots (after its own edges) would leave every cell
   strictly inside with weight 0, so they are not evaluated; and along a row of cells
   only the ends are evaluated. Why the last is exact: along a row, d is computed from
   x_off + i cw by a product and two sums with fixed operands, and rounding is monotone,
   so each edge's d is a monotone function of i in doubles too. Each edge's "strictly
   inside" thus holds on a prefix or a suffix of the row, and so does its "strictly
   outside": the inside cells (every edge inside) form one run, and so do the cells not
   separated (no edge outside). The row is scanned from its left end to the first cell
   not separated and from its right end likewise; between them, from the left to the
   first inside cell and from the right to the last; every cell between those two is
   inside (mask 0) without a test. The entries come out in the same order.

   assemble() turns the classified entries into the grid's arrays, as GridIndex's numpy
   route does. */
#include "_fast.h"

/* numpy's maximum(x, 0.0) and minimum(x, 0.0): NaN propagates. */
static inline double max0(double x) { return (x >= 0.0 || isnan(x)) ? x : 0.0; }
static inline double min0(double x) { return (x <= 0.0 || isnan(x)) ? x : 0.0; }

/* A piece's half-planes (per edge: outward unit normal, offset, the cell's corner spread
   hi and lo, mask weight), its edge count and the grid's margin. */
typedef struct {
    double *nx, *ny, *c, *hi, *lo;
    int64_t *w;
    int64_t s;
    double m;
} Edges;

enum { SEPARATED = 0, MEETS = 1, INSIDE = 2 };

/* The cell with corner (cx0, cy0): SEPARATED (one edge has it strictly outside by the
   margin; its other edges skipped), INSIDE (every edge has it strictly inside by the
   margin) or MEETS, with *mask the weights of the edges it is not strictly inside. */
static inline int cell_test(const Edges *h, double cx0, double cy0, int64_t *mask)
{
    int inside = 1;
    int64_t mk = 0;
    for (int64_t e = 0; e < h->s; e++) {
        double d = cx0 * h->nx[e];
        d += cy0 * h->ny[e];
        d -= h->c[e];
        if (!(d <= -h->m - h->hi[e])) {
            inside = 0;
            mk += h->w[e];
        }
        if (d >= h->m - h->lo[e]) return SEPARATED;
    }
    *mask = mk;
    return inside ? INSIDE : MEETS;
}

/* Write the entry of cell i of the current row: a wide piece's mask is wide_mask. */
#define PUT(i, in, mk)                                                                   \
    (opiece[n] = id, ocell[n] = row0 + (i), oin[n] = (uint8_t)(in), omask[n] = is_wide ? (int64_t)wide_mask : (mk), n++)

/* classify(Q, sizes, sag, wide, rows, i0, i1, j0, j1, x_off, y_off, cw, ch, m,
            ids, nx, wide_mask, out_piece, out_cell, out_inside, out_mask) -> count

   Q: float64 K x E x 2; sizes: int64 K; sag: float64 K x E, or empty (no chords);
   wide: uint8 K (WIDE pieces: weights 0, mask wide_mask); rows: int64, the pieces to
   classify; i0..j1: int64 K, each piece's box of cells; ids: int64 K, each piece's id
   in the grid; nx: the grid's columns; outputs: room for the rows' boxes' cells. */
PyObject *fast_classify(PyObject *self, PyObject *args)
{
    PyObject *o[14];
    double x_off, y_off, cw, ch, m;
    long long gnx, wide_mask;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOdddddOLLOOOO", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6], &o[7],
                          &o[8], &x_off, &y_off, &cw, &ch, &m, &o[9], &gnx, &wide_mask, &o[10], &o[11], &o[12],
                          &o[13]))
        return NULL;
    Py_buffer b[14];
    int got = 0;
    Py_ssize_t count = -1;
    double *hp = NULL;
    int64_t *right = NULL;
    for (; got < 14; got++) {
        int flags = got >= 10 ? (PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) : PyBUF_C_CONTIGUOUS;
        if (PyObject_GetBuffer(o[got], &b[got], flags) < 0) goto done;
    }
    const double *Q = b[0].buf, *sag = b[2].buf;
    const int64_t *sizes = b[1].buf, *rows = b[4].buf, *i0 = b[5].buf, *i1 = b[6].buf, *j0 = b[7].buf, *j1 = b[8].buf;
    const int64_t *ids = b[9].buf;
    const uint8_t *wide = b[3].buf;
    int64_t *opiece = b[10].buf, *ocell = b[11].buf, *omask = b[13].buf;
    uint8_t *oin = b[12].buf;
    Py_ssize_t K = b[1].len / 8, R = b[4].len / 8, cap = b[10].len / 8;
    Py_ssize_t E = K ? b[0].len / 16 / K : 0;
    int has_sag = b[2].len > 0;
    if (b[0].len != 16 * K * E || (has_sag && b[2].len != 8 * K * E) || b[3].len != K || b[5].len != 8 * K
        || b[6].len != 8 * K || b[7].len != 8 * K || b[8].len != 8 * K || b[9].len != 8 * K
        || b[11].len != 8 * cap || b[12].len != cap || b[13].len != 8 * cap) {
        PyErr_SetString(PyExc_ValueError, "_fast.classify: inconsistent array sizes");
        goto done;
    }
    hp = PyMem_Malloc(sizeof(double) * 6 * (E ? E : 1)); /* per edge: n_x, n_y, c, hi, lo, weight */
    if (!hp) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t n = 0, width = 1;
    for (Py_ssize_t t = 0; t < R; t++) { /* the widest box: room for a row's right run */
        int64_t r = rows[t];
        if (r < 0 || r >= K || sizes[r] < 1 || sizes[r] > E) {
            PyErr_SetString(PyExc_ValueError, "_fast.classify: a row or size out of range");
            goto done;
        }
        if (i1[r] - i0[r] + 1 > width) width = i1[r] - i0[r] + 1;
    }
    right = PyMem_Malloc(sizeof(int64_t) * (size_t)width);
    if (!right) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t t = 0; t < R; t++) {
        int64_t r = rows[t];
        int64_t s = sizes[r];
        const double *q = Q + 2 * r * E;
        Edges h = {hp, hp + E, hp + 2 * E, hp + 3 * E, hp + 4 * E, (int64_t *)(hp + 5 * E), s, m};
        for (int64_t e = 0; e < s; e++) { /* the half-planes, as _classify_many computes them */
            int64_t f = e + 1 < s ? e + 1 : 0;
            double ex = q[2 * f] - q[2 * e], ey = q[2 * f + 1] - q[2 * e + 1];
            double len = hypot(ey, -ex);
            h.nx[e] = ey / len, h.ny[e] = -ex / len;
            h.c[e] = h.nx[e] * q[2 * e] + h.ny[e] * q[2 * e + 1];
            h.hi[e] = max0(h.nx[e]) * cw + max0(h.ny[e]) * ch;
            h.lo[e] = min0(h.nx[e]) * cw + min0(h.ny[e]) * ch;
            if (has_sag) h.lo[e] -= sag[r * E + e];
            h.w[e] = wide[r] ? 0 : (int64_t)((uint64_t)1 << ((e + 1) % s));
        }
        int64_t id = ids[r];
        int is_wide = wide[r] != 0;
        for (int64_t j = j0[r]; j <= j1[r]; j++) {
            double cy0 = y_off + (double)j * ch;
            int64_t row0 = j * (int64_t)gnx, L = i0[r], Rr = i1[r], ml = 0, mr = 0;
            int tl = SEPARATED, tr;
            /* The row's cells not separated: [L, Rr], from either end. */
            for (; L <= Rr; L++)
                if ((tl = cell_test(&h, x_off + (double)L * cw, cy0, &ml)) != SEPARATED) break;
            if (L > Rr) continue;
            if (n + (Rr - L + 1) > cap) {
                PyErr_SetString(PyExc_ValueError, "_fast.classify: outputs too small");
                goto done;
            }
            tr = tl, mr = ml;
            for (; Rr > L; Rr--)
                if ((tr = cell_test(&h, x_off + (double)Rr * cw, cy0, &mr)) != SEPARATED) break;
            if (Rr == L) tr = tl, mr = ml;
            /* From L rightwards up to the first inside cell a. */
            int64_t a = L, mk = ml;
            int ta = tl;
            for (;;) {
                PUT(a, ta == INSIDE, mk);
                if (ta == INSIDE || a == Rr) break;
                a++;
                if (a == Rr) ta = tr, mk = mr;
                else ta = cell_test(&h, x_off + (double)a * cw, cy0, &mk);
            }
            if (ta != INSIDE) continue; /* no inside cell: the row is written */
            /* From Rr leftwards down to the last inside cell b; then (a, b] inside, then (b, Rr]. */
            int64_t b = Rr, nr = 0;
            int tb = tr;
            mk = mr;
            while (b > a && tb != INSIDE) {
                right[nr++] = mk;
                b--;
                if (b > a) tb = cell_test(&h, x_off + (double)b * cw, cy0, &mk);
            }
            for (int64_t i = a + 1; i <= b; i++) PUT(i, 1, 0);
            for (int64_t k = nr - 1; k >= 0; k--) PUT(Rr - k, 0, right[k]);
        }
    }
    count = n;
done:
    PyMem_Free(hp);
    PyMem_Free(right);
    for (int k = 0; k < got; k++) PyBuffer_Release(&b[k]);
    return count < 0 ? NULL : PyLong_FromSsize_t(count);
}

/* assemble(cc, cp, cm, inside, npieces, out_state, out_blocker, out_starts, out_cand, out_masks)
       -> (free, mixed, blocked) cell counts

   The grid from its classified (cell, piece, mask, inside) entries, as GridIndex's numpy
   route assembles it: a cell inside a piece is BLOCKED, its blocker the largest such
   piece; the other entries are the candidates, by cell and then piece (a counting sort
   by cell, then each cell's few candidates by piece), a cell with a candidate and no
   blocker MIXED, starts[c] .. starts[c + 1] the candidates of cell c. Outputs: state
   int8 (cells, zeroed here), blocker int64 (cells), starts int64 (cells + 1), cand and
   masks int64 (room for every entry). */
PyObject *fast_assemble(PyObject *self, PyObject *args)
{
    PyObject *o[9];
    Py_ssize_t npieces;
    if (!PyArg_ParseTuple(args, "OOOOnOOOOO", &o[0], &o[1], &o[2], &o[3], &npieces, &o[4], &o[5], &o[6], &o[7], &o[8]))
        return NULL;
    Py_buffer b[9];
    int got = 0, ok = 0;
    Py_ssize_t cells = 0, mixed = 0, blocked = 0;
    for (; got < 9; got++) {
        int flags = got >= 4 ? (PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) : PyBUF_C_CONTIGUOUS;
        if (PyObject_GetBuffer(o[got], &b[got], flags) < 0) goto done;
    }
    const int64_t *cc = b[0].buf, *cp = b[1].buf, *cm = b[2].buf;
    const uint8_t *inside = b[3].buf;
    int8_t *state = b[4].buf;
    int64_t *blocker = b[5].buf, *starts = b[6].buf, *cand = b[7].buf, *masks = b[8].buf;
    Py_ssize_t n = b[0].len / 8;
    cells = b[4].len;
    if (b[1].len != 8 * n || b[2].len != 8 * n || b[3].len != n || b[5].len != 8 * cells
        || b[6].len != 8 * (cells + 1) || b[7].len < 8 * n || b[8].len < 8 * n) {
        PyErr_SetString(PyExc_ValueError, "_fast.assemble: inconsistent array sizes");
        goto done;
    }
    memset(state, 0, (size_t)cells);
    memset(starts, 0, sizeof(int64_t) * (size_t)(cells + 1));
    memset(blocker, 0xff, sizeof(int64_t) * (size_t)cells); /* every byte 0xff: -1 */
    for (Py_ssize_t t = 0; t < n; t++) {
        if (cc[t] < 0 || cc[t] >= cells || cp[t] < 0 || cp[t] >= npieces) {
            PyErr_SetString(PyExc_ValueError, "_fast.assemble: a cell or piece out of range");
            goto done;
        }
        if (inside[t]) {
            state[cc[t]] = 2; /* BLOCKED */
            if (cp[t] > blocker[cc[t]]) blocker[cc[t]] = cp[t];
        } else {
            starts[cc[t] + 1]++;
        }
    }
    /* starts[c + 1] becomes the first slot of cell c (the counts' exclusive prefix sums); placing
       cell c's candidates advances it to cell c's end, which is cell c + 1's start: the
       counting sort needs no cursor array of its own. */
    int64_t run = 0;
    for (Py_ssize_t c = 0; c < cells; c++) {
        int64_t count = starts[c + 1];
        if (count && state[c] != 2) state[c] = 1; /* MIXED */
        mixed += state[c] == 1, blocked += state[c] == 2;
        starts[c + 1] = run;
        run += count;
    }
    for (Py_ssize_t t = 0; t < n; t++) { /* by cell, each cell's candidates in entry order... */
        if (inside[t]) continue;
        int64_t k = starts[cc[t] + 1]++;
        cand[k] = cp[t], masks[k] = cm[t];
    }
    for (Py_ssize_t c = 0; c < cells; c++) { /* ... then by piece (insertion sort: a few each) */
        for (int64_t k = starts[c] + 1; k < starts[c + 1]; k++) {
            int64_t p = cand[k], m = masks[k], h = k;
            for (; h > starts[c] && cand[h - 1] > p; h--) cand[h] = cand[h - 1], masks[h] = masks[h - 1];
            cand[h] = p, masks[h] = m;
        }
    }
    ok = 1;
done:
    for (int k = 0; k < got; k++) PyBuffer_Release(&b[k]);
    if (!ok) return NULL;
    return Py_BuildValue("(nnn)", cells - mixed - blocked, mixed, blocked);
}
