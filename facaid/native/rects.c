/* Executing procedures and flattening labelled rectangles in C: the same rows as the Python reference,
 * `facaid.segmentation.flatten_array` and `facaid.grammar.execute.execute` followed by `leaf_array`.
 *
 * Flattening. Paint the rectangles in paint order onto the grid of all their edges (the last painter of a cell
 * wins), cut each grid row into maximal runs of one label, continue a run into the rectangle above it when that
 * rectangle has the same columns and label, and sort the rectangles by (y0, x0, label). ``mode`` 0 keeps every
 * non-background label ("pieces"); mode 1 writes two layers, the footprint (every non-background cell as facade)
 * and the elements (labels above facade) ("footprint").
 *
 * The caller passes room for ``cap`` rows; when more are needed nothing is written and the count is returned, so
 * that the caller can call again with room enough.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define FACADE 1

static int before(const int64_t *p, const int64_t *q) { /* rows (label, x0, y0, x1, y1) by y0, x0, label */
    if (p[2] != q[2]) return p[2] < q[2];
    if (p[1] != q[1]) return p[1] < q[1];
    return p[0] < q[0];
}

/* The sorted distinct values of {0, size} and the rows' columns a and b into out, and for each value v between
 * lo and hi (out[0] and out[m - 1]) its index in out at index[v - lo] (values that are not edges: unused).
 * Returns m, or -1 when the values span more than MAX_SPAN (the caller declines). */
#define MAX_SPAN (1 << 24)
static int64_t edges(const int64_t *rows, int64_t n, int a, int b, int64_t size, int64_t *out, int32_t **index) {
    int64_t lo = 0, hi = size;
    for (int64_t i = 0; i < n; i++) {
        int64_t u = rows[5 * i + a], v = rows[5 * i + b];
        if (u < lo) lo = u;
        if (v > hi) hi = v; /* u <= v: checked by the caller */
    }
    if (hi - lo > MAX_SPAN) return -1;
    int32_t *at = malloc((size_t)(hi - lo + 1) * sizeof(int32_t));
    uint8_t *seen = calloc((size_t)(hi - lo + 1), 1);
    if (!at || !seen) { free(at); free(seen); return -2; }
    seen[0] = seen[size - lo] = 1;
    for (int64_t i = 0; i < n; i++) seen[rows[5 * i + a] - lo] = seen[rows[5 * i + b] - lo] = 1;
    int64_t m = 0;
    for (int64_t v = 0; v <= hi - lo; v++)
        if (seen[v]) { at[v] = (int32_t)m; out[m++] = v + lo; }
    free(seen);
    *index = at;
    return m;
}

typedef struct { int64_t c0, c1, lab, rect; } Run;

/* decompose the grid's cells under ``layer`` (0: labels as they are, 1: footprint, 2: elements), appending
 * rows in grid cells (label, c0, r0, c1, r1) to out; returns the new count */
static int64_t decompose(const uint8_t *grid, int64_t nr, int64_t nc, int layer, int64_t *out, int64_t count,
                         Run *prev, Run *cur) {
    int64_t np_ = 0;
    for (int64_t r = 0; r < nr; r++) {
        const uint8_t *row = grid + r * nc;
        int64_t ncur = 0, j = 0, c = 0;
        while (c < nc) {
            int64_t lab = row[c];
            if (layer == 1) lab = lab != 0 ? FACADE : 0;
            else if (layer == 2) lab = lab > FACADE ? lab : 0;
            int64_t e = c + 1;
            while (e < nc) {
                int64_t l2 = row[e];
                if (layer == 1) l2 = l2 != 0 ? FACADE : 0;
                else if (layer == 2) l2 = l2 > FACADE ? l2 : 0;
                if (l2 != lab) break;
                e++;
            }
            if (lab != 0) {
                while (j < np_ && prev[j].c0 < c) j++;
                int64_t rect;
                if (j < np_ && prev[j].c0 == c && prev[j].c1 == e && prev[j].lab == lab) {
                    rect = prev[j].rect;
                    out[5 * rect + 4] = r + 1;
                } else {
                    rect = count++;
                    int64_t *o = out + 5 * rect;
                    o[0] = lab; o[1] = c; o[2] = r; o[3] = e; o[4] = r + 1;
                }
                cur[ncur++] = (Run){c, e, lab, rect};
            }
            c = e;
        }
        memcpy(prev, cur, (size_t)ncur * sizeof(Run));
        np_ = ncur;
    }
    return count;
}

/* rows: n x 5 int64 (label, x0, y0, x1, y1); priority: paint rank of each of the 12 labels. Writes the rows of
 * the result to out (room for cap rows) and returns how many there are: more than cap when it wrote nothing, -1
 * when memory ran out, -2 for rows that are not plain (a label outside 0..11, x1 < x0 or y1 < y0). */
static int64_t flatten(int64_t width, int64_t height, const int64_t *rows, int64_t n, const int64_t *priority,
                       int mode, int64_t *result, int64_t cap) {
    int64_t *order = malloc((size_t)(n > 0 ? n : 1) * sizeof(int64_t));
    int64_t *xs = malloc((size_t)(2 * n + 2) * sizeof(int64_t));
    int64_t *ys = malloc((size_t)(2 * n + 2) * sizeof(int64_t));
    int32_t *ix = NULL, *iy = NULL;
    uint8_t *grid = NULL;
    Run *prev = NULL, *cur = NULL;
    int64_t *out = NULL, count = -1;
    if (!order || !xs || !ys) goto done;
    /* paint order: stable counting sort by priority rank */
    int64_t start[257] = {0};
    for (int64_t i = 0; i < n; i++) start[priority[rows[5 * i]] + 1]++;
    for (int k = 0; k < 256; k++) start[k + 1] += start[k];
    for (int64_t i = 0; i < n; i++) order[start[priority[rows[5 * i]]]++] = i;
    int64_t nx = edges(rows, n, 1, 3, width, xs, &ix);
    int64_t ny = nx < 0 ? nx : edges(rows, n, 2, 4, height, ys, &iy);
    if (nx < 0 || ny < 0) { count = nx == -1 || ny == -1 ? -2 : -1; goto done; }
    int64_t nc = nx - 1, nr = ny - 1, x_lo = xs[0], y_lo = ys[0];
    grid = calloc((size_t)(nr * nc > 0 ? nr * nc : 1), 1);
    prev = malloc((size_t)(nc > 0 ? nc : 1) * sizeof(Run));
    cur = malloc((size_t)(nc > 0 ? nc : 1) * sizeof(Run));
    if (!grid || !prev || !cur) goto done;
    for (int64_t k = 0; k < n; k++) { /* the last painter of a cell wins */
        const int64_t *p = rows + 5 * order[k];
        int64_t c0 = ix[p[1] - x_lo], c1 = ix[p[3] - x_lo], r0 = iy[p[2] - y_lo], r1 = iy[p[4] - y_lo];
        if (c1 > c0)
            for (int64_t r = r0; r < r1; r++) memset(grid + r * nc + c0, (int)p[0], (size_t)(c1 - c0));
    }
    /* at most one rectangle per run of a layer, and a layer has no more runs than the grid */
    int64_t runs = 0;
    for (int64_t r = 0; r < nr; r++) {
        const uint8_t *row = grid + r * nc;
        for (int64_t c = 0; c < nc; c++) runs += (c == 0 || row[c] != row[c - 1]);
    }
    out = malloc((size_t)((mode == 1 ? 2 : 1) * runs + 1) * 5 * sizeof(int64_t));
    if (!out) goto done;
    /* each layer's rectangles come out sorted by (y0, x0): made row by row, left to right */
    int64_t split = decompose(grid, nr, nc, mode == 1 ? 1 : 0, out, 0, prev, cur);
    count = mode == 1 ? decompose(grid, nr, nc, 2, out, split, prev, cur) : split;
    for (int64_t i = 0; i < count; i++) { /* grid cells to pixels */
        int64_t *o = out + 5 * i;
        int64_t c0 = o[1], r0 = o[2], c1 = o[3], r1 = o[4];
        o[1] = xs[c0]; o[2] = ys[r0]; o[3] = xs[c1]; o[4] = ys[r1];
    }
    if (count <= cap) { /* merge the layers' sorted runs [0, split) and [split, count) */
        int64_t i = 0, j = split, k = 0;
        while (i < split || j < count) {
            const int64_t *src = j >= count || (i < split && !before(out + 5 * j, out + 5 * i)) ? out + 5 * i++
                                                                                                 : out + 5 * j++;
            memcpy(result + 5 * k++, src, 5 * sizeof(int64_t));
        }
    }
done:
    free(order); free(xs); free(ys); free(ix); free(iy); free(grid); free(prev); free(cur); free(out);
    return count;
}

int64_t facaid_flatten(int64_t width, int64_t height, const int64_t *rows, int64_t n, const int64_t *priority,
                       int mode, int64_t *result, int64_t cap) {
    for (int64_t i = 0; i < n; i++) {
        const int64_t *p = rows + 5 * i;
        if (p[0] < 0 || p[0] > 11 || p[3] < p[1] || p[4] < p[2]) return -2;
    }
    return flatten(width, height, rows, n, priority, mode, result, cap);
}

/* Executing. The tree comes in breadth-first order, 10 int64 a node: rule (0 leaf, 1 split, 2 repeat, 3 mirror),
 * axis (0 x, 1 y), count (-1 "fill"), tail, center, label id, index of the first child, number of children, index
 * of the first exception, number of exceptions; a node's children are consecutive, and node k > 0 has its size
 * (mode 0 abs, 1 rel, 2 flt; value) at k - 1 (an exception's node, queued after the children, has an unused one).
 * An exception is 6 int64: copy, index of its path in ``steps``, the path's length, size mode (-1: none), index of
 * its node (-1: none), and its size value's index in ``ovalues``. The arithmetic is `facaid.grammar.layout`'s,
 * operation for operation, in doubles (compiled without contraction). */
enum { LEAF, SPLIT, REPEAT, MIRROR };
enum { ABS, REL, FLT };
#define NODE 10
#define OVER 6

typedef struct {
    const int64_t *nodes;
    const int64_t *modes;
    const double *values;
    const int64_t *overs; /* the exceptions */
    const int64_t *steps; /* their paths */
    const double *ovalues; /* their sizes */
    int64_t max_count, max_leaves, n_leaves, room;
    double *leaves; /* room x 5: label, x0, y0, x1, y1 */
    int error;
} Exec;

/* an exception on its way down: which one, and how many steps of its path are behind it */
typedef struct { int64_t id, pos; } Pending;

static double nominal(const Exec *e, int64_t k, double length) {
    return e->modes[k - 1] == REL ? e->values[k - 1] * length : e->values[k - 1];
}

/* the node index of expanded child i of node nd (first child at first, nk children): a repeat's copies cycle
 * through the pattern; a mirror's children after the first nk run back from index back (nk - 2 when centred) */
static int64_t child_of(const int64_t *nd, int64_t first, int64_t nk, int64_t back, int64_t i) {
    return nd[0] == MIRROR && i >= nk ? first + back - (i - nk) : first + i % nk;
}

/* The children of an instance that exceptions reach (`layout.expand_over`): per expanded child its node, size
 * mode and value, and the exceptions that go on into it. */
typedef struct {
    int64_t *kid, *mode;
    double *value;
    Pending *entry; /* the exceptions that apply here, own first, each with the index of the child it names */
    int64_t *at, n_entries;
} Over;

static void over_free(Over *o) { free(o->kid); free(o->mode); free(o->value); free(o->entry); free(o->at); }

static int over_make(const Exec *e, const int64_t *nd, int64_t first, int64_t nk, int64_t back, int64_t n,
                     int64_t reps, const Pending *pending, int64_t n_pending, Over *o) {
    int64_t n_own = nd[0] == REPEAT ? nd[9] : 0, cap = n_own + n_pending;
    o->kid = malloc((size_t)n * sizeof(int64_t));
    o->mode = malloc((size_t)n * sizeof(int64_t));
    o->value = malloc((size_t)n * sizeof(double));
    o->entry = malloc((size_t)(cap > 0 ? cap : 1) * sizeof(Pending));
    o->at = malloc((size_t)(cap > 0 ? cap : 1) * sizeof(int64_t));
    o->n_entries = 0;
    if (!o->kid || !o->mode || !o->value || !o->entry || !o->at) return -1;
    for (int64_t i = 0; i < n; i++) {
        int64_t c = child_of(nd, first, nk, back, i);
        o->kid[i] = c; o->mode[i] = e->modes[c - 1]; o->value[i] = e->values[c - 1];
    }
    for (int64_t j = 0; j < n_own; j++) { /* own exceptions: the first step is copy x pattern + item */
        int64_t id = nd[8] + j;
        const int64_t *ov = e->overs + OVER * id;
        int64_t item = e->steps[ov[1]];
        if (ov[0] < reps || (ov[0] == reps && item < nd[3])) {
            o->entry[o->n_entries] = (Pending){id, 0};
            o->at[o->n_entries++] = ov[0] * nk + item;
        }
    }
    for (int64_t j = 0; j < n_pending; j++) {
        o->entry[o->n_entries] = pending[j];
        o->at[o->n_entries++] = e->steps[e->overs[OVER * pending[j].id + 1] + pending[j].pos];
    }
    for (int64_t j = 0; j < o->n_entries; j++) { /* in order: an exception from further up wins */
        const int64_t *ov = e->overs + OVER * o->entry[j].id;
        int64_t i = o->at[j];
        if (i >= n || o->entry[j].pos + 1 < ov[2]) continue; /* no such copy here, or it goes on further down */
        if (ov[3] >= 0) { o->mode[i] = ov[3]; o->value[i] = e->ovalues[ov[5]]; }
        if (ov[4] >= 0) o->kid[i] = ov[4];
    }
    return 0;
}

static void run(Exec *e, int64_t k, double x0, double y0, double x1, double y1, int flip_x, int flip_y,
                const Pending *pending, int64_t n_pending) {
    if (e->error) return;
    const int64_t *nd = e->nodes + NODE * k;
    if (nd[0] == LEAF) {
        if (e->n_leaves >= e->max_leaves) { e->error = -3; return; }
        if (e->n_leaves == e->room) {
            double *more = realloc(e->leaves, (size_t)(2 * e->room) * 5 * sizeof(double));
            if (!more) { e->error = -1; return; }
            e->leaves = more;
            e->room *= 2;
        }
        double *o = e->leaves + 5 * e->n_leaves++;
        o[0] = (double)nd[5]; o[1] = x0; o[2] = y0; o[3] = x1; o[4] = y1;
        return;
    }
    int along_x = nd[1] == 0;
    double lo = along_x ? x0 : y0, hi = along_x ? x1 : y1, span = hi - lo;
    int64_t first = nd[6], nk = nd[7], reps = 1, tail = 0, n;
    if (nd[0] == REPEAT) {
        tail = nd[3];
        reps = nd[2];
        if (reps < 0) { /* fill: `repeat_count` */
            double pattern = 0.0, tail_len = 0.0;
            for (int64_t j = 0; j < nk; j++) pattern += nominal(e, first + j, span);
            for (int64_t j = 0; j < tail; j++) tail_len += nominal(e, first + j, span);
            if (!(pattern > 0.0)) { e->error = -4; return; }
            double q = (span - tail_len) / pattern + 0.5;
            if (!(q < (double)e->max_count)) reps = e->max_count;
            else { reps = (int64_t)q; if (reps > e->max_count) reps = e->max_count; }
            if (reps < 1) reps = 1;
        }
        n = nk * reps + tail;
    } else if (nd[0] == MIRROR) {
        n = nk + nk - (nd[4] ? 1 : 0);
    } else {
        n = nk;
    }
    int64_t back = nk - (nd[4] ? 2 : 1);
    Over ov = {0};
    int over = n_pending > 0 || (nd[0] == REPEAT && nd[9] > 0);
    if (over && over_make(e, nd, first, nk, back, n, reps, pending, n_pending, &ov)) {
        over_free(&ov);
        e->error = -1;
        return;
    }
    /* `layout` */
    double length = span > 0.0 ? span : 0.0, fixed = 0.0, weights = 0.0, scale, share;
    for (int64_t i = 0; i < n; i++) {
        int64_t c = child_of(nd, first, nk, back, i), m = over ? ov.mode[i] : e->modes[c - 1];
        double v = over ? ov.value[i] : e->values[c - 1];
        if (m == FLT) weights += v;
        else fixed += m == REL ? v * length : v;
    }
    if (weights > 0) {
        scale = fixed > length ? length / fixed : 1.0;
        share = (length - fixed > 0.0 ? length - fixed : 0.0) / weights;
    } else {
        scale = fixed > 0 ? length / fixed : 0.0;
        share = 0.0;
    }
    int flip = along_x ? flip_x : flip_y;
    double pos = flip ? hi : lo;
    /* the exceptions that go on into each child, in order, bucketed by child (a counting sort: linear in the
     * children and the exceptions, as `layout.count_expansion` charges): child i's are below[end[i - 1] .. end[i]) */
    Pending *below = NULL;
    int64_t *end = NULL;
    if (over && ov.n_entries) {
        below = malloc((size_t)ov.n_entries * sizeof(Pending));
        end = calloc((size_t)n + 1, sizeof(int64_t));
        if (!below || !end) { free(below); free(end); over_free(&ov); e->error = -1; return; }
        for (int64_t j = 0; j < ov.n_entries; j++)
            if (ov.at[j] < n && ov.entry[j].pos + 1 < e->overs[OVER * ov.entry[j].id + 2]) end[ov.at[j] + 1]++;
        for (int64_t i = 0; i < n; i++) end[i + 1] += end[i];
        for (int64_t j = 0; j < ov.n_entries; j++)
            if (ov.at[j] < n && ov.entry[j].pos + 1 < e->overs[OVER * ov.entry[j].id + 2])
                below[end[ov.at[j]]++] = (Pending){ov.entry[j].id, ov.entry[j].pos + 1};
    }
    for (int64_t i = 0; i < n; i++) {
        int reflected = nd[0] == MIRROR && i >= nk;
        int64_t c = over ? ov.kid[i] : child_of(nd, first, nk, back, i), m = over ? ov.mode[i] : e->modes[c - 1];
        double v = over ? ov.value[i] : e->values[c - 1], size, a, b;
        size = m == FLT ? v * share : m == REL ? v * length * scale : v * scale;
        if (flip) { a = i == n - 1 ? lo : pos - size; b = pos; pos = a; }
        else { a = pos; b = i == n - 1 ? hi : pos + size; pos = b; }
        int fx = flip_x, fy = flip_y;
        if (reflected) { if (along_x) fx = !fx; else fy = !fy; }
        int64_t from = !end || i == 0 ? 0 : end[i - 1], n_below = end ? end[i] - from : 0;
        if (along_x) run(e, c, a, y0, b, y1, fx, fy, below ? below + from : NULL, n_below);
        else run(e, c, x0, a, x1, b, fx, fy, below ? below + from : NULL, n_below);
        if (e->error) break;
    }
    free(below);
    free(end);
    if (over) over_free(&ov);
}

/* Execute the tree on [0, extent_x) x [0, extent_y) (the procedure's size), round the leaves' edges to whole
 * pixels (half to even), clip them to the width x height image, drop background and empty ones and flatten the rest
 * (mode as in `facaid_flatten`). Returns the row count as `facaid_flatten` does, or -3 for more than max_leaves
 * leaves, -4 for a "fill" repeat whose pattern has no length (the Python executor then reports either). */
int64_t facaid_execute(const int64_t *nodes, const int64_t *modes, const double *values, const int64_t *overs,
                       const int64_t *steps, const double *ovalues, double extent_x, double extent_y, int64_t width,
                       int64_t height, int64_t max_count, int64_t max_leaves, const int64_t *priority, int mode,
                       int64_t *result, int64_t cap) {
    Exec e = {nodes, modes, values, overs, steps, ovalues, max_count, max_leaves, 0, 1024,
              malloc(1024 * 5 * sizeof(double)), 0};
    if (!e.leaves) return -1;
    run(&e, 0, 0.0, 0.0, extent_x, extent_y, 0, 0, NULL, 0);
    if (e.error) { free(e.leaves); return e.error; }
    int64_t *rows = malloc((size_t)(e.n_leaves > 0 ? e.n_leaves : 1) * 5 * sizeof(int64_t)), n = 0;
    if (!rows) { free(e.leaves); return -1; }
    for (int64_t i = 0; i < e.n_leaves; i++) {
        const double *l = e.leaves + 5 * i;
        if (l[0] == 0.0) continue; /* background */
        int64_t b[4], lim[4] = {width, height, width, height};
        for (int j = 0; j < 4; j++) {
            b[j] = (int64_t)nearbyint(l[1 + j]);
            if (b[j] < 0) b[j] = 0;
            if (b[j] > lim[j]) b[j] = lim[j];
        }
        if (b[0] >= b[2] || b[1] >= b[3]) continue;
        int64_t *o = rows + 5 * n++;
        o[0] = (int64_t)l[0]; o[1] = b[0]; o[2] = b[1]; o[3] = b[2]; o[4] = b[3];
    }
    free(e.leaves);
    int64_t count = n ? flatten(width, height, rows, n, priority, mode, result, cap) : 0;
    free(rows);
    return count;
}
