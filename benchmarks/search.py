"""Throughput of the closest-point search alone (``contact_ufl.contact.search``).

Times :func:`~contact_ufl.contact.search.closest_points` (points per second, one core:
the BLAS/OpenMP thread pools are limited to one thread) against the number of master facets,
on three wavy master surfaces:

* 2D segments on ``y = 0.05 sin(6 pi x)``, ``x`` in [0, 1];
* 3D triangles and bilinear quadrilaterals on ``z = 0.05 sin(4 pi x) sin(4 pi y)`` over the
  unit square (a structured grid with its inner vertices moved in-plane by up to 20% of a
  cell, each cell split in two triangles for the triangle surface);

with slave points on a perturbed copy of the surface: uniform over the parameter domain (and
5% beyond it), moved along the vertical by ``+-h 10^U(-2, 2)`` (h the facet size), at most
0.25 (the package's default search radius is a quarter of the surfaces' size), so that a
part of them lies within the search radius and a part beyond it. The radii run from ``h``
to infinity. Each timing is the best of several calls (one call if it takes over a second;
the pairings of the ``scenes`` sweep, of a few milliseconds each: the best of 100).

    python benchmarks/search.py --json benchmarks/results/search.json [--quick] [--largest 1e6]

``--largest`` is the largest master of the radius sweep (1e6 facets by default).

Records (``sweep``):

* ``"graded"``: 5,000 segments 0.004 long with (``large_facets = 2``) and without two
  segments 0.6 long beyond their end, points over the small ones, radii 0.004, 0.04 and
  infinity (the pathology of a single KD-tree bounded by the largest facet);
* ``"self_contact"``: the boundary of an elliptic slit of 10,000 segments searched against
  itself, radii 0.05 and infinity (``first_call_s``, ``second_call_s``: CPU);

* ``"radius"``: the slave points above, radii h to infinity: ``kind``, ``gdim``, ``facets``,
  ``points``, ``radius_over_h`` (``null``: infinite), ``paired_fraction``, ``seconds`` and
  ``cpu_seconds`` (best repeated call, wall and CPU of this process: the KD-tree of the
  unchanged master is reused), ``first_call_s`` (CPU, the KD-trees built), ``second_call_s``
  (CPU, the KD-trees reused), ``points_per_s`` and ``cpu_points_per_s``;
* ``"quadratic"``: the records of ``"radius"`` at radius h and infinity for quadratic
  facets (3-node segments, 6-node triangles and 9-node quadrilaterals with their midpoint
  nodes on the surface), 1e3 to 1e5 facets (``search_quadratic.json``);
* ``"distance"`` (the largest master of each kind): all points at ``offset_over_h`` (0.1 to
  50) from the surface, radii 2 and 10 times that offset and infinity (all points paired):
  the cost against the points' distance and the radius;
* ``"stages"``: CPU seconds of what any search built on the KD-tree of centroids and these
  kernels pays per call: the per-facet data (``master_s``), one nearest-centroid query per
  point (``query_k1_s``; ``query_kK_s`` with the search's K), one exact projection per point
  (``one_projection_s``), and ``floor_points_per_s`` = points / (master + k=1 query + one
  projection).

Results on this machine (shared by several engineers: the wall times ran at 2 to 3 times the
CPU times, so the CPU figures are the per-core throughput): ``search_baseline.json`` (before
the first rewrite), ``search.json`` (now; same closest points, ``tests/test_search_exact.py``).
The first rewrite (one K-nearest query, ball queries only where more centroids are in reach,
kernels on coordinate columns; wall points/s at radius h / infinity, baseline -> rewrite): 1e4
segments 1.0e6 -> 1.6e6 / 4.3e5 -> 5.5e5; 1e5 segments 4.8e5 -> 9.7e5 / 2.5e5 -> 3.7e5; 1e4
triangles 2.4e5 -> 4.7e5 / 3.5e4 -> 7.5e4; 1e5 triangles 8.9e4 -> 2.7e5 / 9.3e3 -> 2.8e4; 1e4
quadrilaterals 1.9e5 -> 4.6e5 / 3.7e4 -> 8.0e4; 1e5 quadrilaterals 9.3e4 -> 2.7e5 / 1.3e4 ->
4.2e4 (the README has the table).
This round, CPU points/s at radius h / infinity, the code before it (run just before with this
script) -> now: 1e3 segments 1.5e6 -> 1.7e6 / 5.7e5 -> 6.1e5; 1e5
segments 7.4e5 -> 8.8e5 / 3.1e5 -> 3.9e5; 1e3 triangles 4.3e5 -> 4.9e5 / 1.1e5 -> 1.4e5; 1e4
triangles 4.0e5 -> 4.1e5 / 7.2e4 -> 7.2e4; 1e5 triangles 2.6e5 -> 3.0e5 / 2.7e4 -> 3.6e4; 1e4
quadrilaterals 4.2e5 -> 3.7e5 / 7.4e4 -> 7.8e4; 1e5 quadrilaterals 2.4e5 -> 2.7e5 / 4.0e4 ->
4.8e4 (per-facet data from contiguous columns: half the time; points ordered by grid cells
on a master of over 2^14 facets; blocks of 4096 points).

Third round (README): KD-trees by facet size class (graded masters 14 to 18 times faster),
self-contact by normal bins (10 times faster on the 10,000-segment slit), the linearisation
from coordinate columns. A uniform cell grid before the KD-trees was measured
(``search_grid.json``, run with the ``--grid`` option of commit 3b6744e: up to 1.3 times
faster at radius h in 3D, its build 5 to 10 searches on 1e6 facets) and not kept.
``search_before_grid.json`` holds the code before that round run with this script.

Fourth round (issue 12 item 4, the compiled search; README): the flat facet kinds are
searched by ``search_kernel.c`` (a bounding-volume hierarchy over the facets, refitted per
search, walked by branch and bound per point: the boxes farther than the best exact distance
met are skipped, so the work follows the point's distance to the surface, not the radius;
exact projections in C; the closest point of a point with one facet in reach in C, the
tie-break in NumPy). ``search_numpy.json``: the NumPy search of the third round
(``CONTACT_UFL_SEARCH=numpy``), run with this script just before ``search.json`` (now), up to
1e6 facets. The ``stages`` records are those of the NumPy search (its KD-tree of centroids
and kernels), kept for comparison: the compiled search does not use them. The third round's
``search.json`` (CPU points/s at radius h / infinity): 1e4 segments 1.5e6 / 5.5e5; 1e5
segments 8.1e5 / 3.6e5; 1e4 triangles 3.8e5 / 6.1e4; 1e5 triangles 2.6e5 / 3.3e4; 1e4
quadrilaterals 3.0e5 / 6.8e4; 1e5 quadrilaterals 2.6e5 / 4.3e4 (graded master 0.034 s,
self-contact slit 0.11 / 0.25 s).

Fifth round (issue 12 item 4; README): the compiled walk reads rows of four children with
single-precision boxes rounded outwards (one row per two levels of the binary tree),
prefetches what it pushes, skips the quadrilaterals beyond the bound by their slab along the
centre normal, and is built with ``-O3``; the unchanged-master check is one sequential
comparison, the refit one prefetched pass, the points' Z-order a radix sort in C.
``search.json`` (now) against the fourth round's code run with this script just before it
(CPU points/s at radius h / infinity, before -> now): 1e4 segments 3.1e6 -> 5.6e6 / 1.9e6 ->
2.4e6; 1e6 segments 1.3e6 -> 2.0e6 / 8.7e5 -> 1.3e6; 1e4 triangles 1.1e6 -> 1.8e6 / 2.2e5 ->
2.9e5; 1e5 triangles 9.4e5 -> 1.4e6 / 1.6e5 -> 2.1e5; 1e6 triangles 6.1e5 -> 9.6e5 / 1.2e5 ->
1.8e5; 1e4 quadrilaterals 1.1e6 -> 1.6e6 / 2.1e5 -> 3.0e5; 1e5 quadrilaterals 9.4e5 -> 1.3e6 /
1.4e5 -> 2.1e5; 1e6 quadrilaterals 6.2e5 -> 8.7e5 / 1.1e5 -> 1.8e5 (self-contact slit, second
call: 0.021 / 0.026 -> 0.011 / 0.016 s, its bins' trees now kept). The fourth round's own
``search.json`` is in the history (commit c78de93).

Sixth round (the compiled search per point, 3D): a profile (``perf``) of 1e4 triangles at
radius h had 12% of the time in page faults of the query's pair arrays (rows for every point,
written for the tied points only: spread over all pages) and 17% in the row distances (not
vectorised by the compiler); at 1e6 facets the walk waits on memory. Now: the tied points'
pairs go to the first rows (no fault beyond them), the row distances take two children at a
time (SSE2/NEON vectors, the same operations), four points are walked by turns on a surface
(a step of each: the loads one walk prefetched arrive while the others work; segments one
at a time: 25% slower at 100 h by turns), the Newton step's residual is reused. Counted per
point on 1e6 facets (radius h / 10 h / infinity): 2.1 / 8.0 / 51 exact projections on
triangles, 1.2 / 4.0 / 21 on quadrilaterals (3.8 Newton iterations a projection). Measured
and not kept: a warm start on the last point's closest facet (tried for 1% / 45% / 100% of
the points, closest for 0 to 3%: slower at 10 h and infinity, 1.33e5 -> 1.18e5 on 1e6
triangles) and the slab test for triangles (no gain). CPU points/s, best of two runs of
``--sweeps radius`` before -> after (the machine shared with other jobs: +-10% noise),
radius h: 1e4 triangles 1.29e6 -> 1.59e6, 1e5 1.25e6 -> 1.38e6, 1e6 8.7e5 -> 1.03e6; 1e4
quadrilaterals 1.30e6 -> 1.53e6, 1e5 1.07e6 -> 1.22e6, 1e6 7.9e5 -> 9.4e5; radius 10 h on 1e6:
triangles 4.8e5 -> 5.0e5, quadrilaterals 4.4e5 -> 4.7e5; 100 h and infinity unchanged within
the noise. ``--sweeps points`` (1e6 facets, radius h), per-point rate of the fit: triangles
9.8e5 -> 1.21e6 (unchanged master) / 8.6e5 -> 1.14e6 (moved), quadrilaterals 7.6e5 -> 8.9e5 /
8.3e5 -> 8.0e5 (one run each). ``search.json`` was then re-run on the quiet machine
(load below 1): radius h, 1e5 triangles 1.43e6, quadrilaterals 1.24e6; 1e6 triangles
9.9e5, quadrilaterals 8.4e5; the points sweep's per-point rate on 1e6 facets (unchanged /
moved master): triangles 1.14e6 / 1.26e6, quadrilaterals 9.9e5 / 8.7e5 (self-contact and
graded master: the same as before, checked side by side).

The distance sweep of the third round showed where the time went: at a given distance the
cost is flat in the radius (within the timing noise, e.g. 1e5 triangles at 1 h: 1.2e5
points/s at radii 2 h, 10 h and infinity), but it falls with the distance (1e5 triangles:
2.5e5 at 0.1 h, 1.2e5 at 1 h, 2.8e4 at 10 h, 7.7e3 at 50 h; segments 7.2e5 to 2.3e5): a
point at distance D has all the facets with a centroid within D + R_max as candidates (about
D R_max / h^2 on a surface). The stages bound any such search from above: on 1e5 triangles
one unbounded nearest-centroid query per point of the radius sweep's points costs 6
microseconds (the KD-tree visits many cells for points off the surface), so the floor is
1.5e5 points/s at infinite radius (6.3e5 on 1e4 triangles, 1.7e6 on 1e3); one exact
projection per point is 0.2 (triangles) to 1.5 (quadrilaterals) microseconds. 1e6 points/s
per core in 3D is therefore out of reach of a KD-tree of centroids driven from NumPy; it
needs a compiled traversal (a bounding-volume tree with the slab bounds, walked per point):
the fourth round.

The scenes sweep (session 19) times the pairing alone, 100 calls (before: the best of five,
timed with the displacement's move); ``search_scenes_before_c_tie_break.json`` is the code
before the tie-break moved into C and the glue went (README), run with this script.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402

import numpy as np  # noqa: E402
import resultfile  # noqa: E402

from contact_ufl.contact.search import (  # noqa: E402
    SelfContact,
    TreeCache,
    closest_points,
    numpy_search,
)
from contact_ufl.contact.search.numpy_facets import MasterFacets  # noqa: E402

AMPLITUDE = 0.05


def surface_2d(x: np.ndarray) -> np.ndarray:
    """Height of the 2D master curve."""
    return AMPLITUDE * np.sin(6 * np.pi * x)


def surface_3d(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Height of the 3D master surface."""
    return AMPLITUDE * np.sin(4 * np.pi * x) * np.sin(4 * np.pi * y)


def segments(nf: int) -> tuple[np.ndarray, float]:
    """``nf`` segments on the 2D curve, and their size."""
    x = np.linspace(0.0, 1.0, nf + 1)
    v = np.stack([x, surface_2d(x)], axis=1)
    return np.stack([v[:-1], v[1:]], axis=1), 1.0 / nf


def grid_3d(m: int, rng: np.random.Generator) -> np.ndarray:
    """Vertices (m + 1, m + 1, 3) of a perturbed structured grid on the 3D surface."""
    s = np.linspace(0.0, 1.0, m + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    jitter = rng.uniform(-0.2, 0.2, size=(2, m - 1, m - 1)) / m
    X[1:-1, 1:-1] += jitter[0]
    Y[1:-1, 1:-1] += jitter[1]
    return np.stack([X, Y, surface_3d(X, Y)], axis=-1)


def quadrilaterals(nf: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """About ``nf`` bilinear quadrilaterals (basix vertex order), and their size."""
    m = max(int(round(np.sqrt(nf))), 2)
    V = grid_3d(m, rng)
    quads = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:], V[1:, 1:]], axis=2)
    return quads.reshape(-1, 4, 3), 1.0 / m


def triangles(nf: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """About ``nf`` triangles (each grid cell split in two), and their size."""
    m = max(int(round(np.sqrt(nf / 2))), 2)
    V = grid_3d(m, rng)
    lower = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:]], axis=2)
    upper = np.stack([V[1:, :-1], V[1:, 1:], V[:-1, 1:]], axis=2)
    return np.concatenate([lower.reshape(-1, 3, 3), upper.reshape(-1, 3, 3)]), 1.0 / m


def slave_points(gdim: int, npts: int, h: float, rng: np.random.Generator) -> np.ndarray:
    """Points on a perturbed copy of the master surface (see the module docstring)."""
    offset = np.minimum(h * 10.0 ** rng.uniform(-2.0, 2.0, size=npts), 0.25)
    offset *= rng.choice([-1.0, 1.0], size=npts)
    u = rng.uniform(-0.05, 1.05, size=(npts, gdim - 1))
    if gdim == 2:
        return np.stack([u[:, 0], surface_2d(u[:, 0]) + offset], axis=1)
    return np.stack([u[:, 0], u[:, 1], surface_3d(u[:, 0], u[:, 1]) + offset], axis=1)


def best_of(call: Callable[[], object]) -> tuple[float, float, object]:
    """Best wall and CPU (this process) times over a few calls of ``call``, and its result.

    One call if it takes over a second, three if over 0.2 s, else five."""
    wall, cpu, calls, result = np.inf, np.inf, 0, None
    while calls < 5:
        start, start_cpu = time.perf_counter(), time.process_time()
        result = call()
        wall = min(wall, time.perf_counter() - start)
        cpu = min(cpu, time.process_time() - start_cpu)
        calls += 1
        if wall > 1.0 or (calls >= 3 and wall > 0.2):
            break
    return wall, cpu, result


def time_call(points: np.ndarray, nodes: np.ndarray, radius: float) -> dict:
    """CPU times of a first call of ``closest_points`` (no KD-tree kept from an earlier call)
    and of a second one (the KD-trees reused), the best wall and CPU times over a few more
    calls (the trees of the unchanged master reused), and the fraction of points paired."""
    options = {"trees": TreeCache()}
    start = time.process_time()
    closest_points(points, nodes, radius, **options)
    first = time.process_time() - start
    start = time.process_time()
    closest_points(points, nodes, radius, **options)
    second = time.process_time() - start
    wall, cpu, proj = best_of(lambda: closest_points(points, nodes, radius, **options))
    npts = len(points)
    return {
        "paired_fraction": float(np.mean(proj.facet >= 0)),
        "seconds": wall,
        "cpu_seconds": cpu,
        "first_call_s": first,
        "second_call_s": second,
        "points_per_s": npts / wall,
        "cpu_points_per_s": npts / cpu,
    }


def stages(points: np.ndarray, nodes: np.ndarray) -> dict:
    """CPU seconds of the parts of a search that any candidate pruning pays: the per-facet data
    of the master (KD-tree reused), one K-nearest query of the centroids per point (K = 1
    and the search's K), and one exact projection per point (on the facet of its nearest
    centroid)."""
    trees = TreeCache()
    master = MasterFacets(nodes, trees)
    # the KD-tree of all the centroids (one level on these even meshes)
    tree = master.levels[0].tree if hasattr(master, "levels") else master.tree
    K = min(numpy_search._K[nodes.shape[2]], len(nodes))
    _, master_s, _ = best_of(lambda: MasterFacets(nodes, trees))
    _, k1_s, (_, nearest) = best_of(lambda: tree.query(points, k=1))
    _, kK_s, _ = best_of(lambda: tree.query(points, k=K))
    n = len(points)
    _, project_s, _ = best_of(lambda: master.project(points, nearest, np.arange(n), n))
    return {
        "master_s": master_s,
        "query_k1_s": k1_s,
        "query_kK_s": kK_s,
        "K": K,
        "one_projection_s": project_s,
        "floor_points_per_s": n / (master_s + k1_s + project_s),
    }


def offset_points(gdim: int, npts: int, offset: float, rng: np.random.Generator) -> np.ndarray:
    """Points over the parameter domain at the vertical distance ``+-offset`` from the
    master surface."""
    u = rng.uniform(0.0, 1.0, size=(npts, gdim - 1))
    dz = offset * rng.choice([-1.0, 1.0], size=npts)
    if gdim == 2:
        return np.stack([u[:, 0], surface_2d(u[:, 0]) + dz], axis=1)
    return np.stack([u[:, 0], u[:, 1], surface_3d(u[:, 0], u[:, 1]) + dz], axis=1)


SWEEPS = ("graded", "self_contact", "radius", "distance", "points", "quadratic", "scenes")

MAKERS = {
    "segment": lambda nf, rng: segments(nf),
    "triangle": triangles,
    "quadrilateral": quadrilaterals,
}


def quadratic_segments(nf: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """``nf`` 3-node segments on the 2D curve (ends, then the midpoint node on the curve)."""
    seg, h = segments(nf)
    mid = 0.5 * (seg[:, 0] + seg[:, 1])
    mid[:, 1] = surface_2d(mid[:, 0])
    return np.concatenate([seg, mid[:, None]], axis=1), h


def quadratic_triangles(nf: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """About ``nf`` 6-node triangles (vertices, then the midpoint nodes of the edges 01, 12,
    02 lifted onto the surface: curved facets)."""
    tri, h = triangles(nf, rng)
    mid = np.stack([0.5 * (tri[:, a] + tri[:, b]) for a, b in ((0, 1), (1, 2), (0, 2))], axis=1)
    mid[..., 2] = surface_3d(mid[..., 0], mid[..., 1])
    return np.concatenate([tri, mid], axis=1), h


def quadratic_quadrilaterals(nf: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """About ``nf`` 9-node quadrilaterals (basix vertices, the midpoint nodes of the edges 01,
    13, 23, 02, then the centre node, lifted onto the surface from the means of their edge's
    or cell's vertices: curved facets), and their size."""
    quads, h = quadrilaterals(nf, rng)
    edges = ((0, 1), (1, 3), (2, 3), (0, 2))
    mid = [0.5 * (quads[:, a] + quads[:, b]) for a, b in edges] + [quads.mean(axis=1)]
    mid = np.stack(mid, axis=1)
    mid[..., 2] = surface_3d(mid[..., 0], mid[..., 1])
    return np.concatenate([quads, mid], axis=1), h


QUADRATIC_MAKERS = {
    "segment3": quadratic_segments,
    "triangle6": quadratic_triangles,
    "quadrilateral9": quadratic_quadrilaterals,
}


def radius_sweep(sizes, npts, factors, makers=MAKERS, sweep: str = "radius") -> list[dict]:
    """The records of the radius sweep (the slave points of :func:`slave_points`) over the
    facet kinds of ``makers``, named ``sweep``; the flat kinds' (``"radius"``) with the
    stages of the NumPy search."""
    records = []
    print(
        f"{'facets':>8} {'kind':>13} {'radius/h':>8} {'paired':>7} {'cpu s':>8} {'points/s':>10}"
        f" {'first s':>8}"
    )
    for kind, make in makers.items():
        for nf in sizes:
            rng = np.random.default_rng(nf)
            nodes, h = make(nf, rng)
            points = slave_points(nodes.shape[2], npts, h, rng)
            for factor in factors:
                record = {
                    "sweep": sweep,
                    "kind": kind,
                    "gdim": int(nodes.shape[2]),
                    "facets": int(nodes.shape[0]),
                    "points": npts,
                    "radius_over_h": None if np.isinf(factor) else factor,
                    **time_call(points, nodes, factor * h),
                }
                records.append(record)
                print(
                    f"{record['facets']:8d} {kind:>13} {factor:8.0f} "
                    f"{record['paired_fraction']:7.2f} {record['cpu_seconds']:8.4f} "
                    f"{record['cpu_points_per_s']:10.3g} {record['first_call_s']:8.4f}",
                    flush=True,
                )
            if sweep != "radius":
                continue
            record = {
                "sweep": "stages",
                "kind": kind,
                "gdim": int(nodes.shape[2]),
                "facets": int(nodes.shape[0]),
                "points": npts,
                **stages(points, nodes),
            }
            records.append(record)
            print(
                f"{record['facets']:8d} {kind:>13} stages: master {record['master_s']:.4f} "
                f"k=1 {record['query_k1_s']:.4f} k={record['K']} {record['query_kK_s']:.4f} "
                f"one projection {record['one_projection_s']:.4f} -> floor "
                f"{record['floor_points_per_s']:.3g} points/s",
                flush=True,
            )
    return records


def distance_sweep(nf: int, npts: int, offsets, factors) -> list[dict]:
    """The records of the distance sweep: all points at ``offset h`` from the surface, radii
    ``factor offset h`` (all points within them) and infinity."""
    records = []
    for kind, make in MAKERS.items():
        rng = np.random.default_rng(nf)
        nodes, h = make(nf, rng)
        for offset in offsets:
            points = offset_points(nodes.shape[2], npts, offset * h, rng)
            for factor in factors:
                radius = factor * offset * h
                record = {
                    "sweep": "distance",
                    "kind": kind,
                    "gdim": int(nodes.shape[2]),
                    "facets": int(nodes.shape[0]),
                    "points": npts,
                    "offset_over_h": offset,
                    "radius_over_h": None if np.isinf(radius) else radius / h,
                    **time_call(points, nodes, radius),
                }
                records.append(record)
                print(
                    f"{record['facets']:8d} {kind:>13} offset {offset:6.1f} h radius "
                    f"{radius / h:8.1f} h paired {record['paired_fraction']:5.2f} "
                    f"{record['cpu_points_per_s']:10.3g} points/s",
                    flush=True,
                )
    return records


def graded_master(big: bool) -> np.ndarray:
    """5,000 segments 0.004 long on ``y = 0.01 sin x``, ``x`` in [0, 20], and (``big``) two
    segments 0.6 long beyond its end."""
    x = np.linspace(0.0, 20.0, 5001)
    v = np.stack([x, 0.01 * np.sin(x)], axis=1)
    nodes = np.stack([v[:-1], v[1:]], axis=1)
    if big:
        end = v[-1]
        large = np.array([[end, end + [0.6, 0.0]], [end + [0.6, 0.0], end + [1.2, 0.0]]])
        nodes = np.concatenate([nodes, large])
    return nodes


def graded_sweep(npts: int) -> list[dict]:
    """The graded master with and without its two large facets: points over the small ones
    at ``0.004 10^U(-2, 1)`` from them, radii 0.004, 0.04 and infinity."""
    rng = np.random.default_rng(0)
    u = rng.uniform(0.0, 20.0, npts)
    offset = rng.choice([-1.0, 1.0], npts) * 0.004 * 10.0 ** rng.uniform(-2.0, 1.0, npts)
    points = np.stack([u, 0.01 * np.sin(u) + offset], axis=1)
    records = []
    for radius in (0.004, 0.04, np.inf):
        for big in (False, True):
            nodes = graded_master(big)
            record = {
                "sweep": "graded",
                "large_facets": 2 if big else 0,
                "facets": len(nodes),
                "points": npts,
                "radius": None if np.isinf(radius) else radius,
                **time_call(points, nodes, radius),
            }
            records.append(record)
            print(
                f"graded master, {record['large_facets']} large facets, radius {radius:6g}: "
                f"first call {record['first_call_s']:.3f} s, best {record['cpu_seconds']:.3f} s "
                f"CPU ({npts} points)",
                flush=True,
            )
    return records


def self_contact_sweep(n: int) -> list[dict]:
    """Self-contact of the boundary of an elliptic slit (half-axes 1 and 0.06) of ``n``
    segments, the slave points at their centres (as ``tests/test_self_contact.py``)."""
    t = -np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    ring = np.stack([np.cos(t), 0.06 * np.sin(t)], axis=1)
    facet_nodes = np.stack([np.arange(n), (np.arange(n) + 1) % n], axis=1)
    nodes = ring[facet_nodes]
    points = nodes.mean(axis=1)
    a1 = nodes[:, 1] - nodes[:, 0]
    normals = np.stack([a1[:, 1], -a1[:, 0]], axis=1)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    rule = SelfContact(facet_nodes, facet_nodes, normals)
    records = []
    for radius in (0.05, np.inf):
        trees = TreeCache()
        start = time.process_time()
        closest_points(points, nodes, radius, trees, rule)
        first = time.process_time() - start
        start = time.process_time()
        proj = closest_points(points, nodes, radius, trees, rule)
        second = time.process_time() - start
        record = {
            "sweep": "self_contact",
            "facets": n,
            "points": n,
            "radius": None if np.isinf(radius) else radius,
            "paired_fraction": float(np.mean(proj.facet >= 0)),
            "first_call_s": first,
            "second_call_s": second,
        }
        records.append(record)
        print(
            f"self-contact, {n} segments, radius {radius}: first call {first:.3f} s, second "
            f"{second:.3f} s CPU",
            flush=True,
        )
    return records


def _searcher(points, masters: list, radius: float, trees, moved: bool) -> Callable:
    """A search of ``points`` on ``masters[0]``; each call first swaps the two masters if
    ``moved`` (so that every call meets a moved master: ``masters[0]`` must be the master of
    the last search before the first call; with the other first, the first call met an
    unchanged master and, the fastest of all, was what the sweep kept)."""

    def call():
        if moved:
            masters.reverse()
        return closest_points(points, masters[0], radius, trees=trees)

    return call


def points_sweep(nf: int, counts) -> list[dict]:
    """Search time against the number of points on the largest master, radius h, with the
    master unchanged between calls (the other sweeps) and moved at every call (as in a
    Newton iteration: each call refits the tree), and the line ``seconds = per_call_s +
    points / per_point_rate`` fitted to them: a per-call cost that follows the facets (the
    unchanged check, or the refit) and a per-point one."""
    records = []
    print(f"{'facets':>8} {'kind':>13} {'master':>9} {'points':>8} {'cpu s':>8} {'points/s':>10}")
    for kind, make in MAKERS.items():
        rng = np.random.default_rng(nf)
        nodes, h = make(nf, rng)
        # a translation by 1e-9 h: a moved master (refitted), the same tree and closest facets
        shifted = np.ascontiguousarray(nodes + 1e-9 * h)
        for moved in (False, True):
            times = []
            for n in counts:
                points = slave_points(nodes.shape[2], n, h, rng)
                trees = TreeCache()
                closest_points(points, nodes, h, trees=trees)
                _, cpu, _ = best_of(_searcher(points, [nodes, shifted], h, trees, moved))
                times.append(cpu)
                records.append(
                    {
                        "sweep": "points",
                        "kind": kind,
                        "gdim": int(nodes.shape[2]),
                        "facets": int(nodes.shape[0]),
                        "master": "moved" if moved else "unchanged",
                        "points": int(n),
                        "radius_over_h": 1.0,
                        "cpu_seconds": cpu,
                        "cpu_points_per_s": n / cpu,
                    }
                )
                print(
                    f"{nodes.shape[0]:8d} {kind:>13} {records[-1]['master']:>9} {n:8d} "
                    f"{cpu:8.4f} {n / cpu:10.3g}",
                    flush=True,
                )
            slope, per_call = np.polyfit(np.asarray(counts, float), times, 1)
            records.append(
                {
                    "sweep": "points_fit",
                    "kind": kind,
                    "facets": int(nodes.shape[0]),
                    "master": "moved" if moved else "unchanged",
                    "per_call_s": float(per_call),
                    "per_point_rate": float(1.0 / slope),
                }
            )
            print(
                f"{'':8} {kind:>13} {records[-1]['master']:>9} per call {per_call * 1e3:.1f} ms, "
                f"per point {1.0 / slope:.3g} points/s",
                flush=True,
            )
    return records


#: the scenes of the ``"scenes"`` sweep: the scene maker, its keywords, displacement degree
SCENES = [
    ("hertz_2d", {"h_contact": 0.005}, 1),
    ("hertz_2d", {"h_contact": 0.00125}, 1),
    ("hertz_3d", {"h_contact": 0.0125}, 1),
    ("hertz_3d", {"h_contact": 0.00625}, 1),
    ("hertz_3d", {"h_contact": 0.0045}, 1),
    ("hertz_3d", {"h_contact": 0.05, "order": 2}, 2),
    ("hertz_3d", {"h_contact": 0.025, "h_edge": 0.01, "order": 2}, 2),
]


#: calls of a scene's pairing, timed alone (each after a move of the displacement, which is
#: not timed: before, the best of five calls timed with the move, 0.3 ms of a 115k scene's
#: call and 1 ms of the 340k one's, and at the mercy of the machine's noise)
SCENE_CALLS = 100


def _moved_pairing(search, u, layout, x: np.ndarray, rng, times: list) -> Callable:
    """A pairing of ``search`` after moving the displacement ``u`` to ``x`` plus up to 1e-6
    (a moved master), its wall and CPU seconds (of the pairing alone, not of the move)
    appended to ``times``."""

    def call():
        u.x.array[:] = x + 1e-6 * rng.random(len(x))
        start, start_cpu = time.perf_counter(), time.process_time()
        pairing = search.pair(u, layout)
        times.append((time.perf_counter() - start, time.process_time() - start_cpu))
        return pairing

    return call


def scene_sweep(quick: bool) -> list[dict]:
    """The whole search of a contact pair as a Newton iteration calls it
    (:meth:`~contact_ufl.contact.search.ClosestPointSearch.pair`: slave points, candidate
    exchange and order, closest points, release at the master's boundary, gathered nodes and
    columns) on the verification scenes, each call after a small displacement of both
    bodies (a moved master: the tree refitted), against the part of it in
    :func:`closest_points` (the kernel the other sweeps time). Records: the CPU seconds of
    the fastest of ``SCENE_CALLS`` calls and of their median (``cpu_seconds``,
    ``cpu_median_seconds``), points/s of each, the kernel's share of them all."""
    from contact_ufl.contact.search import pairing as search_module
    from contact_ufl.problem import ContactProblem
    from contact_ufl.verification import scenes

    records = []
    print(f"{'scene':>9} {'p':>2} {'dofs':>7} {'points':>7} {'facets':>7} {'ms/call':>8} "
          f"{'points/s':>9} {'median':>8} {'points/s':>9} {'kernel':>7}")  # fmt: skip
    kernel = [0.0]

    def timed(*args, **kwargs):
        start = time.process_time()
        out = closest_points(*args, **kwargs)
        kernel[0] += time.process_time() - start
        return out

    search_module.closest_points = timed
    try:
        rng = np.random.default_rng(0)
        for name, options, degree in SCENES[:3] if quick else SCENES:
            problem = ContactProblem(getattr(scenes, name)(**options).scene, degree=degree,
                                     verbose=False)  # fmt: skip
            contact = problem.contacts[0]
            search, layout, u = contact.kinematics.search, problem.full_layout, contact.u
            x = u.x.array.copy()
            search.pair(u, layout)

            times: list[tuple[float, float]] = []
            kernel[0] = 0.0
            call = _moved_pairing(search, u, layout, x, rng, times)
            for _ in range(SCENE_CALLS):
                pairing = call()
            wall, cpu = np.min(times, axis=0)
            median = float(np.median([t[1] for t in times]))
            npts = len(pairing.points)
            record = {
                "sweep": "scenes",
                "scene": name,
                **options,
                "degree": degree,
                "dofs": problem.layout.global_size,
                "points": npts,
                "master_facets": int(len(search.master.keys)),
                "paired": int(np.count_nonzero(pairing.paired)),
                "seconds": float(wall),
                "cpu_seconds": float(cpu),
                "cpu_points_per_s": npts / cpu,
                "cpu_median_seconds": median,
                "cpu_median_points_per_s": npts / median,
                "kernel_fraction": kernel[0] / sum(t[1] for t in times),
            }
            records.append(record)
            print(
                f"{name:>9} {degree:2d} {record['dofs']:7d} {npts:7d} {record['master_facets']:7d} "
                f"{cpu * 1e3:8.2f} {npts / cpu:9.3g} {median * 1e3:8.2f} {npts / median:9.3g} "
                f"{record['kernel_fraction']:7.2f}",
                flush=True,
            )
    finally:  # the kernel restored however the sweep ends
        search_module.closest_points = closest_points
    return records


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--quick", action="store_true", help="fewer facets and points")
    parser.add_argument(
        "--largest", type=float, default=1e6, help="largest number of facets (full run)"
    )
    parser.add_argument(
        "--sweeps", nargs="+", default=list(SWEEPS), choices=list(SWEEPS), help="which sweeps"
    )
    args = parser.parse_args()
    sizes = [1_000, 10_000] if args.quick else [1_000, 10_000, 100_000]
    if not args.quick and args.largest > 100_000:
        sizes.append(int(args.largest))
    npts = 10_000 if args.quick else 50_000
    factors = (1.0, 10.0, np.inf) if args.quick else (1.0, 10.0, 100.0, np.inf)
    largest = sizes[-1]
    counts = [npts // 5, npts, 4 * npts, 20 * npts] if largest >= 1e6 else [npts // 5, npts]
    run = {
        "graded": lambda: graded_sweep(npts // 2),
        "self_contact": lambda: self_contact_sweep(2_000 if args.quick else 10_000),
        "radius": lambda: radius_sweep(sizes, npts, factors),
        "distance": lambda: distance_sweep(
            100_000 if not args.quick else 10_000, npts, (0.1, 1.0, 10.0, 50.0), (2.0, 10.0, np.inf)
        ),
        "points": lambda: points_sweep(largest, counts),
        "scenes": lambda: scene_sweep(args.quick),
        "quadratic": lambda: radius_sweep(
            sizes[:3], npts, (1.0, np.inf), QUADRATIC_MAKERS, "quadratic"
        ),
    }
    records = [r for name in args.sweeps for r in run[name]()]
    resultfile.write(args.json, {"quick": args.quick, "records": records}, ranks=1)


if __name__ == "__main__":
    main()
