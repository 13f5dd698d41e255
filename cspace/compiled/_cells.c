/* The grid build (part of cspace.compiled._fast): entries() is CellClassifier's numpy
   route (cspace/translation/cellclass.py, _classify_all, _classify_many and its evaluate) in C,
   piece by piece from the packed vertices, with the same float operations in the same
   order, so the same grid: the local frame's shift, each box's cells, the chord polygons
   of pieces of more than mask_edges edges (_chords.c), the half-planes and the cells.

   Each piece's edge i -> i+1 (its vertices Q in the local frame) is a half-plane
   n . x <= c with n = (e_y, -e_x) / hypot(e_y, -e_x), c = n_x Q_x + n_y Q_y; over a cell
   the signed distance of its corners ranges over d + lo .. d + hi with
   hi = max(n_x, 0) cw + max(n_y, 0) ch, lo = min(n_x, 0) cw + min(n_y, 0) ch (less the
   chord's sagitta for chord polygons), d = (x_off + i cw) n_x + (y_off + j ch) n_y - c.
   A cell is inside when d <= -m - hi for every edge, separated when d >= m - lo for one;
   its mask sums the weights (bit (i + 1) mod size, 0 for wide pieces) of the edges it is
   not strictly inside. Cells not separated are written (piece id, cell j nx + i, inside,
   mask; WIDE_MASK for wide pieces), piece by piece, row-major: the entries
   CellClassifier._gathered makes of the numpy route's, up to their order (which the
   assembly does not see). No filter and no rounding argument of its own: the numpy
   route's doubles. NaN normals (a piece rounded to a point) propagate as numpy's maximum
   and minimum propagate them: no cell is inside or separated by such an edge.

   Two shortcuts change no output: a separated cell is not written, so its remaining
   edges are skipped; and along a row of cells only the ends are evaluated. Why the
   second is exact: along a row, d is computed from x_off + i cw by a product and two
   sums with fixed operands, and rounding is monotone, so each edge's d is a monotone
   function of i in doubles too. Each edge's "strictly
   inside" thus holds on a prefix or a suffix of the row, and so does its "strictly
   outside": the inside cells (every edge inside) form one run, and so do the cells not
   separated (no edge outside). The row is scanned from its left end to the first cell
   not separated and from its right end likewise; between them, from the left to the
   first inside cell and from the right to the last; every cell between those two is
   inside (mask 0) without a test. The entries come out row-major all the same.

   assemble() turns the classified entries into the grid's arrays, as GridIndex's numpy
   route does. */
#include "_fast.h"

/* numpy's maximum(x, 0.0) and minimum(x, 0.0): NaN propagates. */
static inline double max0(double x) { return (x >= 0.0 || isnan(x)) ? x : 0.0; }
static inline double min0(double x) { return (x <= 0.0 || isnan(x)) ? x : 0.0; }

/* A piece's half-planes (per edge: outward unit normal, offset, the thresholds of strictly
   inside and strictly outside, mask weight), the last separating edge, its edge count and
   the grid's margin. */
typedef struct {
    double *nx, *ny, *c, *in, *out;
    int64_t *w;
    int64_t s, hint;
    double m;
} Edges;

/* Where classified cells go: the grid's frame (x_off, y_off: the local frame's offset of
   cell (0, 0); cell size; margin; columns), the entry arrays (room for cap entries, n
   written), and a row's scratch (right: one int64 per column). */
typedef struct {
    double x_off, y_off, cw, ch, m;
    int64_t gnx, wide_mask;
    int64_t *piece, *cell, *mask;
    uint8_t *inside;
    Py_ssize_t n, cap;
    int64_t *right;
} Out;

enum { SEPARATED = 0, MEETS = 1, INSIDE = 2 };

/* The cell with corner (cx0, cy0): SEPARATED (one edge has it strictly outside by the
   margin), INSIDE (every edge has it strictly inside by the margin) or MEETS, with *mask
   the weights of the edges it is not strictly inside. The answer does not depend on the
   order the edges are taken in (any separating edge gives SEPARATED; INSIDE and the mask
   read every edge), so the edge that separated the last separated cell (its neighbour,
   mostly) is tried first. Strictly outside implies not strictly inside (in < 0 < out),
   so the outside test sits in the not-inside branch. */
static inline int cell_test(Edges *h, double cx0, double cy0, int64_t *mask)
{
    int64_t e = h->hint;
    double d = cx0 * h->nx[e];
    d += cy0 * h->ny[e];
    d -= h->c[e];
    if (d >= h->out[e]) return SEPARATED;
    int inside = 1;
    int64_t mk = 0;
    for (e = 0; e < h->s; e++) {
        d = cx0 * h->nx[e];
        d += cy0 * h->ny[e];
        d -= h->c[e];
        if (!(d <= h->in[e])) { /* NaN: not inside, not outside, as in numpy */
            inside = 0;
            mk += h->w[e];
            if (d >= h->out[e]) {
                h->hint = e;
                return SEPARATED;
            }
        }
    }
    *mask = mk;
    return inside ? INSIDE : MEETS;
}

/* The unit outward normals and offsets of piece q's edges (s vertices, local frame), as
   _classify_many computes them, into h (scratch for s edges). A chord polygon's come from
   chord_polygon, which computes them the same way. */
static void normals(Edges *h, const double *q, int64_t s)
{
    for (int64_t e = 0; e < s; e++) {
        int64_t f = e + 1 < s ? e + 1 : 0;
        double ex = q[2 * f] - q[2 * e], ey = q[2 * f + 1] - q[2 * e + 1];
        double len = hypot(ey, -ex);
        h->nx[e] = ey / len, h->ny[e] = -ex / len;
        h->c[e] = h->nx[e] * q[2 * e] + h->ny[e] * q[2 * e + 1];
    }
}

/* The rest of the s half-planes in h (their normals set): from each cell's corner spread hi
   and lo (less the chord's sagitta, sag, for chord polygons), the thresholds of strictly
   inside and strictly outside; and the edges' mask weights, as _classify_many computes them. */
static void half_planes(Edges *h, int64_t s, const double *sag, int wide, double cw, double ch)
{
    h->s = s;
    for (int64_t e = 0; e < s; e++) {
        double hi = max0(h->nx[e]) * cw + max0(h->ny[e]) * ch;
        double lo = min0(h->nx[e]) * cw + min0(h->ny[e]) * ch;
        if (sag) lo -= sag[e];
        h->in[e] = -h->m - hi;  /* strictly inside: d <= in */
        h->out[e] = h->m - lo;  /* strictly outside: d >= out */
        h->w[e] = wide ? 0 : (int64_t)((uint64_t)1 << ((e + 1) % s));
    }
    h->hint = 0;
}

/* Write the entry of cell i of the current row: a wide piece's mask is wide_mask. */
#define PUT(i, in, mk)                                                                                    \
    (o->piece[o->n] = id, o->cell[o->n] = row0 + (i), o->inside[o->n] = (uint8_t)(in),                    \
     o->mask[o->n] = wide ? o->wide_mask : (mk), o->n++)

/* The cells of box i0..i1 x j0..j1 that piece id (half-planes h) may meet, row by row,
   each row scanned from its ends (the header's second shortcut). -1 if o has no room. */
static int classify_box(Out *o, Edges *h, int wide, int64_t id, int64_t i0, int64_t i1, int64_t j0, int64_t j1)
{
    for (int64_t j = j0; j <= j1; j++) {
        double cy0 = o->y_off + (double)j * o->ch;
        int64_t row0 = j * o->gnx, L = i0, Rr = i1, ml = 0, mr = 0;
        int tl = SEPARATED, tr;
        /* The row's cells not separated: [L, Rr], from either end. */
        for (; L <= Rr; L++)
            if ((tl = cell_test(h, o->x_off + (double)L * o->cw, cy0, &ml)) != SEPARATED) break;
        if (L > Rr) continue;
        if (o->n + (Rr - L + 1) > o->cap) return -1;
        tr = tl, mr = ml;
        for (; Rr > L; Rr--)
            if ((tr = cell_test(h, o->x_off + (double)Rr * o->cw, cy0, &mr)) != SEPARATED) break;
        if (Rr == L) tr = tl, mr = ml;
        /* From L rightwards up to the first inside cell a. */
        int64_t a = L, mk = ml;
        int ta = tl;
        for (;;) {
            PUT(a, ta == INSIDE, mk);
            if (ta == INSIDE || a == Rr) break;
            a++;
            if (a == Rr) ta = tr, mk = mr;
            else ta = cell_test(h, o->x_off + (double)a * o->cw, cy0, &mk);
        }
        if (ta != INSIDE) continue; /* no inside cell: the row is written */
        /* From Rr leftwards down to the last inside cell b; then (a, b] inside, then (b, Rr]. */
        int64_t b = Rr, nr = 0;
        int tb = tr;
        mk = mr;
        while (b > a && tb != INSIDE) {
            o->right[nr++] = mk;
            b--;
            if (b > a) tb = cell_test(h, o->x_off + (double)b * o->cw, cy0, &mk);
        }
        for (int64_t i = a + 1; i <= b; i++) PUT(i, 1, 0);
        for (int64_t k = nr - 1; k >= 0; k--) PUT(Rr - k, 0, o->right[k]);
    }
    return 0;
}

/* Scratch for the half-planes of pieces of up to E edges (6 doubles an edge). */
static int edges_alloc(Edges *h, double **hp, Py_ssize_t E, double m)
{
    *hp = PyMem_Malloc(sizeof(double) * 6 * (size_t)(E ? E : 1));
    if (!*hp) return -1;
    double *p = *hp;
    *h = (Edges){p, p + E, p + 2 * E, p + 3 * E, p + 4 * E, (int64_t *)(p + 5 * E), 0, 0, m};
    return 0;
}

/* A box's first and last cell along one axis, as _classify_many computes them in numpy:
   floor((lo - m - x0) * inv) clipped below at 0, floor((hi + m - x0) * inv) clipped above
   at n - 1 (clipped further, to -1 .. n, only where the box then holds no cell anyway). */
static void cell_range(double lo, double hi, double m, double x0, double inv, int64_t n, int64_t *a, int64_t *b)
{
    double f = floor((lo - m - x0) * inv), g = floor((hi + m - x0) * inv);
    f = f > 0.0 ? f : 0.0;
    g = g < (double)(n - 1) ? g : (double)(n - 1);
    *a = (int64_t)(f < (double)n ? f : (double)n);
    *b = (int64_t)(g > -1.0 ? g : -1.0);
}

/* entries(xy, offsets, lo, hi, ox, oy, x0, y0, inv_w, inv_h, cw, ch, m, nx, ny,
           mask_edges, block_edges, max_box, long_edge, tolerance, wide_mask)
       -> (piece, cell, inside, mask, todo)

   The compiled route of CellClassifier._classify_all from the packed pieces (xy: float64
   2 x vertices, piece k from offsets[k]; lo, hi: float64 K x 2, their boxes): each piece
   of at most block_edges edges whose box holds 1 .. max_box cells is shifted to the local
   frame (x - ox, y - oy), replaced by its chord polygon when it has more than mask_edges
   edges (mask wide_mask), and its box classified by classify_box: the same doubles as
   the numpy route, the same entries up to their order. The entries come back as bytearrays
   (int64, int64, uint8, int64); todo lists the pieces left to the caller (more edges or
   cells than that). */
PyObject *fast_entries(PyObject *self, PyObject *args)
{
    PyObject *ob[4];
    Out o = {0};
    double ox, oy, x0, y0, iw, ih, long_edge, tol;
    long long ny, mask_edges, block_edges, max_box;
    if (!PyArg_ParseTuple(args, "OOOOdddddddddLLLLLddL", &ob[0], &ob[1], &ob[2], &ob[3], &ox, &oy, &x0, &y0, &iw,
                          &ih, &o.cw, &o.ch, &o.m, &o.gnx, &ny, &mask_edges, &block_edges, &max_box, &long_edge,
                          &tol, &o.wide_mask))
        return NULL;
    o.x_off = x0 - ox, o.y_off = y0 - oy;
    Py_buffer b[4];
    int got = 0;
    PyObject *result = NULL, *todo = NULL, *arr[4] = {NULL, NULL, NULL, NULL};
    double *hp = NULL, *q = NULL, *cq = NULL, *sag = NULL;
    char *keep = NULL;
    int64_t *idx = NULL, *box = NULL;
    for (; got < 4; got++)
        if (PyObject_GetBuffer(ob[got], &b[got], PyBUF_C_CONTIGUOUS) < 0) goto done;
    const double *xy = b[0].buf, *lo = b[2].buf, *hi = b[3].buf;
    const int64_t *off = b[1].buf;
    Py_ssize_t K = b[1].len / 8 - 1;
    if (K < 0 || b[2].len != 16 * K || b[3].len != 16 * K || off[0] != 0 || b[0].len != 16 * off[K] || o.gnx < 1
        || ny < 1 || block_edges < 3) {
        PyErr_SetString(PyExc_ValueError, "_fast.entries: inconsistent arrays");
        goto done;
    }
    /* First pass: each piece's box of cells (i0, i1, j0, j1, and its cell count), the room
       the pieces taken need, the longest of them. */
    if (!(box = PyMem_Malloc(sizeof(int64_t) * 5 * (size_t)(K ? K : 1)))) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t cap = 0, E = 3;
    for (Py_ssize_t k = 0; k < K; k++) {
        int64_t s = off[k + 1] - off[k], *bx = box + 5 * k;
        if (s < 1) {
            PyErr_SetString(PyExc_ValueError, "_fast.entries: a piece without vertices");
            goto done;
        }
        cell_range(lo[2 * k], hi[2 * k], o.m, x0, iw, o.gnx, &bx[0], &bx[1]);
        cell_range(lo[2 * k + 1], hi[2 * k + 1], o.m, y0, ih, ny, &bx[2], &bx[3]);
        bx[4] = (bx[1] >= bx[0] && bx[3] >= bx[2]) ? (bx[1] - bx[0] + 1) * (bx[3] - bx[2] + 1) : 0;
        if (s <= block_edges && bx[4] <= max_box) {
            cap += bx[4];
            if (s > E) E = s;
        }
    }
    if (!(todo = PyList_New(0))) goto done;
    for (int t = 0; t < 4; t++)
        if (!(arr[t] = PyByteArray_FromStringAndSize(NULL, (t == 2 ? 1 : 8) * (cap ? cap : 1)))) goto done;
    o.piece = (int64_t *)PyByteArray_AS_STRING(arr[0]), o.cell = (int64_t *)PyByteArray_AS_STRING(arr[1]);
    o.inside = (uint8_t *)PyByteArray_AS_STRING(arr[2]), o.mask = (int64_t *)PyByteArray_AS_STRING(arr[3]);
    o.cap = cap;
    Edges h;
    if (edges_alloc(&h, &hp, E, o.m) < 0 || !(q = PyMem_Malloc(16 * (size_t)E))
        || !(cq = PyMem_Malloc(16 * (size_t)E)) || !(sag = PyMem_Malloc(8 * (size_t)E))
        || !(keep = PyMem_Malloc((size_t)E)) || !(idx = PyMem_Malloc(8 * (size_t)E))
        || !(o.right = PyMem_Malloc(sizeof(int64_t) * (size_t)(o.gnx + 1)))) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t k = 0; k < K; k++) {
        int64_t s = off[k + 1] - off[k], *bx = box + 5 * k;
        if (s > block_edges || bx[4] > max_box) {
            PyObject *v = PyLong_FromSsize_t(k);
            if (!v || PyList_Append(todo, v) < 0) {
                Py_XDECREF(v);
                goto done;
            }
            Py_DECREF(v);
            continue;
        }
        if (!bx[4]) continue;
        const double *p = xy + 2 * off[k];
        for (int64_t v = 0; v < s; v++) q[2 * v] = p[2 * v] - ox, q[2 * v + 1] = p[2 * v + 1] - oy;
        int wide = s > mask_edges;
        if (wide) {
            double *const nrm[3] = {h.nx, h.ny, h.c};
            int64_t n = chord_polygon(q, s, long_edge, tol, keep, idx, cq, sag, nrm);
            half_planes(&h, n, sag, 1, o.cw, o.ch);
        } else {
            normals(&h, q, s);
            half_planes(&h, s, NULL, 0, o.cw, o.ch);
        }
        if (classify_box(&o, &h, wide, k, bx[0], bx[1], bx[2], bx[3]) < 0) {
            PyErr_SetString(PyExc_ValueError, "_fast.entries: outputs too small");
            goto done;
        }
    }
    for (int t = 0; t < 4; t++)
        if (PyByteArray_Resize(arr[t], (t == 2 ? 1 : 8) * o.n) < 0) goto done;
    result = Py_BuildValue("(OOOOO)", arr[0], arr[1], arr[2], arr[3], todo);
done:
    for (int t = 0; t < 4; t++) Py_XDECREF(arr[t]);
    Py_XDECREF(todo);
    PyMem_Free(hp);
    PyMem_Free(q);
    PyMem_Free(cq);
    PyMem_Free(sag);
    PyMem_Free(keep);
    PyMem_Free(idx);
    PyMem_Free(box);
    PyMem_Free(o.right);
    for (int k = 0; k < got; k++) PyBuffer_Release(&b[k]);
    return result;
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
