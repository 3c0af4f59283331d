/* Closest-point search of contact_ufl: a bounding-volume hierarchy (AABB tree) over the
 * master facets and a branch-and-bound nearest-facet query per slave point.
 *
 * Compiled on first use by contact_ufl.contact.compiled (the system C compiler, loaded with
 * cffi) and called by contact_ufl.contact.projection for every facet kind:
 *   kind 0: segment (2 nodes, 2D), 1: triangle (3 nodes, 3D), 2: bilinear quadrilateral
 *   (4 nodes, 3D, basix order); the quadratic kinds 3: 3-node segment (2D), 4: 6-node
 *   triangle, 5: 9-node quadrilateral (3D; node orders of contact_ufl.contact.curved).
 * The exact projections of the flat kinds repeat the operations of the NumPy kernels of
 * projection.py in the same order (compile with -ffp-contract=off: no fused multiply-add),
 * so that the distances are those of the NumPy kernels to the last bit; those of the
 * quadratic kinds are the kernels of curved.py, their Newton iterations on the facet in
 * monomial form (the same points to round-off). The boxes of a quadratic facet are those
 * of its Bernstein control points (which hold it), and its exact projection waits until
 * the walk is done (DEFERRED, resolve).
 *
 * Tree layout: nodes in preorder; node i is a leaf when a[i] < 0 (its facets are
 * perm[-a[i] - 1 .. -a[i] - 1 + b[i]]), else its children are a[i] and b[i]. The query walks
 * the rows of bvh_refit (node_t, two 64-byte cache lines), a tree of four children a node:
 * the row of an internal node holds the boxes of its children's children (of a child that is
 * a leaf, that leaf; by coordinate, the four side by side for the compiler to vectorise), in
 * single precision rounded outwards (a box holding the exact one: the pruning is as safe,
 * the closest points are the same), and their codes (a row index, or -1 - (8 start + count)
 * for a leaf, EMPTY for an unused slot), so that two levels of the binary tree cost one
 * row. The rows are in preorder; row m holds the root's box and code as its first child.
 * The facets themselves are records in the order of the leaves (RECORD: nodes, box, chord
 * deviation), written with the rows by bvh_refit.
 *
 * The query walks LANES points at a time on a surface, one step of each by turns (a row's
 * children pushed, or a leaf's facets visited): the loads one walk has just started
 * (prefetched) arrive while the others work, instead of stalling the one walk. Each walk is
 * the same branch and bound as alone, so its facets, hence the results, are those of one
 * point at a time.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef long long i64;

#define WIDE 4
#define EMPTY ((i64)1 << 62) /* the code of an unused slot of a row */

typedef struct {
    float lo[3][WIDE], hi[3][WIDE]; /* the children's boxes, by coordinate then child */
    i64 child[WIDE];                /* row index, leaf code -1 - (8 start + count), or EMPTY */
} node_t;
/* projection.py allocates the tree buffer as (m + 2) * 128 bytes */
_Static_assert(sizeof(node_t) == 128, "a row of the tree is 128 bytes");

/* The record of a facet in the order of the leaves (bvh_refit writes them, the walk reads
 * them): its nn g node coordinates, its box (lo, hi: 2 g values, of its hull points) and the
 * deviation of a quadratic facet from its chord facet (chord_deviation; 0 of a flat one), so
 * that the walk reads a facet's box and bounds from the lines it loads for its nodes. */
#define RECORD(g, nn) ((nn) * (g) + 2 * (g) + 1)

/* the rows of a tree buffer of at least (m + 1) sizeof(node_t) + 128 bytes, 128-byte
 * aligned (a row in two cache lines that are loaded together) */
static node_t *rows(const void *buffer)
{
    return (node_t *)(((uintptr_t)buffer + 127) & ~(uintptr_t)127);
}

#define LEAF 4
#define NEWTON_ITERATIONS 25
#define NEWTON_TOL 1e-13
#define RESTART_CURVATURE 0.2 /* curved.RESTART_CURVATURE */
#define STACK 512
#ifndef LANES
#define LANES 4 /* points walked at a time (by turns) */
#endif
#define AHEAD 16 /* facets ahead whose nodes the refit prefetches */
#define INLINE static inline __attribute__((always_inline))
#if defined(__GNUC__) || defined(__clang__)
#define PREFETCH(address) __builtin_prefetch(address)
#else
#define PREFETCH(address) ((void)0)
#endif

/* -- build ------------------------------------------------------------------------------ */

static void select_nth(i64 *perm, i64 lo, i64 hi, i64 nth, const double *c, int g, int axis)
{
    /* reorder perm[lo:hi] so that perm[nth] has the nth key and smaller keys come first */
    while (hi - lo > 1) {
        double pivot = c[perm[(lo + hi) / 2] * g + axis];
        i64 i = lo, j = hi - 1;
        while (i <= j) {
            while (c[perm[i] * g + axis] < pivot) i++;
            while (c[perm[j] * g + axis] > pivot) j--;
            if (i <= j) {
                i64 t = perm[i];
                perm[i] = perm[j];
                perm[j] = t;
                i++;
                j--;
            }
        }
        if (nth <= j)
            hi = j + 1;
        else if (nth >= i)
            lo = i;
        else
            return;
    }
}

static i64 build_node(int g, const double *c, i64 *perm, i64 lo, i64 hi, i64 *a, i64 *b,
                      i64 *count)
{
    i64 node = (*count)++;
    if (hi - lo <= LEAF) {
        a[node] = -(lo + 1);
        b[node] = hi - lo;
        return node;
    }
    double mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (i64 i = lo; i < hi; i++)
        for (int k = 0; k < g; k++) {
            double v = c[perm[i] * g + k];
            if (v < mn[k]) mn[k] = v;
            if (v > mx[k]) mx[k] = v;
        }
    int axis = 0;
    for (int k = 1; k < g; k++)
        if (mx[k] - mn[k] > mx[axis] - mn[axis]) axis = k;
    i64 mid = (lo + hi) / 2;
    select_nth(perm, lo, hi, mid, c, g, axis);
    a[node] = build_node(g, c, perm, lo, mid, a, b, count);
    b[node] = build_node(g, c, perm, mid, hi, a, b, count);
    return node;
}

/* Build the tree over n facets of centroids c (n, g); perm (n) is filled, a and b (at
 * least n + 1 entries: the leaves hold 2 to 4 facets) too. Returns the number of tree nodes. */
i64 bvh_build(int g, i64 n, const double *c, i64 *perm, i64 *a, i64 *b)
{
    i64 count = 0;
    for (i64 i = 0; i < n; i++) perm[i] = i;
    if (n > 0) build_node(g, c, perm, 0, n, a, b, &count);
    return count;
}

/* The float v rounds to, moved by one unit in the last place down (step -1) or up (step 1)
 * where move is 1, on its bits and without a branch: whether a bound rounds up or down is a
 * coin toss, and a branch's mispredictions would be most of the refit of the tree's rows.
 * A float's bits count its magnitude, so a step towards -infinity is -1 on a positive float
 * and +1 on a negative one; a zero rounded from a nonzero v carries v's sign, so it steps
 * away from zero, to the smallest subnormal. */
INLINE float nudged(float f, int move, int step)
{
    union {
        float f;
        uint32_t u;
    } b = {f};
    int negative = (int)(b.u >> 31);
    b.u += (uint32_t)(move * step * (1 - 2 * negative));
    return b.f;
}

INLINE float down(double v)
{
    /* the largest float not above v */
    float f = (float)v;
    return nudged(f, (double)f > v, -1);
}

INLINE float up(double v)
{
    /* the smallest float not below v */
    float f = (float)v;
    return nudged(f, (double)f < v, 1);
}

typedef struct {
    int kind, g, nn;
    i64 n;
    const double *nodes; /* (n, nn, g) as given */
    const i64 *perm, *a, *b;
    double *leaves;     /* (n, RECORD) in the order of perm */
    double *boxes;      /* the leaves' boxes (lo, hi), in preorder */
    i64 m;              /* tree nodes (of the binary tree, in preorder) */
    node_t *T;
    i64 used, leaf; /* rows written, leaf boxes taken */
    double r2max, change;
    int finite;
} fit_t;

/* The facet kind of nn nodes in g dimensions (projection._COMPILED_KINDS), -1 if none. */
static int kind_of(int g, int nn)
{
    if (g == 2) return nn == 2 ? 0 : (nn == 3 ? 3 : -1);
    if (g == 3) return nn == 3 ? 1 : (nn == 4 ? 2 : (nn == 6 ? 4 : (nn == 9 ? 5 : -1)));
    return -1;
}

/* The points whose convex hull holds the facet X of kind: its nodes (X itself) for a flat
 * facet; for a quadratic one its Bernstein control points, written to H (nn g values):
 * the vertices, and for an edge ij of midpoint node m the point 2 x_m - (x_i + x_j) / 2
 * (curved.bernstein_hull, the same operations). */
static const int SEG3_EDGES[1][3] = {{0, 1, 2}};
static const int TRI6_EDGES[3][3] = {{0, 1, 3}, {1, 2, 4}, {0, 2, 5}};
static const int QUAD9_EDGES[4][3] = {{0, 1, 4}, {1, 3, 5}, {2, 3, 6}, {0, 2, 7}};

INLINE const double *hull(int kind, int g, const double *X, double *H)
{
    if (kind < 3) return X;
    const int nn = kind == 3 ? 3 : (kind == 4 ? 6 : 9), ne = kind == 3 ? 1 : (kind == 4 ? 3 : 4);
    const int(*E)[3] = kind == 3 ? SEG3_EDGES : (kind == 4 ? TRI6_EDGES : QUAD9_EDGES);
    memcpy(H, X, (size_t)(nn * g) * sizeof(double));
    for (int e = 0; e < ne; e++)
        for (int k = 0; k < g; k++)
            H[E[e][2] * g + k] = 2.0 * X[E[e][2] * g + k] - 0.5 * (X[E[e][0] * g + k] + X[E[e][1] * g + k]);
    if (kind == 5) /* the centre: along s at t = 1/2, then along t */
        for (int k = 0; k < 3; k++) {
            double along = 2.0 * X[24 + k] - 0.5 * (X[21 + k] + X[15 + k]);
            H[24 + k] = 2.0 * along - 0.5 * (H[12 + k] + H[18 + k]);
        }
    return H;
}

static double chord_deviation(int kind, const double *X);

/* The records of all facets written in the order of perm (their nodes, boxes of their hull
 * points and chord deviations), the boxes of the leaves (of their facets' boxes) in
 * preorder, and the largest facet radius, node change and finiteness updated: one flat pass
 * over the tree nodes (numbered in preorder, so the leaves come in the order of their
 * facets), the tree's rows after it from the leaves' boxes. (Fitting the facets inside the
 * recursion over the tree, or reading their boxes back there, costs about twice as much.) */
INLINE void fit_records(fit_t *F, const int kind, const int g, const int nn)
{
    const int w = nn * g;
    double r2max = F->r2max, change = F->change, *box = F->boxes;
    int finite = 1;
    for (i64 i = 0; i < F->m; i++) {
        if (F->a[i] >= 0) continue;
        i64 start = -F->a[i] - 1;
        for (int k = 0; k < g; k++) {
            box[k] = INFINITY;
            box[g + k] = -INFINITY;
        }
        for (i64 j = start; j < start + F->b[i]; j++) {
            const double *X = F->nodes + F->perm[j] * w;
            double *Y = F->leaves + j * RECORD(g, nn), c[3]; /* the nodes of the last refit */
            for (int q = 0; q < w; q++) {
                double d = fabs(X[q] - Y[q]);
                change = d > change ? d : change;
                Y[q] = X[q];
            }
            if (j + AHEAD < F->n) { /* the nodes of a facet a few on: the gather's latency hidden */
                const double *next = F->nodes + F->perm[j + AHEAD] * w;
                PREFETCH(next);
                PREFETCH(next + w - 1);
            }
            double H[27];
            const double *P = hull(kind, g, X, H);
            for (int k = 0; k < g; k++) { /* nn times the centroid: no division */
                double s = P[k];
                for (int q = 1; q < nn; q++) s += P[q * g + k];
                c[k] = s;
                finite &= isfinite(s); /* a NaN or infinite coordinate makes its sum so */
            }
            double *B = Y + w; /* the facet's box */
            for (int k = 0; k < g; k++) B[k] = B[g + k] = P[k];
            for (int q = 0; q < nn; q++) {
                double d2 = 0.0; /* nn^2 times the squared distance from the centroid */
                for (int k = 0; k < g; k++) {
                    double v = P[q * g + k], d = nn * v - c[k];
                    d2 += d * d;
                    B[k] = v < B[k] ? v : B[k];
                    B[g + k] = v > B[g + k] ? v : B[g + k];
                }
                r2max = d2 > r2max ? d2 : r2max;
            }
            for (int k = 0; k < g; k++) {
                box[k] = B[k] < box[k] ? B[k] : box[k];
                box[g + k] = B[g + k] > box[g + k] ? B[g + k] : box[g + k];
            }
            B[2 * g] = kind >= 3 ? chord_deviation(kind, X) : 0.0;
        }
        box += 2 * g;
    }
    F->r2max = r2max; /* nn^2 times the largest squared facet radius */
    F->change = change;
    F->finite &= finite;
}

INLINE i64 leaf_code(const fit_t *F, i64 i) { return -1 - (8 * (-F->a[i] - 1) + F->b[i]); }

INLINE void store_box(node_t *N, int slot, int g, const double *B)
{
    for (int k = 0; k < 3; k++) { /* an unused coordinate (2D) at 0: no distance */
        N->lo[k][slot] = k < g ? down(B[k]) : 0.0f;
        N->hi[k][slot] = k < g ? up(B[g + k]) : 0.0f;
    }
}

/* The box (lo, hi) of binary node i and its code (leaf code, or the row written for it, its
 * subtree's rows after it). */
static i64 fit(fit_t *F, i64 i, double *box)
{
    const int g = F->g;
    if (F->a[i] < 0) { /* the next leaf in preorder */
        memcpy(box, F->boxes + 2 * g * F->leaf++, 2 * g * sizeof(double));
        return leaf_code(F, i);
    }
    i64 row = F->used++, grand[WIDE];
    int slots = 0;
    for (int c = 0; c < 2; c++) {
        i64 child = c ? F->b[i] : F->a[i];
        if (F->a[child] < 0) {
            grand[slots++] = child;
        } else {
            grand[slots++] = F->a[child];
            grand[slots++] = F->b[child];
        }
    }
    double B[WIDE][6];
    i64 code[WIDE];
    for (int c = 0; c < slots; c++) code[c] = fit(F, grand[c], B[c]);
    node_t *N = F->T + row;
    for (int k = 0; k < g; k++) {
        box[k] = INFINITY;
        box[g + k] = -INFINITY;
    }
    for (int c = 0; c < WIDE; c++) {
        if (c >= slots) {
            for (int k = 0; k < 3; k++) N->lo[k][c] = N->hi[k][c] = 0.0f;
            N->child[c] = EMPTY;
            continue;
        }
        store_box(N, c, g, B[c]);
        N->child[c] = code[c];
        for (int k = 0; k < g; k++) {
            box[k] = B[c][k] < box[k] ? B[c][k] : box[k];
            box[g + k] = B[c][g + k] > box[g + k] ? B[c][g + k] : box[g + k];
        }
    }
    return row;
}

INLINE double refit(int g, int nn, i64 n, const double *nodes, const i64 *perm, i64 m,
                    const i64 *a, const i64 *b, void *tree, double *leaves, double *boxes,
                    double *change)
{
    fit_t F = {kind_of(g, nn), g, nn, n, nodes, perm, a, b, leaves, boxes, m,
               rows(tree), 0, 0, 0.0, 0.0, 1};
    fit_records(&F, F.kind, g, nn);
    if (m > 0) {
        double B[6];
        i64 code = fit(&F, 0, B);
        node_t *R = F.T + m;
        store_box(R, 0, g, B);
        R->child[0] = code;
        for (int c = 1; c < WIDE; c++) {
            for (int k = 0; k < 3; k++) R->lo[k][c] = R->hi[k][c] = 0.0f;
            R->child[c] = EMPTY;
        }
    }
    *change = F.change;
    return F.finite ? sqrt(F.r2max) / nn : -2.0;
}

/* The tree over the current nodes (n, nn, g) of the facets: tree (a buffer of (m + 1)
 * sizeof(node_t) + 128 bytes) gets the rows of the walk (every facet point lies in the box of
 * its nodes' convex hull); leaves (n, bvh_record(g, nn)) the facets' records in the order
 * of perm (RECORD: nodes, box, chord deviation; the facets of a leaf contiguous), their
 * nodes those of the last refit before, so that change gets the largest coordinate change
 * from those to these; boxes (at least n 2 g values) is scratch. Returns the largest facet
 * radius (node distance from the mean of the nodes), -1 for an unknown facet kind, -2 if a
 * coordinate is not finite. */
double bvh_refit(int g, int nn, i64 n, const double *nodes, const i64 *perm, i64 m,
                 const i64 *a, const i64 *b, void *tree, double *leaves, double *boxes,
                 double *change)
{
    if (g == 2 && nn == 2) return refit(2, 2, n, nodes, perm, m, a, b, tree, leaves, boxes, change);
    if (g == 3 && nn == 3) return refit(3, 3, n, nodes, perm, m, a, b, tree, leaves, boxes, change);
    if (g == 3 && nn == 4) return refit(3, 4, n, nodes, perm, m, a, b, tree, leaves, boxes, change);
    if (g == 2 && nn == 3) return refit(2, 3, n, nodes, perm, m, a, b, tree, leaves, boxes, change);
    if (g == 3 && nn == 6) return refit(3, 6, n, nodes, perm, m, a, b, tree, leaves, boxes, change);
    if (g == 3 && nn == 9) return refit(3, 9, n, nodes, perm, m, a, b, tree, leaves, boxes, change);
    return -1.0;
}

/* The length of a facet's record in the leaves (RECORD) of nn nodes in g dimensions. */
int bvh_record(int g, int nn) { return RECORD(g, nn); }

/* Whether the nodes (n, nn, g) are those of the last refit, in the records of leaves, to the
 * last bit (facet by facet in the order of the leaves, stopped at the first difference: a
 * moved master costs one facet). */
INLINE int same(const int g, const int nn, i64 n, const double *nodes, const i64 *perm,
                const double *leaves)
{
    const int w = nn * g, rec = RECORD(g, nn);
    for (i64 j = 0; j < n; j++) {
        if (j + AHEAD < n) PREFETCH(nodes + perm[j + AHEAD] * w);
        uint64_t differ = 0, x, y; /* the bits of the facet's values, compared all at once */
        for (int q = 0; q < w; q++) {
            memcpy(&x, nodes + perm[j] * w + q, sizeof x);
            memcpy(&y, leaves + j * rec + q, sizeof y);
            differ |= x ^ y;
        }
        if (differ) return 0;
    }
    return 1;
}

int same_nodes(int g, int nn, i64 n, const double *nodes, const i64 *perm, const double *leaves)
{
    /* the loops of each kind unrolled, as bvh_refit's; an unknown kind is never the same */
    if (g == 2 && nn == 2) return same(2, 2, n, nodes, perm, leaves);
    if (g == 3 && nn == 3) return same(3, 3, n, nodes, perm, leaves);
    if (g == 3 && nn == 4) return same(3, 4, n, nodes, perm, leaves);
    if (g == 2 && nn == 3) return same(2, 3, n, nodes, perm, leaves);
    if (g == 3 && nn == 6) return same(3, 6, n, nodes, perm, leaves);
    if (g == 3 && nn == 9) return same(3, 9, n, nodes, perm, leaves);
    return 0;
}

/* -- the order of the points: a Z-order (Morton) curve ----------------------------------- */

INLINE unsigned long long spread_bits(unsigned long long v, int g)
{
    /* the 10 low bits of v to every g-th bit (bit i to bit g i) */
    unsigned long long out = 0;
    for (int i = 0; i < 10; i++) out |= ((v >> i) & 1ULL) << (g * i);
    return out;
}

/* An order (n) of the points x (n, g) along a Z-order curve through the cells of a 1024^g
 * grid over their bounding box (the cell of a coordinate: min((x - lo) 1024 / span, 1023)
 * with span the box's largest side): the points of a cell, then of its neighbours, come one
 * after the other. A radix sort of the keys (stable: equal keys in the given order); the
 * identity if the span is not positive and finite. Returns 0, or -1 when out of memory. */
int morton_order(int g, i64 n, const double *x, i64 *order)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (i64 i = 0; i < n; i++)
        for (int k = 0; k < g; k++) {
            double v = x[i * g + k];
            if (v < lo[k]) lo[k] = v;
            if (v > hi[k]) hi[k] = v;
        }
    double span = 0.0;
    for (int k = 0; k < g; k++)
        if (hi[k] - lo[k] > span) span = hi[k] - lo[k];
    for (i64 i = 0; i < n; i++) order[i] = i;
    if (!(span > 0.0 && span < INFINITY)) return 0;
    unsigned *key = malloc(2 * n * sizeof(unsigned));
    i64 *other = malloc(n * sizeof(i64));
    if (!key || !other) {
        free(key);
        free(other);
        return -1;
    }
    for (i64 i = 0; i < n; i++) {
        unsigned k3 = 0;
        for (int k = 0; k < g; k++) {
            double c = (x[i * g + k] - lo[k]) * (1024.0 / span);
            unsigned long long cell = c < 1023.0 ? (unsigned long long)c : 1023ULL;
            k3 |= (unsigned)(spread_bits(cell, g) << k);
        }
        key[i] = k3;
    }
    /* least significant digit first, 10 bits a pass, over the 10 g bits of the keys */
    unsigned *kin = key, *kout = key + n;
    i64 *oin = order, *oout = other;
    for (int shift = 0; shift < 10 * g; shift += 10) {
        i64 start[1025] = {0};
        for (i64 i = 0; i < n; i++) start[((kin[i] >> shift) & 1023) + 1]++;
        for (int d = 0; d < 1024; d++) start[d + 1] += start[d];
        for (i64 i = 0; i < n; i++) {
            i64 at = start[(kin[i] >> shift) & 1023]++;
            kout[at] = kin[i];
            oout[at] = oin[i];
        }
        unsigned *kt = kin;
        kin = kout;
        kout = kt;
        i64 *ot = oin;
        oin = oout;
        oout = ot;
    }
    if (oin != order) memcpy(order, oin, n * sizeof(i64));
    free(key);
    free(other);
    return 0;
}

/* -- exact projections (the NumPy kernels' operations, in their order) ------------------- */

typedef struct {
    double xi[2];
    double dist;
    i64 edge;
    int vertex;
} pair_t;

/* straight edges: start node, end node, xi at start, xi at end (projection._EDGES) */
static const int SEG_EDGES[1][2] = {{0, 1}};
static const double SEG_XI[1][2][2] = {{{0.0, 0.0}, {1.0, 0.0}}};
static const int TRI_EDGES[3][2] = {{0, 1}, {1, 2}, {0, 2}};
static const double TRI_XI[3][2][2] = {
    {{0.0, 0.0}, {1.0, 0.0}}, {{1.0, 0.0}, {0.0, 1.0}}, {{0.0, 0.0}, {0.0, 1.0}}};
static const int QUAD_EDGES[4][2] = {{0, 1}, {1, 3}, {2, 3}, {0, 2}};
static const double QUAD_XI[4][2][2] = {{{0.0, 0.0}, {1.0, 0.0}},
                                        {{1.0, 0.0}, {1.0, 1.0}},
                                        {{0.0, 1.0}, {1.0, 1.0}},
                                        {{0.0, 0.0}, {0.0, 1.0}}};

INLINE double sum_sq(int g, const double *w)
{
    /* sum(w[k] * w[k] for k in range(1, g)) + w[0] * w[0], as projection._edges */
    double s = w[1] * w[1];
    for (int k = 2; k < g; k++) s += w[k] * w[k];
    return s + w[0] * w[0];
}

INLINE double sum_prod(int g, const double *v, const double *w)
{
    double s = v[1] * w[1];
    for (int k = 2; k < g; k++) s += v[k] * w[k];
    return s + v[0] * w[0];
}

INLINE void edges(int g, int ne, const int (*E)[2], const double (*XI)[2][2], int fdim,
                  const double *X, const double *x, pair_t *out)
{
    double best_d = 0.0, best_u = 0.0;
    int best_k = 0;
    for (int n = 0; n < ne; n++) {
        const double *A = X + E[n][0] * g, *B = X + E[n][1] * g;
        double e[3], r[3], w[3];
        for (int k = 0; k < g; k++) {
            e[k] = B[k] - A[k];
            r[k] = x[k] - A[k];
        }
        double ee = sum_sq(g, e), re = sum_prod(g, r, e);
        double u = re / (ee > 0 ? ee : 1.0);
        u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
        for (int k = 0; k < g; k++) w[k] = r[k] - u * e[k];
        double d = sqrt(sum_sq(g, w));
        if (n == 0 || d < best_d) {
            best_d = d;
            best_u = u;
            best_k = n;
        }
    }
    for (int j = 0; j < fdim; j++)
        out->xi[j] = XI[best_k][0][j] + best_u * (XI[best_k][1][j] - XI[best_k][0][j]);
    out->dist = best_d;
    out->edge = best_k;
    out->vertex = best_u == 0.0 || best_u == 1.0;
}

INLINE double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The reference coordinates xi of the projection of x on the plane of the triangle of the
 * nodes X[0..2] (the operations of projection._triangle_interior), its tangents a1, a2 and
 * r = x - X[0]; xi = 0 and 0 returned where the triangle is degenerate. */
INLINE int plane_xi(const double *X, const double *x, double *xi, double *a1, double *a2,
                    double *r)
{
    for (int k = 0; k < 3; k++) {
        a1[k] = X[3 + k] - X[k];
        a2[k] = X[6 + k] - X[k];
        r[k] = x[k] - X[k];
    }
    double g11 = dot3(a1, a1), g12 = dot3(a1, a2), g22 = dot3(a2, a2);
    double det = g11 * g22 - g12 * g12;
    int ok = det > 1e-14 * g11 * g22;
    double inv = ok ? 1.0 / det : 0.0;
    double i11 = g22 * inv, i12 = -g12 * inv, i22 = g11 * inv;
    double b1 = r[0] * a1[0] + r[1] * a1[1] + r[2] * a1[2];
    double b2 = r[0] * a2[0] + r[1] * a2[1] + r[2] * a2[2];
    xi[0] = i11 * b1 + i12 * b2;
    xi[1] = i12 * b1 + i22 * b2;
    return ok;
}

INLINE void triangle(const double *X, const double *x, pair_t *out)
{
    /* the projection on the plane where it is inside, else the closest point of the edges
     * (projection._triangle_interior replaces the edges' result where it is inside) */
    double a1[3], a2[3], r[3], xi[2];
    plane_xi(X, x, xi, a1, a2, r);
    double xi1 = xi[0], xi2 = xi[1];
    if (xi1 > 0.0 && xi2 > 0.0 && xi1 + xi2 < 1.0) {
        double w[3];
        for (int k = 0; k < 3; k++) w[k] = r[k] - xi1 * a1[k] - xi2 * a2[k];
        out->xi[0] = xi1;
        out->xi[1] = xi2;
        out->dist = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        out->edge = -1;
        out->vertex = 0;
    } else {
        edges(3, 3, TRI_EDGES, TRI_XI, 2, X, x, out);
    }
}

INLINE void quad_residual(const double (*c)[3], const double *x, double s, double t, double *r)
{
    for (int k = 0; k < 3; k++) r[k] = x[k] - (c[0][k] + s * c[1][k] + t * c[2][k] + s * t * c[3][k]);
}

INLINE double clip01(double v) { return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v); }

/* projection._quad_newton for one pair: xi in/out, returns the distance; conv, pd out */
static double quad_newton(const double (*c)[3], const double *x, double *xi, int *conv, int *pd)
{
    double s = xi[0], t = xi[1], a1[3], a2[3], r[3], rn[3];
    int fresh = 0; /* whether r already holds the residual at (s, t): that of the step taken */
    *conv = 0;
    for (int it = 0; it < NEWTON_ITERATIONS; it++) {
        for (int k = 0; k < 3; k++) {
            a1[k] = c[1][k] + t * c[3][k];
            a2[k] = c[2][k] + s * c[3][k];
        }
        if (!fresh) quad_residual(c, x, s, t, r);
        double g1 = -dot3(r, a1), g2 = -dot3(r, a2);
        double h11 = dot3(a1, a1), h22 = dot3(a2, a2), h12gn = dot3(a1, a2);
        double h12 = h12gn - dot3(r, c[3]);
        double det = h11 * h22 - h12 * h12;
        if (det <= 1e-12 * h11 * h22) h12 = h12gn;
        det = h11 * h22 - h12 * h12;
        if (!(det > 0)) det = INFINITY;
        double step1 = -(h22 * g1 - h12 * g2) / det, step2 = -(h11 * g2 - h12 * g1) / det;
        int fix1 = (s <= 0.0 && g1 > 0.0) || (s >= 1.0 && g1 < 0.0);
        int fix2 = (t <= 0.0 && g2 > 0.0) || (t >= 1.0 && g2 < 0.0);
        if (fix1 != fix2) {
            step1 = fix1 ? 0.0 : -g1 / (h11 > 0 ? h11 : INFINITY);
            step2 = fix2 ? 0.0 : -g2 / (h22 > 0 ? h22 : INFINITY);
        }
        if (fix1 && fix2) step1 = step2 = 0.0;
        double f0 = dot3(r, r);
        double ns = clip01(s + step1), nt = clip01(t + step2);
        fresh = 0;
        for (int h = 0; h < 3; h++) {
            quad_residual(c, x, ns, nt, rn);
            if (!(dot3(rn, rn) > f0 * (1 + 1e-10))) {
                fresh = 1;
                break;
            }
            step1 *= 0.5;
            step2 *= 0.5;
            ns = clip01(s + step1);
            nt = clip01(t + step2);
        }
        double ds = fabs(ns - s), dt = fabs(nt - t);
        int done = (ds > dt ? ds : dt) <= NEWTON_TOL;
        s = ns;
        t = nt;
        if (fresh) memcpy(r, rn, sizeof r);
        if (done) {
            *conv = 1;
            break;
        }
    }
    for (int k = 0; k < 3; k++) {
        a1[k] = c[1][k] + t * c[3][k];
        a2[k] = c[2][k] + s * c[3][k];
    }
    if (!fresh) quad_residual(c, x, s, t, r);
    double h11 = dot3(a1, a1), h22 = dot3(a2, a2);
    double h12 = dot3(a1, a2) - dot3(r, c[3]);
    *pd = h11 > 0 && h11 * h22 - h12 * h12 > 0;
    xi[0] = s;
    xi[1] = t;
    return sqrt(dot3(r, r));
}

INLINE int inner(const double *xi) { return xi[0] > 0.0 && xi[0] < 1.0 && xi[1] > 0.0 && xi[1] < 1.0; }

static void quadrilateral(const double *X, const double *x, pair_t *out)
{
    static const double starts[4][2] = {{0.25, 0.25}, {0.75, 0.25}, {0.25, 0.75}, {0.75, 0.75}};
    edges(3, 4, QUAD_EDGES, QUAD_XI, 2, X, x, out);
    double c[4][3];
    for (int k = 0; k < 3; k++) {
        c[0][k] = X[k];
        c[1][k] = X[3 + k] - X[k];
        c[2][k] = X[6 + k] - X[k];
        c[3][k] = X[k] - X[3 + k] - X[6 + k] + X[9 + k];
    }
    double xi[2] = {0.5, 0.5};
    int conv, pd;
    double dist = quad_newton(c, x, xi, &conv, &pd);
    if (!conv || (inner(xi) && !pd)) {
        for (int j = 0; j < 4; j++) {
            double xr[2] = {starts[j][0], starts[j][1]};
            int conv_r, pd_r;
            double dist_r = quad_newton(c, x, xr, &conv_r, &pd_r);
            if (inner(xr) && (!inner(xi) || dist_r < dist)) {
                xi[0] = xr[0];
                xi[1] = xr[1];
                dist = dist_r;
            }
        }
    }
    if (inner(xi) && dist < out->dist) {
        out->xi[0] = xi[0];
        out->xi[1] = xi[1];
        out->dist = dist;
        out->edge = -1;
        out->vertex = 0;
    }
}

/* -- quadratic facets (curved.py's kernels, for one pair) --------------------------------- */

/* The shape functions N (nn), first derivatives dN[alpha][n] and second derivatives
 * d2N[alpha][beta][n] of the quadratic facet kind (3: segment3, 4: triangle6, 5:
 * quadrilateral9) at xi (curved.quadratic_shape_functions). */
INLINE void quadratic_shape(int kind, const double *xi, double *N, double (*dN)[9],
                            double (*d2N)[2][9])
{
    if (kind == 3) {
        double u = xi[0];
        N[0] = (1 - u) * (1 - 2 * u), N[1] = u * (2 * u - 1), N[2] = 4 * u * (1 - u);
        dN[0][0] = 4 * u - 3, dN[0][1] = 4 * u - 1, dN[0][2] = 4 - 8 * u;
        d2N[0][0][0] = 4.0, d2N[0][0][1] = 4.0, d2N[0][0][2] = -8.0;
        return;
    }
    if (kind == 4) {
        static const double dL[3][2] = {{-1.0, -1.0}, {1.0, 0.0}, {0.0, 1.0}};
        const double L[3] = {1.0 - xi[0] - xi[1], xi[0], xi[1]};
        for (int i = 0; i < 3; i++) {
            N[i] = L[i] * (2 * L[i] - 1);
            for (int a = 0; a < 2; a++) {
                dN[a][i] = (4 * L[i] - 1) * dL[i][a];
                for (int b = 0; b < 2; b++) d2N[a][b][i] = 4 * (dL[i][a] * dL[i][b]);
            }
        }
        for (int e = 0; e < 3; e++) {
            int i = TRI6_EDGES[e][0], j = TRI6_EDGES[e][1], n = TRI6_EDGES[e][2];
            N[n] = 4 * L[i] * L[j];
            for (int a = 0; a < 2; a++) {
                dN[a][n] = 4 * (L[j] * dL[i][a] + L[i] * dL[j][a]);
                for (int b = 0; b < 2; b++)
                    d2N[a][b][n] = 4 * (dL[i][a] * dL[j][b] + dL[j][a] * dL[i][b]);
            }
        }
        return;
    }
    /* the tensor product of the 1D functions (start, end, middle) */
    static const int Q9[9][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 0},
                                 {1, 2}, {2, 1}, {0, 2}, {2, 2}};
    double l[2][3], dl[2][3];
    static const double d2l[3] = {4.0, 4.0, -8.0};
    for (int a = 0; a < 2; a++) {
        double u = xi[a];
        l[a][0] = (1 - u) * (1 - 2 * u), l[a][1] = u * (2 * u - 1), l[a][2] = 4 * u * (1 - u);
        dl[a][0] = 4 * u - 3, dl[a][1] = 4 * u - 1, dl[a][2] = 4 - 8 * u;
    }
    for (int n = 0; n < 9; n++) {
        int i = Q9[n][0], j = Q9[n][1];
        N[n] = l[0][i] * l[1][j];
        dN[0][n] = dl[0][i] * l[1][j];
        dN[1][n] = l[0][i] * dl[1][j];
        d2N[0][0][n] = d2l[i] * l[1][j];
        d2N[0][1][n] = d2N[1][0][n] = dl[0][i] * dl[1][j];
        d2N[1][1][n] = l[0][i] * d2l[j];
    }
}

/* sum_n w[n] X[n] (g) */
INLINE void combine(int g, int nn, const double *w, const double *X, double *out)
{
    for (int k = 0; k < g; k++) {
        double v = w[0] * X[k];
        for (int n = 1; n < nn; n++) v += w[n] * X[n * g + k];
        out[k] = v;
    }
}

/* The distance of x from the straight segment AB (g coordinates). */
INLINE double segment_distance(int g, const double *x, const double *A, const double *B)
{
    double e[3], r[3], w[3];
    for (int k = 0; k < g; k++) {
        e[k] = B[k] - A[k];
        r[k] = x[k] - A[k];
    }
    double ee = sum_prod(g, e, e);
    double u = clip01(sum_prod(g, r, e) / (ee > 0 ? ee : 1.0));
    for (int k = 0; k < g; k++) w[k] = r[k] - u * e[k];
    return sqrt(sum_prod(g, w, w));
}

/* curved.curve_closest for one point: the closest point of x on the quadratic curve through
 * A (u = 0), C (u = 1/2) and B (u = 1); returns the distance, u in *u (exactly 0 or 1 at an
 * end). */
static double curve_closest(int g, const double *x, const double *A, const double *B,
                            const double *C, double *u_out)
{
    double b1[3], b2[3], r0[3], chord[3], r[3], rn[3], dy[3];
    for (int k = 0; k < g; k++) {
        b1[k] = 4.0 * C[k] - 3.0 * A[k] - B[k];
        b2[k] = 2.0 * A[k] + 2.0 * B[k] - 4.0 * C[k];
        r0[k] = x[k] - A[k];
        chord[k] = B[k] - A[k];
    }
    double cc = sum_prod(g, chord, chord);
    double u = clip01(sum_prod(g, r0, chord) / (cc > 0 ? cc : 1.0));
    for (int it = 0; it < NEWTON_ITERATIONS; it++) {
        for (int k = 0; k < g; k++) {
            r[k] = r0[k] - u * b1[k] - (u * u) * b2[k];
            dy[k] = b1[k] + 2.0 * u * b2[k];
        }
        double gr = -sum_prod(g, r, dy), gn = sum_prod(g, dy, dy);
        double h = gn - 2.0 * sum_prod(g, r, b2);
        h = h > 1e-12 * gn ? h : gn;
        double step = -gr / (h > 0 ? h : INFINITY);
        if ((u <= 0.0 && gr > 0) || (u >= 1.0 && gr < 0)) step = 0.0;
        double f0 = sum_prod(g, r, r), next = clip01(u + step);
        for (int half = 0; half < 3; half++) {
            for (int k = 0; k < g; k++) rn[k] = r0[k] - next * b1[k] - (next * next) * b2[k];
            if (!(sum_prod(g, rn, rn) > f0 * (1 + 1e-10))) break;
            step *= 0.5;
            next = clip01(u + step);
        }
        int done = fabs(next - u) <= NEWTON_TOL;
        u = next;
        if (done) break;
    }
    for (int k = 0; k < g; k++) {
        r[k] = r0[k] - u * b1[k] - (u * u) * b2[k];
        rn[k] = x[k] - B[k];
    }
    double d_newton = sqrt(sum_prod(g, r, r)), d_start = sqrt(sum_prod(g, r0, r0));
    double d_end = sqrt(sum_prod(g, rn, rn)), d = d_newton;
    if (d_start < d) {
        d = d_start;
        u = 0.0;
    }
    if (d_end < d) {
        d = d_end;
        u = 1.0;
    }
    *u_out = u;
    return d;
}

/* A quadratic facet of two reference dimensions in monomial form, y(s, t) = sum_pq
 * C[p][q] s^p t^q (p, q <= 2; of a 6-node triangle p + q <= 2), made once per projection:
 * the Newton iterations then evaluate y, its tangents and second derivatives in a few
 * operations instead of the shape functions' sums over the nodes. */
typedef struct {
    double C[3][3][3]; /* C[p][q][k] */
} patch_t;

/* the monomial coefficients of the 1D quadratic Lagrange functions (start, end, middle) */
static const double LAGRANGE_1D[3][3] = {{1.0, -3.0, 2.0}, {0.0, -1.0, 2.0}, {0.0, 4.0, -4.0}};

static void make_patch(int kind, const double *X, patch_t *P)
{
    memset(P, 0, sizeof *P);
    if (kind == 5) { /* node n = (i, j): l_i(s) l_j(t) */
        static const int Q9[9][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 0},
                                     {1, 2}, {2, 1}, {0, 2}, {2, 2}};
        for (int n = 0; n < 9; n++)
            for (int p = 0; p < 3; p++)
                for (int q = 0; q < 3; q++) {
                    double w = LAGRANGE_1D[Q9[n][0]][p] * LAGRANGE_1D[Q9[n][1]][q];
                    if (w != 0.0)
                        for (int k = 0; k < 3; k++) P->C[p][q][k] += w * X[3 * n + k];
                }
        return;
    }
    /* a 6-node triangle: its value, tangents and (constant) second derivatives at 0 */
    double N[9], dN[2][9], d2N[2][2][9], zero[2] = {0.0, 0.0}, c[3];
    quadratic_shape(4, zero, N, dN, d2N);
    combine(3, 6, N, X, P->C[0][0]);
    combine(3, 6, dN[0], X, P->C[1][0]);
    combine(3, 6, dN[1], X, P->C[0][1]);
    combine(3, 6, d2N[0][1], X, P->C[1][1]);
    combine(3, 6, d2N[0][0], X, c);
    for (int k = 0; k < 3; k++) P->C[2][0][k] = 0.5 * c[k];
    combine(3, 6, d2N[1][1], X, c);
    for (int k = 0; k < 3; k++) P->C[0][2][k] = 0.5 * c[k];
}

/* The state of a Newton iteration on a quadratic facet at xi: x - y, the tangents a, the
 * Hessian H of |x - y|^2 / 2 and the metric gm (curved._state). */
typedef struct {
    double r[3], a[2][3], H[2][2], gm[2][2];
} state_t;

/* x - y(xi) */
INLINE void patch_residual(int kind, const patch_t *P, const double *x, const double *xi,
                           double *r)
{
    const double s = xi[0], t = xi[1], t2 = t * t, S[3] = {1.0, s, s * s};
    for (int k = 0; k < 3; k++) {
        double v = 0.0;
        if (kind == 4) /* the terms of the nine-term sum that are not zero, in its order */
            v = ((P->C[0][0][k] + t * P->C[0][1][k]) + t2 * P->C[0][2][k])
                + S[1] * (P->C[1][0][k] + t * P->C[1][1][k]) + S[2] * P->C[2][0][k];
        else
            for (int p = 0; p < 3; p++)
                v += S[p] * (P->C[p][0][k] + t * P->C[p][1][k] + t2 * P->C[p][2][k]);
        r[k] = x[k] - v;
    }
}

/* The state at xi, the sums over the monomials without their terms that are zero (of a
 * 6-node triangle only those of p + q <= 2; the factors dS[0], dT[0], d2[0], d2[1]), in the
 * order of the full sums: the same values. */
INLINE void patch_state(int kind, const patch_t *P, const double *x, const double *xi,
                        state_t *Z)
{
    const double s = xi[0], t = xi[1];
    const double S[3] = {1.0, s, s * s}, T[3] = {1.0, t, t * t};
    const double dS[3] = {0.0, 1.0, 2.0 * s}, dT[3] = {0.0, 1.0, 2.0 * t};
    const double d2[3] = {0.0, 0.0, 2.0};
    double y2[2][2][3] = {{{0.0}}};
    patch_residual(kind, P, x, xi, Z->r);
    for (int k = 0; k < 3; k++) {
        if (kind == 4) {
            Z->a[0][k] = (P->C[1][0][k] + t * P->C[1][1][k]) + dS[2] * P->C[2][0][k];
            Z->a[1][k] = (P->C[0][1][k] + dT[2] * P->C[0][2][k]) + s * P->C[1][1][k];
            y2[0][0][k] = 2.0 * P->C[2][0][k];
            y2[0][1][k] = P->C[1][1][k];
            y2[1][1][k] = 2.0 * P->C[0][2][k];
            continue;
        }
        /* the sums over p, q in that order without their zero terms (dS[0] = dT[0] = 0,
         * d2[0] = d2[1] = 0) */
        double a0 = 0.0, a1 = 0.0;
        for (int p = 1; p < 3; p++)
            for (int q = 0; q < 3; q++) a0 += dS[p] * T[q] * P->C[p][q][k];
        for (int p = 0; p < 3; p++)
            for (int q = 1; q < 3; q++) a1 += S[p] * dT[q] * P->C[p][q][k];
        for (int q = 0; q < 3; q++) y2[0][0][k] += d2[2] * T[q] * P->C[2][q][k];
        for (int p = 1; p < 3; p++)
            for (int q = 1; q < 3; q++) y2[0][1][k] += dS[p] * dT[q] * P->C[p][q][k];
        for (int p = 0; p < 3; p++) y2[1][1][k] += S[p] * d2[2] * P->C[p][2][k];
        Z->a[0][k] = a0;
        Z->a[1][k] = a1;
    }
    for (int al = 0; al < 2; al++)
        for (int be = al; be < 2; be++) {
            Z->gm[al][be] = Z->gm[be][al] = dot3(Z->a[al], Z->a[be]);
            Z->H[al][be] = Z->H[be][al] = Z->gm[al][be] - dot3(Z->r, y2[al][be]);
        }
}

/* curved._newton for one pair from xi (in/out): returns the distance; *settled whether xi is
 * a strict local minimum (converged, positive definite Hessian), *good whether it is one
 * inside the facet. The state of an accepted iterate (whose residual the line search
 * checks) is the next iteration's. */
INLINE double curved_newton(int kind, const patch_t *P, const double *x, double *xi, int *good,
                            int *settled)
{
    state_t Z, Zn;
    int conv = 0;
    patch_state(kind, P, x, xi, &Z);
    for (int it = 0; it < NEWTON_ITERATIONS; it++) {
        double H[2][2];
        double g0 = -dot3(Z.r, Z.a[0]), g1 = -dot3(Z.r, Z.a[1]);
        memcpy(H, Z.H, sizeof H);
        double det = H[0][0] * H[1][1] - H[0][1] * H[1][0];
        if (det <= 1e-12 * H[0][0] * H[1][1] || H[0][0] <= 0) memcpy(H, Z.gm, sizeof H);
        det = H[0][0] * H[1][1] - H[0][1] * H[1][0];
        det = det > 0 ? det : INFINITY;
        double step[2] = {-(H[1][1] * g0 - H[0][1] * g1) / det,
                          -(H[0][0] * g1 - H[1][0] * g0) / det};
        for (int j = 0; j < 2; j++) /* keep the iterate near the facet */
            step[j] = step[j] < -0.5 ? -0.5 : (step[j] > 0.5 ? 0.5 : step[j]);
        double f0 = dot3(Z.r, Z.r), next[2] = {xi[0] + step[0], xi[1] + step[1]};
        int half = 0;
        for (; half < 3; half++) {
            patch_state(kind, P, x, next, &Zn);
            if (!(dot3(Zn.r, Zn.r) > f0 * (1 + 1e-10))) break;
            for (int j = 0; j < 2; j++) {
                step[j] *= 0.5;
                next[j] = xi[j] + step[j];
            }
        }
        if (half == 3) patch_state(kind, P, x, next, &Zn); /* the last halving, unchecked */
        double d0 = fabs(next[0] - xi[0]), d1 = fabs(next[1] - xi[1]);
        int done = (d0 > d1 ? d0 : d1) <= NEWTON_TOL;
        xi[0] = next[0];
        xi[1] = next[1];
        Z = Zn;
        if (done) {
            conv = 1;
            break;
        }
    }
    int inside = xi[0] > 0.0 && xi[1] > 0.0
                 && (kind == 4 ? xi[0] + xi[1] < 1.0 : xi[0] < 1.0 && xi[1] < 1.0);
    int pd = Z.H[0][0] > 0 && Z.H[0][0] * Z.H[1][1] - Z.H[0][1] * Z.H[1][0] > 0;
    *settled = conv && pd;
    *good = *settled && inside;
    return sqrt(dot3(Z.r, Z.r));
}

/* The largest squared distance of the points P[m] of the ne edges (i, j, m) of E from the
 * midpoints of the chords X[i] X[j] (3D). */
INLINE double largest_offset(int ne, const int (*E)[3], const double *P, const double *X)
{
    double largest = 0.0;
    for (int e = 0; e < ne; e++) {
        double d[3];
        for (int k = 0; k < 3; k++)
            d[k] = P[3 * E[e][2] + k] - 0.5 * (X[3 * E[e][0] + k] + X[3 * E[e][1] + k]);
        double d2 = dot3(d, d);
        largest = d2 > largest ? d2 : largest;
    }
    return largest;
}

/* curved.curvature of the quadratic facet X (kind 4 or 5): 8 |delta| / L^2 */
static double curvature(int kind, const double *X)
{
    const int ne = kind == 4 ? 3 : 4;
    const int(*E)[3] = kind == 4 ? TRI6_EDGES : QUAD9_EDGES;
    double offset2 = largest_offset(ne, E, X, X), chord2 = INFINITY;
    for (int e = 0; e < ne; e++) {
        double d[3];
        for (int k = 0; k < 3; k++) d[k] = X[3 * E[e][1] + k] - X[3 * E[e][0] + k];
        double d2 = dot3(d, d);
        chord2 = d2 < chord2 ? d2 : chord2;
    }
    if (kind == 5) { /* the centre node from the 8-node quadrilateral's centre */
        double d[3];
        for (int k = 0; k < 3; k++)
            d[k] = X[24 + k] - (0.5 * (X[12 + k] + X[15 + k] + X[18 + k] + X[21 + k])
                                - 0.25 * (X[k] + X[3 + k] + X[6 + k] + X[9 + k]));
        double d2 = dot3(d, d);
        offset2 = d2 > offset2 ? d2 : offset2;
    }
    return 8.0 * sqrt(offset2) / chord2;
}

/* curved._restart: whether a Newton result (distance dist) calls for a restart */
INLINE int restart(int kind, const double *X, double dist, int good, int settled)
{
    return !good && (!settled || dist * curvature(kind, X) > RESTART_CURVATURE);
}

/* curved.triangle_interior for one pair: Newton from the projection on the plane of the
 * vertices (clamped into the triangle), restarted from the centroid where it may have
 * missed an interior minimum (restart). */
static double triangle6_interior(const double *X, const double *x, double *xi, int *good)
{
    double a1[3], a2[3], r[3];
    if (!plane_xi(X, x, xi, a1, a2, r)) xi[0] = xi[1] = 1.0 / 3.0;
    xi[0] = clip01(xi[0]);
    xi[1] = clip01(xi[1]);
    double sum = xi[0] + xi[1];
    if (sum > 1.0) {
        xi[0] /= sum;
        xi[1] /= sum;
    }
    patch_t P;
    make_patch(4, X, &P);
    int settled;
    double dist = curved_newton(4, &P, x, xi, good, &settled);
    if (restart(4, X, dist, *good, settled)) {
        double xr[2] = {1.0 / 3.0, 1.0 / 3.0};
        int good_r;
        double dist_r = curved_newton(4, &P, x, xr, &good_r, &settled);
        if (good_r) {
            xi[0] = xr[0], xi[1] = xr[1], dist = dist_r, *good = 1;
        }
    }
    return dist;
}

/* curved.quadrilateral_interior for one pair: Newton from the centre, restarted from four
 * other points in turn while the last result calls for it (restart). */
static double quadrilateral9_interior(const double *X, const double *x, double *xi, int *good)
{
    static const double starts[4][2] = {{0.25, 0.25}, {0.75, 0.25}, {0.25, 0.75}, {0.75, 0.75}};
    patch_t P;
    make_patch(5, X, &P);
    xi[0] = xi[1] = 0.5;
    int settled;
    double dist = curved_newton(5, &P, x, xi, good, &settled);
    int again = restart(5, X, dist, *good, settled);
    for (int j = 0; j < 4 && again; j++) {
        double xr[2] = {starts[j][0], starts[j][1]};
        int good_r;
        double dist_r = curved_newton(5, &P, x, xr, &good_r, &settled);
        if (good_r) {
            xi[0] = xr[0], xi[1] = xr[1], dist = dist_r, *good = 1;
        }
        again = restart(5, X, dist_r, good_r, settled);
    }
    return dist;
}

/* projection._Master._project_quadratic for one pair: the closest point on the curved
 * edges, replaced by an interior minimum where that is closer. */
static void quadratic(int kind, const double *X, const double *x, pair_t *out)
{
    if (kind == 3) {
        double u, d = curve_closest(2, x, X, X + 2, X + 4, &u);
        out->xi[0] = u;
        out->dist = d;
        out->edge = -1;
        out->vertex = u == 0.0 || u == 1.0;
        return;
    }
    const int ne = kind == 4 ? 3 : 4;
    const int(*E)[3] = kind == 4 ? TRI6_EDGES : QUAD9_EDGES;
    const double(*XI)[2][2] = kind == 4 ? TRI_XI : QUAD_XI;
    double xi[2];
    int good;
    double d_in = kind == 4 ? triangle6_interior(X, x, xi, &good)
                            : quadrilateral9_interior(X, x, xi, &good);
    /* The interior minimum wins unless an edge is at most as close (the order of
     * _project_quadratic: the edges' best in their order, ties to the first, replaced by the
     * interior where strictly closer). An edge whose distance is certainly above d_in, or
     * above the best edge so far, cannot change the result and is not projected: the curve
     * y = chord + 4 u (1 - u) delta is within |delta| of its chord, so its distance is at
     * least the chord's minus |delta| (margin far above round-off). */
    double best_d = INFINITY, best_u = 0.0;
    int best_k = -1;
    for (int n = 0; n < ne; n++) {
        const double *A = X + 3 * E[n][0], *B = X + 3 * E[n][1], *C = X + 3 * E[n][2];
        if (good || best_k >= 0) {
            double delta[3], chord[3];
            for (int k = 0; k < 3; k++) {
                delta[k] = C[k] - 0.5 * (A[k] + B[k]);
                chord[k] = B[k] - A[k];
            }
            double lower = segment_distance(3, x, A, B) - sqrt(dot3(delta, delta));
            double bar = good && d_in < best_d ? d_in : best_d;
            if (lower > bar + 1e-10 * (bar + sqrt(dot3(chord, chord)))) continue;
        }
        double u, d = curve_closest(3, x, A, B, C, &u);
        if (best_k < 0 || d < best_d) {
            best_d = d;
            best_u = u;
            best_k = n;
        }
    }
    if (good && (best_k < 0 || d_in < best_d)) {
        out->xi[0] = xi[0];
        out->xi[1] = xi[1];
        out->dist = d_in;
        out->edge = -1;
        out->vertex = 0;
        return;
    }
    for (int j = 0; j < 2; j++)
        out->xi[j] = XI[best_k][0][j] + best_u * (XI[best_k][1][j] - XI[best_k][0][j]);
    out->dist = best_d;
    out->edge = best_k;
    out->vertex = best_u == 0.0 || best_u == 1.0;
}

/* The deviation of the quadratic facet X (kind 3, 4 or 5) from its chord facet, the
 * straight facet of its vertices: a bound of their distance point for point (at the same
 * reference coordinates, both ways), so that the distance of a point from the facet is
 * within it of the distance from the chord facet (an exact projection, cheap).
 * - 3-node segment: the chord AB, y = chord + 4 u (1 - u) delta, delta the midpoint node's
 *   offset from the chord's midpoint: |delta|.
 * - 6-node triangle: the triangle of the vertices plus sum_e 4 L_i L_j delta_e (weights
 *   summing to at most 4/3): 4/3 max |delta_e|.
 * - 9-node quadrilateral: the two triangles (v0, v1, v2), (v1, v3, v2) of its corners. The
 *   facet minus the bilinear patch of the corners has the Bernstein control points H - P (P
 *   those of the bilinear patch: the corners, the edges' chord midpoints, the corners'
 *   mean), so it is within max |H - P|; the bilinear patch is within |c3| / 4 of the two
 *   triangles (s t c3, (1 - s)(1 - t) c3 at most a quarter, c3 = x0 - x1 - x2 + x3).
 * Made once per refit (the facet's record). */
static double chord_deviation(int kind, const double *X)
{
    if (kind == 3) {
        double delta[2] = {X[4] - 0.5 * (X[0] + X[2]), X[5] - 0.5 * (X[1] + X[3])};
        return sqrt(sum_prod(2, delta, delta));
    }
    if (kind == 4) return 4.0 / 3.0 * sqrt(largest_offset(3, TRI6_EDGES, X, X));
    double H[27], c3[3], d[3];
    hull(5, 3, X, H);
    double dev2 = largest_offset(4, QUAD9_EDGES, H, X); /* H - chord midpoints */
    for (int k = 0; k < 3; k++) { /* the centre: H - the corners' mean */
        d[k] = H[24 + k] - 0.25 * (X[k] + X[3 + k] + X[6 + k] + X[9 + k]);
        c3[k] = X[k] - X[3 + k] - X[6 + k] + X[9 + k];
    }
    double d2 = dot3(d, d);
    dev2 = d2 > dev2 ? d2 : dev2;
    return sqrt(dev2) + 0.25 * sqrt(dot3(c3, c3));
}

/* The squared distance of x from the segment A, A + e (3D). */
INLINE double segment_distance2(const double *x, const double *A, const double *e)
{
    double r[3] = {x[0] - A[0], x[1] - A[1], x[2] - A[2]}, ee = dot3(e, e);
    double u = clip01(dot3(r, e) / (ee > 0 ? ee : 1.0));
    for (int k = 0; k < 3; k++) r[k] -= u * e[k];
    return dot3(r, r);
}

/* The distance of x from the triangle A, B, C (3D) for a chord bound: from its plane where
 * the projection on it is inside, else from the edges whose lines the projection is beyond
 * (the closest point of a triangle lies on such an edge: one or two edges, not three), every
 * edge of a degenerate triangle. The distance of triangle() to round-off. */
INLINE double triangle_distance(const double *A, const double *B, const double *C,
                                const double *x)
{
    double a1[3], a2[3], a3[3], r[3];
    for (int k = 0; k < 3; k++) {
        a1[k] = B[k] - A[k];
        a2[k] = C[k] - A[k];
        a3[k] = C[k] - B[k];
        r[k] = x[k] - A[k];
    }
    double g11 = dot3(a1, a1), g12 = dot3(a1, a2), g22 = dot3(a2, a2);
    double det = g11 * g22 - g12 * g12, b1 = dot3(r, a1), b2 = dot3(r, a2);
    int flat = !(det > 1e-14 * g11 * g22);
    double s1 = g22 * b1 - g12 * b2, s2 = g11 * b2 - g12 * b1; /* det xi */
    if (!flat && s1 > 0.0 && s2 > 0.0 && s1 + s2 < det) {
        double xi1 = s1 / det, xi2 = s2 / det, w[3];
        for (int k = 0; k < 3; k++) w[k] = r[k] - xi1 * a1[k] - xi2 * a2[k];
        return sqrt(dot3(w, w));
    }
    double d2 = INFINITY, e;
    if (flat || s2 <= 0.0) d2 = segment_distance2(x, A, a1);
    if (flat || s1 <= 0.0) d2 = (e = segment_distance2(x, A, a2)) < d2 ? e : d2;
    if (flat || s1 + s2 >= det) d2 = (e = segment_distance2(x, B, a3)) < d2 ? e : d2;
    return sqrt(d2);
}

/* Bounds of the distance of x from a quadratic facet X (kind 3, 4 or 5) without its
 * projection: the distance from its chord facet (of kind 5, the nearer of the two
 * triangles of its corners) widened by the facet's chord deviation dev. */
INLINE void chord_bounds(int kind, const double *X, double dev, const double *x,
                         double *lower, double *upper)
{
    double chord;
    if (kind == 3) {
        chord = segment_distance(2, x, X, X + 2);
    } else if (kind == 4) {
        chord = triangle_distance(X, X + 3, X + 6, x);
    } else { /* (v0, v1, v2) and (v1, v3, v2) */
        double d0 = triangle_distance(X, X + 3, X + 6, x);
        double d1 = triangle_distance(X + 3, X + 9, X + 6, x);
        chord = d0 < d1 ? d0 : d1;
    }
    /* widened by far more than the round-off of the distances */
    *lower = chord - dev * (1 + 1e-12);
    *upper = chord + dev * (1 + 1e-12);
}

INLINE void project(int kind, const double *X, const double *x, pair_t *out)
{
    if (kind == 0) {
        edges(2, 1, SEG_EDGES, SEG_XI, 1, X, x, out);
        out->edge = -1;
    } else if (kind == 1) {
        triangle(X, x, out);
    } else if (kind == 2) {
        quadrilateral(X, x, out);
    } else {
        quadratic(kind, X, x, out);
    }
}

/* -- branch-and-bound query -------------------------------------------------------------- */

INLINE double box_distance2(int g, const double *B, const double *x)
{
    /* branch-free: max(lo - x, x - hi, 0) per coordinate (a box is never inverted) */
    double s = 0.0;
    for (int k = 0; k < g; k++) {
        double lo = B[k] - x[k], hi = x[k] - B[g + k];
        double d = lo > hi ? lo : hi;
        d = d > 0.0 ? d : 0.0;
        s += d * d;
    }
    return s;
}

/* The squared distances d (WIDE) from x to the children's boxes of row N (box_distance2 of
 * the single-precision boxes, their bounds exact in double), the children side by side:
 * with the GNU vector extensions (GCC, Clang) the four at once, the same operations in the
 * same order per child. */
#if defined(__GNUC__) || defined(__clang__)
/* two lanes of doubles, two of 64-bit masks (SSE2, NEON): two children at a time */
typedef double vd2 __attribute__((vector_size(2 * sizeof(double))));
typedef long long vl2 __attribute__((vector_size(2 * sizeof(long long))));

/* a > b ? a : b per lane */
INLINE vd2 larger(vd2 a, vd2 b)
{
    vl2 m = a > b;
    return (vd2)(((vl2)a & m) | ((vl2)b & ~m));
}

INLINE void row_distance2(int g, const node_t *N, const double *x, double *d)
{
    const vd2 zero = {0.0, 0.0};
    vd2 s0 = zero, s1 = zero; /* children 0, 1 and 2, 3 */
    for (int k = 0; k < g; k++) {
        const float *lo = N->lo[k], *hi = N->hi[k];
        vd2 xk = {x[k], x[k]};
        vd2 lo0 = {lo[0], lo[1]}, lo1 = {lo[2], lo[3]}, hi0 = {hi[0], hi[1]}, hi1 = {hi[2], hi[3]};
        vd2 e0 = larger(larger(lo0 - xk, xk - hi0), zero);
        vd2 e1 = larger(larger(lo1 - xk, xk - hi1), zero);
        s0 += e0 * e0;
        s1 += e1 * e1;
    }
    d[0] = s0[0];
    d[1] = s0[1];
    d[2] = s1[0];
    d[3] = s1[1];
}
#else
INLINE void row_distance2(int g, const node_t *N, const double *x, double *d)
{
    for (int c = 0; c < WIDE; c++) d[c] = 0.0;
    for (int k = 0; k < g; k++)
        for (int c = 0; c < WIDE; c++) {
            double lo = (double)N->lo[k][c] - x[k], hi = x[k] - (double)N->hi[k][c];
            double e = lo > hi ? lo : hi;
            e = e > 0.0 ? e : 0.0;
            d[c] += e * e;
        }
}
#endif

/* Whether the surface facet X (kind 1 or 2) is certainly farther than bound from x: the
 * facet lies in a slab along its normal n at the centre (a triangle in its plane; a bilinear
 * quadrilateral between its corners' heights, n . X(s, t) being bilinear), so the distance
 * from x to the slab is a lower bound of its distance. The slab must be beyond bound by a
 * margin (1e-10 (bound + rmax), far above the round-off of either distance), so that no
 * facet within bound of x by its exact projection is ever skipped. Used before the
 * quadrilaterals' projections (several Newton steps); a triangle's costs no more than it. */
INLINE int beyond_slab(int kind, const double *X, const double *x, double bound, double rmax)
{
    double a1[3], a2[3], n[3], h[4] = {0.0}, r[3];
    for (int k = 0; k < 3; k++) {
        a1[k] = X[3 + k] - X[k];
        a2[k] = X[6 + k] - X[k];
        r[k] = x[k] - X[k];
    }
    if (kind == 2) /* the tangents at the centre */
        for (int k = 0; k < 3; k++) {
            double c3 = 0.5 * (X[k] - X[3 + k] - X[6 + k] + X[9 + k]);
            a1[k] += c3;
            a2[k] += c3;
        }
    n[0] = a1[1] * a2[2] - a1[2] * a2[1];
    n[1] = a1[2] * a2[0] - a1[0] * a2[2];
    n[2] = a1[0] * a2[1] - a1[1] * a2[0];
    double lo = 0.0, hi = 0.0, hx = dot3(n, r);
    for (int q = 1; q < (kind == 2 ? 4 : 3); q++) {
        double e[3] = {X[3 * q] - X[0], X[3 * q + 1] - X[1], X[3 * q + 2] - X[2]};
        h[q] = dot3(n, e);
        lo = h[q] < lo ? h[q] : lo;
        hi = h[q] > hi ? h[q] : hi;
    }
    double excess = hx > hi ? hx - hi : (hx < lo ? lo - hx : 0.0);
    double margin = bound + 1e-10 * (bound + rmax);
    return excess * excess > margin * margin * dot3(n, n);
}

/* Start loading what the walk reads of a child (code as in node_t): its row, or the nodes
 * of the leaf's facets. */
INLINE void prefetch_child(const node_t *T, const double *leaves, int w, i64 code)
{
    if (code >= 0) {
        PREFETCH(T + code);
        PREFETCH((const char *)(T + code) + 64);
    } else {
        const double *X = leaves + ((-code - 1) >> 3) * w;
        for (int q = 0; q < ((-code - 1) & 7) * w; q += 8) PREFETCH(X + q);
    }
}

/* the distance below which a facet may tie with the closest one at distance v (wider than
 * the tie tolerance 1e-10 (v + 2 R_f) of projection._select) */
INLINE double reach(double v, double rmax) { return v + 1e-9 * (v + 2.0 * rmax); }

typedef struct {
    i64 j; /* position in the leaves */
    pair_t q;
    double key; /* q.dist once projected; before, a lower bound of it (a deferred facet) */
} hit_t;

/* The closest point y (g) of x on the facet X at q.xi as projection._select computes it, with
 * r = x - y, the unit normal nu (g; zero on a degenerate facet), the tangents a and (a
 * quadratic facet) the second derivatives d2N of the shape functions. Returns |x - y|. */
INLINE double closest_point(int kind, int g, int nn, const double *X, const double *x,
                            const pair_t *q, double *y, double *r, double *nu, double (*a)[3],
                            double (*d2N)[2][9])
{
    double N[9], dN[2][9];
    int fdim = g - 1;
    if (kind >= 3) {
        quadratic_shape(kind, q->xi, N, dN, d2N);
    } else if (kind == 0) {
        double u = q->xi[0];
        N[0] = 1.0 - u;
        N[1] = u;
        dN[0][0] = -1.0;
        dN[0][1] = 1.0;
    } else if (kind == 1) {
        N[0] = 1.0 - q->xi[0] - q->xi[1];
        N[1] = q->xi[0];
        N[2] = q->xi[1];
        dN[0][0] = -1.0, dN[0][1] = 1.0, dN[0][2] = 0.0;
        dN[1][0] = -1.0, dN[1][1] = 0.0, dN[1][2] = 1.0;
    } else {
        double s = q->xi[0], t = q->xi[1];
        N[0] = (1 - s) * (1 - t), N[1] = s * (1 - t), N[2] = (1 - s) * t, N[3] = s * t;
        dN[0][0] = t - 1.0, dN[0][1] = 1.0 - t, dN[0][2] = -t, dN[0][3] = t;
        dN[1][0] = s - 1.0, dN[1][1] = -s, dN[1][2] = 1.0 - s, dN[1][3] = s;
    }
    for (int k = 0; k < g; k++) {
        double v = N[0] * X[k];
        for (int n = 1; n < nn; n++) v += N[n] * X[n * g + k];
        y[k] = v;
        r[k] = x[k] - v;
        for (int al = 0; al < fdim; al++) {
            double w = dN[al][0] * X[k];
            for (int n = 1; n < nn; n++) w += dN[al][n] * X[n * g + k];
            a[al][k] = w;
        }
    }
    double n3[3], len2 = 0.0;
    if (g == 2) {
        n3[0] = a[0][1];
        n3[1] = -a[0][0];
    } else {
        n3[0] = a[0][1] * a[1][2] - a[0][2] * a[1][1];
        n3[1] = a[0][2] * a[1][0] - a[0][0] * a[1][2];
        n3[2] = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    }
    for (int k = 0; k < g; k++) len2 += n3[k] * n3[k];
    double len = sqrt(len2), rr = 0.0;
    for (int k = 0; k < g; k++) {
        nu[k] = len > 0 ? n3[k] / len : 0.0;
        rr += r[k] * r[k];
    }
    return sqrt(rr);
}

/* The closest point of x on the facet X at q.xi and what projection._select computes of it:
 * y (g), the unit normal nu (g), gap -nu . (x - y), distance |x - y| and the linearisation
 * M (fdim, fdim; projection._sliding). Returns whether the distance is within radius. */
INLINE int finish(int kind, int g, int nn, const double *X, const double *x, const pair_t *q,
                  double radius, double *y, double *nu, double *gap, double *distance,
                  double *M)
{
    double d2N[2][2][9], a[2][3] = {{0.0}}, r[3];
    int fdim = g - 1;
    *distance = closest_point(kind, g, nn, X, x, q, y, r, nu, a, d2N);
    if (!(*distance <= radius)) return 0;
    double nr = 0.0;
    for (int k = 0; k < g; k++) nr += nu[k] * r[k];
    *gap = -nr;
    /* the curvature terms (x - y) . d2y/dxi_a dxi_b of a quadratic facet */
    double curv[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
    if (kind >= 3)
        for (int al = 0; al < fdim; al++)
            for (int be = 0; be < fdim; be++) {
                double c[3];
                combine(g, nn, d2N[al][be], X, c);
                curv[al][be] = sum_prod(g, r, c);
            }
    if (fdim == 1) {
        double A11 = a[0][0] * a[0][0] + a[0][1] * a[0][1] - curv[0][0];
        M[0] = !q->vertex && A11 != 0 ? 1.0 / A11 : 0.0;
        return 1;
    }
    double A00 = dot3(a[0], a[0]) - curv[0][0], A11 = dot3(a[1], a[1]) - curv[1][1];
    double A01 = dot3(a[0], a[1]) - curv[0][1];
    if (kind == 2) {
        double c3[3];
        for (int k = 0; k < 3; k++) c3[k] = X[k] - X[3 + k] - X[6 + k] + X[9 + k];
        A01 -= dot3(r, c3);
    }
    M[0] = M[1] = M[2] = M[3] = 0.0;
    if (q->vertex) return 1;
    if (q->edge < 0) {
        double det = A00 * A11 - A01 * A01;
        if (det != 0) {
            double inv = 1.0 / det;
            M[0] = A11 * inv;
            M[3] = A00 * inv;
            M[1] = M[2] = -A01 * inv;
        }
        return 1;
    }
    const double(*XI)[2][2] = kind == 1 || kind == 4 ? TRI_XI : QUAD_XI;
    double t0 = XI[q->edge][1][0] - XI[q->edge][0][0], t1 = XI[q->edge][1][1] - XI[q->edge][0][1];
    double tAt = t0 * (A00 * t0 + A01 * t1) + t1 * (A01 * t0 + A11 * t1);
    if (tAt != 0) {
        M[0] = t0 * t0 / tAt;
        M[1] = M[2] = t0 * t1 / tAt;
        M[3] = t1 * t1 / tAt;
    }
    return 1;
}

/* Self-contact admissibility (projection.SelfContact.admissible): the facet shares no node
 * number with the point's facet and its centre normal opposes the point's normal. */
INLINE int admissible(int g, int m, const i64 *pnodes, const double *pnormal, int mf,
                      const i64 *fnodes, const double *axis)
{
    for (int i = 0; i < m; i++)
        for (int j = 0; j < mf; j++)
            if (pnodes[i] == fnodes[j]) return 0;
    double s = 0.0;
    for (int k = 0; k < g; k++) s += pnormal[k] * axis[k];
    return s < 0.0;
}

/* Whether the exact projections of a facet kind wait until the walk is done: those of the
 * quadratic facets (several Newton iterations each), whose distance
 * bounds from their chord facets (chord_bounds) prune as the walk goes; then the facets are
 * projected by increasing lower bound, each bound by the distances found (resolve): the
 * same facets within the reach of the closest one, with far fewer projections. */
#define DEFERRED(kind) ((kind) >= 3)

/* The walk of one point: the facets met within the bound (hits, at leaf positions), the
 * smallest distance met (best), the bound (reach of the best, at most reach of the radius;
 * bound2 its square), and the exact projections made by the walks of the lane so far. */
typedef struct {
    hit_t *hits;
    i64 nh, room, projected;
    double best, bound, bound2, radius;
} walk_t;

/* The facet at leaf position j for the point x: skipped if its box or (a quadrilateral) its
 * slab is beyond the bound or (self-contact: pn, the point's facet's nodes, not NULL) it is
 * not admissible; else projected, and a hit if within the bound, which then tightens to the
 * reach of the best distance. Returns 1 if projected, 0 if not, -1 when out of memory. */
INLINE int visit(int kind, int g, int nn, const double *leaves, const i64 *perm, i64 j,
                 const double *xp, double rmax, walk_t *W, int mp, const i64 *pn,
                 const double *pnu, int mf, const i64 *fnodes, const double *axis)
{
    const double *X = leaves + j * RECORD(g, nn);
    /* the facet's box (of its hull points) before its exact projection */
    if (box_distance2(g, X + nn * g, xp) > W->bound2) return 0;
    if (kind == 2 && beyond_slab(kind, X, xp, W->bound, rmax)) return 0;
    if (pn && !admissible(g, mp, pn, pnu, mf, fnodes + perm[j] * mf, axis + perm[j] * g))
        return 0;
    pair_t q;
    double key, upper = INFINITY;
    if (DEFERRED(kind)) { /* projected when the walk is done (resolve) */
        chord_bounds(kind, X, X[RECORD(g, nn) - 1], xp, &key, &upper);
        if (key > W->bound + 1e-10 * (W->bound + rmax)) return 0;
    } else {
        project(kind, X, xp, &q);
        key = q.dist;
        if (q.dist > W->bound) return 1;
    }
    if (W->nh == W->room) {
        /* drop the hits beyond the bound, then grow */
        i64 k = 0;
        for (i64 h = 0; h < W->nh; h++)
            if (W->hits[h].key <= W->bound) W->hits[k++] = W->hits[h];
        W->nh = k;
        if (W->nh == W->room) {
            hit_t *more = realloc(W->hits, 2 * W->room * sizeof(hit_t));
            if (!more) return -1;
            W->hits = more;
            W->room *= 2;
        }
    }
    W->hits[W->nh].j = j;
    W->hits[W->nh].key = key;
    W->nh++;
    if (DEFERRED(kind)) {
        /* the bound from the upper bound of the distance (the closest facet is still
         * within it, and within the reach of any bound it gives) */
        double r = reach(upper < W->radius ? upper : W->radius, rmax);
        if (r < W->bound) {
            W->bound = r;
            W->bound2 = r * r;
        }
        return 0;
    }
    W->hits[W->nh - 1].q = q;
    if (q.dist < W->best) {
        W->best = q.dist;
        double r = reach(q.dist < W->radius ? q.dist : W->radius, rmax);
        if (r < W->bound) {
            W->bound = r;
            W->bound2 = r * r;
        }
    }
    return 1;
}

/* What a query reads and writes (bvh_query's arguments). */
typedef struct {
    const double *leaves, *x;
    const i64 *perm;
    const node_t *T;
    i64 m;
    double rmax, radius;
    int mp, mf;
    const i64 *index;
    i64 *facet;
    double *oxi, *y, *normal, *gap, *distance, *sliding;
    const i64 *pnodes, *fnodes;
    const double *pnormal, *axis;
    i64 hint; /* the leaf position of the facet of the last point concluded, -1 before */
} query_t;

/* The walk of point p in a lane (the lanes of a query walk their points by turns: one
 * lane's loads are under way while the others work): its stack of rows and leaves (codes)
 * with their squared box distances. */
typedef struct {
    walk_t W;
    i64 p, top;
    i64 stack[STACK];
    double lower[STACK];
} lane_t;

/* Start the walk of point p in lane L: its root pushed if within the bound. On quadratic
 * facets the bound starts from the upper chord bound of the facet of the last point
 * concluded (a neighbour in the points' Morton order, often of the same facet; not in a
 * self-contact search, where it may not be admissible): the closest facet is no farther, so
 * the walk prunes from its first row and keeps the same facets (those within the reach of
 * the smallest distance, which every bound is above). A small saving on quadratic facets;
 * none on flat facets, where the bound would cost an exact projection. */
INLINE void start(int kind, int g, int nn, const query_t *Q, lane_t *L, i64 p)
{
    walk_t *W = &L->W;
    L->p = p;
    L->top = 0;
    W->nh = 0;
    W->best = INFINITY;
    W->bound = reach(Q->radius, Q->rmax);
    W->bound2 = W->bound * W->bound;
    if (Q->m == 0) return;
    if (DEFERRED(kind) && Q->hint >= 0 && !Q->pnodes) {
        const double *X = Q->leaves + Q->hint * RECORD(g, nn);
        double lower, upper;
        chord_bounds(kind, X, X[RECORD(g, nn) - 1], Q->x + p * g, &lower, &upper);
        double r = reach(upper < W->radius ? upper : W->radius, Q->rmax);
        if (r < W->bound) {
            W->bound = r;
            W->bound2 = r * r;
        }
    }
    double root[WIDE];
    row_distance2(g, Q->T + Q->m, Q->x + p * g, root);
    if (!(root[0] <= W->bound2)) return;
    L->stack[0] = Q->T[Q->m].child[0];
    L->lower[0] = root[0];
    L->top = 1;
}

/* One step of the walk of lane L (its stack not empty): the nearest entry popped, and
 * either its children within the bound pushed, farthest first (their loads started), or
 * its facets visited. Returns 0, -1 when out of memory, -3 when the stack is full (a tree
 * far deeper than log4(m)). */
INLINE int step(int kind, int g, int nn, const query_t *Q, lane_t *L)
{
    walk_t *W = &L->W;
    const double *xp = Q->x + L->p * g;
    i64 top = --L->top;
    i64 code = L->stack[top];
    if (L->lower[top] > W->bound2) return 0;
    if (code >= 0) {
        const node_t *N = Q->T + code;
        double d[WIDE], ds[WIDE];
        i64 c[WIDE];
        int k = 0;
        row_distance2(g, N, xp, ds);
        for (int slot = 0; slot < WIDE; slot++) {
            if (N->child[slot] == EMPTY || ds[slot] > W->bound2) continue;
            int at = k++; /* insertion by decreasing distance */
            while (at > 0 && d[at - 1] < ds[slot]) {
                d[at] = d[at - 1];
                c[at] = c[at - 1];
                at--;
            }
            d[at] = ds[slot];
            c[at] = N->child[slot];
        }
        if (top + k > STACK) return -3;
        for (int j = 0; j < k; j++) {
            L->stack[top] = c[j];
            L->lower[top++] = d[j];
            prefetch_child(Q->T, Q->leaves, RECORD(g, nn), c[j]);
        }
        L->top = top;
        return 0;
    }
    const i64 *pn = Q->pnodes ? Q->pnodes + L->p * Q->mp : NULL;
    const double *pnu = Q->pnodes ? Q->pnormal + L->p * g : NULL;
    i64 first = (-code - 1) >> 3, end = first + ((-code - 1) & 7);
    for (i64 j = first; j < end; j++) {
        int status = visit(kind, g, nn, Q->leaves, Q->perm, j, xp, Q->rmax, W, Q->mp, pn,
                           pnu, Q->mf, Q->fnodes, Q->axis);
        if (status < 0) return -1;
        W->projected += status;
    }
    return 0;
}

/* The deferred facets of the point of lane L (its walk done; DEFERRED kinds), projected by
 * increasing lower bound while that is within the bound, which tightens to the reach of
 * the smallest distance found: the closest facet (whose lower bound is at most its
 * distance, so within every bound) is projected, and so is every facet within the reach
 * of its distance. The others are left beyond the bound (distance infinite). */
INLINE void resolve(int kind, int g, int nn, const query_t *Q, lane_t *L)
{
    walk_t *W = &L->W;
    hit_t *hits = W->hits;
    const double *xp = Q->x + L->p * g;
    for (i64 h = 1; h < W->nh; h++) { /* insertion sort by lower bound: a few facets */
        hit_t t = hits[h];
        i64 i = h;
        for (; i > 0 && hits[i - 1].key > t.key; i--) hits[i] = hits[i - 1];
        hits[i] = t;
    }
    for (i64 h = 0; h < W->nh; h++) {
        hit_t *H = hits + h;
        if (H->key > W->bound + 1e-10 * (W->bound + Q->rmax)) {
            H->q.dist = INFINITY;
            H->key = INFINITY;
            continue;
        }
        project(kind, Q->leaves + H->j * RECORD(g, nn), xp, &H->q);
        H->key = H->q.dist;
        W->projected++;
        if (H->q.dist < W->best) {
            W->best = H->q.dist;
            double r = reach(H->q.dist < W->radius ? H->q.dist : W->radius, Q->rmax);
            if (r < W->bound) {
                W->bound = r;
                W->bound2 = r * r;
            }
        }
    }
}

/* The centroid c (g) and the radius R_f (the largest distance from it) of the hull points
 * of the facet X, in the operations of projection._centroid_radius. */
INLINE double centroid_radius(int kind, int g, int nn, const double *X, double *c)
{
    double H[27];
    const double *P = hull(kind, g, X, H);
    for (int k = 0; k < g; k++) {
        double s = P[k] + P[g + k];
        for (int q = 2; q < nn; q++) s += P[q * g + k];
        c[k] = s / nn;
    }
    double r2max = 0.0;
    for (int q = 0; q < nn; q++) {
        double r2 = 0.0;
        for (int k = 0; k < g; k++) {
            double d = P[q * g + k] - c[k];
            r2 += d * d;
        }
        r2max = q == 0 || r2 > r2max ? r2 : r2max;
    }
    return sqrt(r2max);
}

/* Whether hit H of the point x is within the tie tolerance of the smallest distance dmin
 * (dmin + TIE (dmin + 2 R_f)), and then its alignment |nu . (x - y)| / |x - y| and the
 * squared distance of x from its centroid (of the hull points), as projection._tie_break. */
#define TIE 1e-10  /* projection._TIE */
#define ALIGN 1e-12 /* projection._ALIGN */
INLINE int tie_measures(int kind, int g, int nn, const query_t *Q, const hit_t *H,
                        const double *xp, double dmin, double *align, double *c2)
{
    const double *X = Q->leaves + H->j * RECORD(g, nn);
    double c[3];
    double size = centroid_radius(kind, g, nn, X, c);
    if (!(H->q.dist <= dmin + TIE * (dmin + 2.0 * size))) return 0;
    double y[3], r[3], nu[3], a[2][3], d2N[2][2][9], nr = 0.0, cc = 0.0;
    double dist = closest_point(kind, g, nn, X, xp, &H->q, y, r, nu, a, d2N);
    for (int k = 0; k < g; k++) {
        nr += nu[k] * r[k];
        c[k] = xp[k] - c[k];
        cc += c[k] * c[k];
    }
    *align = dist > 0 ? fabs(nr) / dist : 0.0;
    *c2 = cc;
    return 1;
}

/* The hit of the closest point of x among the hits within bound (at least one): of those
 * within the tie tolerance of the smallest distance, the one whose normal is the most
 * aligned with x - y, then the one of the nearer centroid, then the one of the lower facet
 * index (perm), alignments and relative squared centroid distances within ALIGN counting as
 * equal: the tie-break of projection._select and _tie_break (three passes over the few
 * tied hits: the largest alignment, the nearest centroid among the aligned, the lowest
 * index among those). */
INLINE i64 tie_break(int kind, int g, int nn, const query_t *Q, const walk_t *W,
                     const double *xp)
{
    const hit_t *hits = W->hits;
    double dmin = INFINITY, align, c2, best = -INFINITY, nearest = INFINITY;
    for (i64 h = 0; h < W->nh; h++)
        if (hits[h].q.dist <= W->bound && hits[h].q.dist < dmin) dmin = hits[h].q.dist;
    for (i64 h = 0; h < W->nh; h++)
        if (hits[h].q.dist <= W->bound &&
            tie_measures(kind, g, nn, Q, hits + h, xp, dmin, &align, &c2) && align > best)
            best = align;
    for (i64 h = 0; h < W->nh; h++)
        if (hits[h].q.dist <= W->bound &&
            tie_measures(kind, g, nn, Q, hits + h, xp, dmin, &align, &c2) &&
            align >= best - ALIGN && c2 < nearest)
            nearest = c2;
    i64 won = -1;
    for (i64 h = 0; h < W->nh; h++)
        if (hits[h].q.dist <= W->bound &&
            tie_measures(kind, g, nn, Q, hits + h, xp, dmin, &align, &c2) &&
            align >= best - ALIGN && c2 <= nearest * (1.0 + ALIGN) &&
            (won < 0 || Q->perm[hits[h].j] < Q->perm[hits[won].j]))
            won = h;
    return won;
}

/* The results of the point of lane L, its walk done: where a facet is within reach(radius),
 * its closest point (of the facet chosen by tie_break among several) at row index[p] (p if
 * index is NULL); the placeholders where that point is beyond radius, nothing else where
 * there is none. */
INLINE void conclude(int kind, int g, int nn, query_t *Q, lane_t *L)
{
    const int fdim = g - 1;
    const walk_t *W = &L->W;
    const hit_t *hits = W->hits;
    const i64 p = L->p, nh = W->nh;
    const double *xp = Q->x + p * g, bound = W->bound;
    i64 k = 0, last = 0;
    for (i64 h = 0; h < nh; h++)
        if (hits[h].q.dist <= bound) {
            last = h;
            k++;
        }
    if (k == 0) return;
    if (k > 1) last = tie_break(kind, g, nn, Q, W, xp);
    const pair_t *q = &hits[last].q;
    const double *X = Q->leaves + hits[last].j * RECORD(g, nn);
    i64 o = Q->index ? Q->index[p] : p;
    Q->hint = hits[last].j;
    double *y = Q->y + o * g, *normal = Q->normal + o * g, *M = Q->sliding + o * fdim * fdim;
    if (finish(kind, g, nn, X, xp, q, Q->radius, y, normal, Q->gap + o, Q->distance + o, M)) {
        Q->facet[o] = Q->perm[hits[last].j];
        for (int j = 0; j < fdim; j++) Q->oxi[o * fdim + j] = q->xi[j];
        return;
    }
    for (int c = 0; c < g; c++) { /* the placeholders of an unpaired point */
        y[c] = xp[c];
        normal[c] = 0.0;
    }
    Q->gap[o] = -INFINITY;
    Q->distance[o] = INFINITY;
    for (int c = 0; c < fdim * fdim; c++) M[c] = 0.0;
}

INLINE void free_lanes(lane_t *L, int lanes)
{
    for (int l = 0; l < lanes; l++) free(L[l].W.hits);
    free(L);
}

/* For each point x[p] (npts, g), on the tree of bvh_build and bvh_refit: its closest point
 * on the facets, if within radius, at row index[p] (p if index is NULL) of facet, oxi, y,
 * normal, gap, distance and sliding (a projection.Projection, its placeholders written where
 * a facet is within reach(radius) but its closest point beyond radius, untouched where none
 * is): of the facets whose exact distance is within reach() of the smallest one, the one of
 * tie_break. Self-contact (pnodes not NULL): only the admissible facets, with pnodes (npts,
 * m) the node numbers of each point's facet, pnormal (npts, g) its normal, fnodes (n, mf)
 * the facets' node numbers, axis (n, g) their centre normals. The points are walked LANES
 * at a time (surfaces; segments one at a time), a step of each by turns. Returns the number
 * of exact projections made, -1 when out of memory, -3 when the walk overflows its stack (a
 * tree far deeper than a balanced one); bvh_query -2 for an unknown facet kind. */
INLINE i64 query(int kind, int g, int nn, const double *leaves, const i64 *perm, i64 m,
                 const void *tree, double rmax, i64 npts, const double *x, double radius,
                 const i64 *index, i64 *facet, double *oxi, double *y, double *normal,
                 double *gap, double *distance, double *sliding, int mp, const i64 *pnodes,
                 const double *pnormal, int mf, const i64 *fnodes, const double *axis)
{
    query_t Q = {leaves, x, perm, rows(tree), m, rmax, radius, mp, mf, index, facet,
                 oxi, y, normal, gap, distance, sliding, pnodes, fnodes, pnormal, axis, -1};
    /* one lane for segments: their walks are short and their projections cheap, the turns
     * cost more than they save */
    const int lanes = g == 2 ? 1 : LANES;
    lane_t *L = malloc(lanes * sizeof(lane_t));
    if (!L) return -1;
    for (int l = 0; l < lanes; l++) {
        walk_t W = {malloc(64 * sizeof(hit_t)), 0, 64, 0, INFINITY, 0.0, 0.0, radius};
        L[l].W = W;
        L[l].p = -1;
        L[l].top = 0;
    }
    for (int l = 0; l < lanes; l++)
        if (!L[l].W.hits) {
            free_lanes(L, lanes);
            return -1;
        }
    i64 next = 0;
    for (int busy = 1; busy;) {
        busy = 0;
        for (int l = 0; l < lanes; l++) {
            lane_t *A = L + l;
            while (A->top == 0) { /* the lane's point done (or none yet): the next point */
                if (A->p >= 0 && DEFERRED(kind)) resolve(kind, g, nn, &Q, A);
                if (A->p >= 0) conclude(kind, g, nn, &Q, A);
                A->p = -1;
                if (next == npts) break;
                start(kind, g, nn, &Q, A, next++);
            }
            if (A->p < 0) continue;
            busy = 1;
            int status = step(kind, g, nn, &Q, A);
            if (status < 0) {
                free_lanes(L, lanes);
                return status;
            }
        }
    }
    i64 projected = 0;
    for (int l = 0; l < lanes; l++) projected += L[l].W.projected;
    free_lanes(L, lanes);
    return projected;
}

i64 bvh_query(int kind, int g, int nn, const double *leaves, const i64 *perm, i64 m,
              const void *tree, double rmax, i64 npts, const double *x, double radius,
              const i64 *index, i64 *facet, double *oxi, double *y, double *normal,
              double *gap, double *distance, double *sliding, int mp, const i64 *pnodes,
              const double *pnormal, int mf, const i64 *fnodes, const double *axis)
{
    /* one copy of the walk per facet kind, its dimensions constant */
#define QUERY(K, G, NN)                                                                     \
    query(K, G, NN, leaves, perm, m, tree, rmax, npts, x, radius, index, facet, oxi, y, \
          normal, gap, distance, sliding, mp, pnodes, pnormal, mf, fnodes, axis)
    switch (kind) {
    case 0: return QUERY(0, 2, 2);
    case 1: return QUERY(1, 3, 3);
    case 2: return QUERY(2, 3, 4);
    case 3: return QUERY(3, 2, 3);
    case 4: return QUERY(4, 3, 6);
    case 5: return QUERY(5, 3, 9);
    }
#undef QUERY
    (void)g;
    (void)nn;
    return -2;
}
