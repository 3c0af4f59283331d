"""The compiled closest-point search (``search_kernel.c``): the same closest points as the
NumPy search, work that does not grow with the search radius, and its build cache."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numpy as np
import pytest
from mpi4py import MPI
from test_projection import segment_polyline, triangle_soup, warped_quads, wavy_quads
from test_quadratic import random_quadrilaterals, random_segments, random_triangles
from test_search_exact import near_and_far

from contact_ufl.contact.search import (
    FACET_KINDS,
    ClosestPointSearch,
    SelfContact,
    TreeCache,
    closest_points,
    compiled,
    facet_kind,
)
from contact_ufl.contact.search import closest as closest_module
from contact_ufl.contact.search.curved import bernstein_hull
from contact_ufl.contact.search.hierarchy import Hierarchy
from contact_ufl.contact.search.kinds import QUADRATIC
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes

FIELDS = ("xi", "y", "normal", "gap", "distance", "sliding")
#: the reference of the records: the package's other implementation of the same search
NUMPY_SEARCH = "this code's NumPy search (backend='numpy')"
#: The bound of the flat kinds' fields (size ~1), compiled against NumPy: round-off (measured
#: equal but for 1.1e-16 in the gap); the margin allows another compiler's order of sums.
FLAT = 1e-14
#: The quadratic kinds' bounds: ``xi``, ``y``, the normal, the gap and the distance (measured
#: <= 1.2e-13, in ``xi``), and ``M`` per point relative to its largest entry (5.1e-13).
QUADRATIC_FIELDS, QUADRATIC_M = 3e-13, 1e-12
#: rank-local kernels on arrays made here: the 2-rank run would repeat them on each rank
serial = pytest.mark.serial


def _wavy_lattice(rng: np.random.Generator, m: int) -> np.ndarray:
    """The nodes (2m + 1, 2m + 1, 3) of a jittered lattice on a wavy surface: the vertices
    and midpoint nodes of an m x m grid of quadratic cells."""
    s = np.linspace(0.0, 1.0, 2 * m + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    X[1:-1, 1:-1] += rng.uniform(-0.1, 0.1, (2 * m - 1, 2 * m - 1)) / m
    Y[1:-1, 1:-1] += rng.uniform(-0.1, 0.1, (2 * m - 1, 2 * m - 1)) / m
    return np.stack([X, Y, 0.15 * np.sin(3 * X) * np.cos(4 * Y)], axis=-1)


def wavy_triangle6(rng: np.random.Generator, n: int) -> np.ndarray:
    """About ``n`` curved 6-node triangles sharing their edges (each quadratic cell of a
    wavy lattice split in two)."""
    m = max(int(round(np.sqrt(n / 2))), 1)
    return _triangle6_cells(_wavy_lattice(rng, m), m)


def _triangle6_cells(V: np.ndarray, m: int) -> np.ndarray:
    """The 6-node triangles of the lattice ``V`` (2m + 1, 2m + 1, 3), two a quadratic cell."""
    i, j = np.meshgrid(2 * np.arange(m), 2 * np.arange(m), indexing="ij")
    i, j = i.ravel(), j.ravel()
    # vertices, then the midpoints of the edges 01, 12, 02
    lower = [V[i, j], V[i + 2, j], V[i, j + 2], V[i + 1, j], V[i + 1, j + 1], V[i, j + 1]]
    upper = [V[i + 2, j], V[i + 2, j + 2], V[i, j + 2], V[i + 2, j + 1], V[i + 1, j + 2],
             V[i + 1, j + 1]]  # fmt: skip
    return np.concatenate([np.stack(lower, axis=1), np.stack(upper, axis=1)])


def wavy_quadrilateral9(rng: np.random.Generator, n: int) -> np.ndarray:
    """About ``n`` curved 9-node quadrilaterals sharing their edges (basix vertices, the
    midpoints of the edges 01, 13, 23, 02, the centre) on a wavy lattice."""
    m = max(int(round(np.sqrt(n))), 1)
    return _quadrilateral9_cells(_wavy_lattice(rng, m), m)


def _quadrilateral9_cells(V: np.ndarray, m: int) -> np.ndarray:
    """The 9-node quadrilaterals of the lattice ``V`` (2m + 1, 2m + 1, 3)."""
    i, j = np.meshgrid(2 * np.arange(m), 2 * np.arange(m), indexing="ij")
    i, j = i.ravel(), j.ravel()
    nodes = [V[i, j], V[i + 2, j], V[i, j + 2], V[i + 2, j + 2], V[i + 1, j], V[i + 2, j + 1],
             V[i + 1, j + 2], V[i, j + 1], V[i + 1, j + 1]]  # fmt: skip
    return np.stack(nodes, axis=1)


#: the surfaces of the comparisons, by their maker (a format of the number of facets)
SURFACES = {
    segment_polyline: "a random polyline of {} segments (2D)",
    triangle_soup: "{} random triangles (3D)",
    warped_quads: "{} random warped bilinear quadrilaterals",
    wavy_quads: "a randomly warped grid of {} bilinear quadrilaterals",
    random_segments: "{} random curved 3-node segments (2D)",
    random_triangles: "{} random curved 6-node triangles",
    random_quadrilaterals: "{} random curved 9-node quadrilaterals",
    wavy_triangle6: "a wavy grid of about {} 6-node triangles",
    wavy_quadrilateral9: "a wavy grid of about {} 9-node quadrilaterals",
}


@pytest.mark.parametrize(
    ("make", "nf"),
    [
        (segment_polyline, 300),
        (triangle_soup, 200),
        (warped_quads, 60),
        (wavy_quads, 400),
        (random_segments, 300),
        (random_triangles, 150),
        (random_quadrilaterals, 60),
        (wavy_triangle6, 400),
        (wavy_quadrilateral9, 200),
    ],
    ids=[
        "segments",
        "triangles",
        "quadrilaterals",
        "quad-grid",
        "segments3",
        "triangles6",
        "quadrilaterals9",
        "triangle6-grid",
        "quadrilateral9-grid",
    ],
)
@pytest.mark.parametrize("radius", [np.inf, 0.05])
@serial
def test_compiled_equals_numpy(make, nf, radius, monkeypatch, verification):
    """Consistency: the compiled search and the NumPy one (its oracle, ``backend="numpy"``)
    find the same facets and, to round-off, the same closest points.

    The flat kinds repeat the NumPy operations (equal to the last bit but for the order of
    a few sums). The quadratic kinds' Newton iterations evaluate the facet in monomial form
    (NumPy: sums over the nodes), so ``xi`` and ``M = A^-1`` agree to round-off times the
    condition of ``A = a_a . a_b - (x - y) . y_,ab``, which grows for points far on the
    concave side of a curved facet (towards its centres of curvature): ``xi`` up to 1.2e-13
    apart, ``M`` (compared relative to its size) up to 5e-13."""
    rng = np.random.default_rng(nf + 11)
    nodes = make(rng, nf)
    points = near_and_far(rng, nodes, 400)
    fast = closest_points(points, nodes, radius, backend="compiled")
    slow = closest_points(points, nodes, radius, backend="numpy")
    np.testing.assert_array_equal(fast.facet, slow.facet)
    assert 0 < np.count_nonzero(fast.facet >= 0)
    paired = fast.facet >= 0
    quadratic = facet_kind(*nodes.shape[1:]) in QUADRATIC
    fields_tol, M_tol = (QUADRATIC_FIELDS, QUADRATIC_M) if quadratic else (FLAT, FLAT)
    fields = max(
        np.abs(getattr(fast, k)[paired] - getattr(slow, k)[paired]).max() for k in FIELDS[:-1]
    )
    a, b = fast.sliding[paired], slow.sliding[paired]
    M = np.abs(a - b).max(axis=(1, 2))
    if quadratic:  # per point, relative to its size
        M = M / np.maximum(np.abs(b).max(axis=(1, 2)), 1.0)
    M = M.max()
    case = f"compiled search: {SURFACES[make].format(nf)}, radius {radius}"
    quantity = "max difference of xi, y, n, g, distance; of M"
    quantity += " relative to max(|M|, 1)" if quadratic else ""
    tolerance = f"< {fields_tol:g} (fields), < {M_tol:g} (M)"
    verification(case, quantity, [fields, M], 0.0, tolerance, NUMPY_SEARCH, kind="consistency")
    assert fields <= fields_tol and M <= M_tol


@serial
def test_points_in_any_memory_layout():
    """Points given as a Fortran-ordered or strided array (e.g. a transpose) get the closest
    points of the same points in C order (the compiled kernel reads a C-contiguous copy)."""
    rng = np.random.default_rng(3)
    nodes = triangle_soup(rng, 50)
    points = near_and_far(rng, nodes, 40)
    expected = closest_points(points, nodes, np.inf)
    for layout in (np.asfortranarray(points), np.repeat(points, 2, axis=0)[::2]):
        got = closest_points(layout, nodes, np.inf)
        np.testing.assert_array_equal(got.facet, expected.facet)
        np.testing.assert_array_equal(got.y, expected.y)


@pytest.mark.parametrize(
    ("quadratic", "per_point"), [(False, 5), (True, 2)], ids=["triangles", "triangles6"]
)
@serial
def test_work_does_not_grow_with_the_radius(quadratic, per_point):
    """On a flat grid of 20,000 triangles (of 6-node triangles: their exact projections
    deferred until the walk is done), points 0.01 to 3 facet sizes above it: the exact
    projections per point of an infinite radius are those of a radius of a few facets, and
    a few per point (the branch and bound prunes by the best distance met, not the radius;
    measured the same at every radius, 3.0 per point on triangles, 1.0 on 6-node ones)."""
    m = 100
    s = np.linspace(0.0, 1.0, m + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    V = np.stack([X, Y, np.zeros_like(X)], axis=-1)
    lower = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:]], axis=2).reshape(-1, 3, 3)
    upper = np.stack([V[1:, :-1], V[1:, 1:], V[:-1, 1:]], axis=2).reshape(-1, 3, 3)
    nodes = np.concatenate([lower, upper])
    if quadratic:  # the midpoints of the edges 01, 12, 02
        mids = [0.5 * (nodes[:, a] + nodes[:, b]) for a, b in ((0, 1), (1, 2), (0, 2))]
        nodes = np.concatenate([nodes, np.stack(mids, axis=1)], axis=1)
    rng = np.random.default_rng(5)
    h = 1.0 / m
    points = np.column_stack(
        [rng.uniform(0.1, 0.9, (2000, 2)), h * 10.0 ** rng.uniform(-2, 0.5, 2000)]
    )
    work = {}
    for radius in (5 * h, 50 * h, np.inf):
        trees = TreeCache()
        proj = closest_points(points, nodes, radius, trees)
        assert np.all(proj.facet >= 0)
        (entry,) = trees.entries.values()
        work[radius] = entry[1].projections / len(points)
    assert work[np.inf] <= 1.01 * work[5 * h]
    assert work[np.inf] < per_point


#: a row of the walk's tree (``node_t`` of ``search_kernel.c``)
_ROW = np.dtype([("lo", "<f4", (3, 4)), ("hi", "<f4", (3, 4)), ("child", "<i8", (4,))])
_EMPTY = 1 << 62


def _leaf_slots(hierarchy: Hierarchy):
    """The slots of the walk's rows that hold a leaf: their float boxes (lo, hi: (L, 3)) and
    the leaves' facets (start, count)."""
    buffer = hierarchy.tree
    offset = (-buffer.ctypes.data) % 128
    rows = buffer[offset : offset + (hierarchy.m + 1) * 128].view(_ROW)
    walked, level = [], [hierarchy.m]  # the rows reached from the root's (row m)
    while level:
        walked += level
        child = rows["child"][level]
        level = list(child[(child >= 0) & (child != _EMPTY)])
    child = rows["child"][walked]
    row, slot = np.nonzero(child < 0)
    code = -1 - child[row, slot]
    row = np.asarray(walked)[row]
    return rows["lo"][row, :, slot], rows["hi"][row, :, slot], code >> 3, code & 7


@pytest.mark.parametrize(
    "make, scale",
    [
        (segment_polyline, 1.0),
        (triangle_soup, 1.0),
        (triangle_soup, -1e-42),  # floats below the normal range
        (triangle_soup, 1e-50),  # every coordinate rounds to a signed zero
        (warped_quads, 3e37),
        (random_triangles, 1.0),
        (random_quadrilaterals, -1.0),
        (random_segments, 1e39),  # beyond the largest float: infinite bounds
    ],
)
@serial
def test_tree_boxes_are_the_tightest_floats_around_the_leaves(make, scale):
    """Every leaf's box in the walk's rows is the tightest single-precision box holding the
    double-precision boxes of its facets (of their hull points): the outward rounding moves
    a bound by one float exactly where the nearest float is on the wrong side of it."""
    rng = np.random.default_rng(11)
    nodes = np.ascontiguousarray(make(rng, 300) * scale)
    hierarchy = Hierarchy(nodes)
    hierarchy.refit(nodes)
    nf, nodes_per_facet, g = nodes.shape
    kind = facet_kind(nodes_per_facet, g)
    hull = bernstein_hull(kind, nodes) if kind in QUADRATIC else nodes
    lo_f, hi_f, start, count = _leaf_slots(hierarchy)
    order = np.argsort(start)
    lo_f, hi_f, start = lo_f[order], hi_f[order], start[order]
    assert np.array_equal(start, np.cumsum(count[order]) - count[order])  # a partition
    assert count.sum() == nf and count.min() >= 1
    for k in range(g):
        leaf_order = hull[hierarchy.perm, :, k]
        lo = np.minimum.reduceat(leaf_order.min(axis=1), start)
        hi = np.maximum.reduceat(leaf_order.max(axis=1), start)
        up, down = np.float32(np.inf), np.float32(-np.inf)
        with np.errstate(over="ignore"):  # the float after the largest is infinite
            above_lo, below_hi = np.nextafter(lo_f[:, k], up), np.nextafter(hi_f[:, k], down)
        assert np.all(lo_f[:, k] <= lo) and np.all(above_lo > lo)
        assert np.all(hi_f[:, k] >= hi) and np.all(below_hi < hi)


@serial
def test_refit_measures_the_change_and_knows_an_unchanged_master():
    """The refit returns the largest coordinate change since the last one (from its records'
    copy of the nodes); the hierarchy knows the nodes of its last refit to the last bit, and
    a tree cache keeps a hierarchy while the movements of its refits add up to less than a
    quarter of the largest facet radius, and replaces it beyond."""
    rng = np.random.default_rng(5)
    nodes = np.ascontiguousarray(triangle_soup(rng, 500))
    hierarchy = Hierarchy(nodes)
    hierarchy.refit(nodes)
    assert hierarchy.fitted(nodes)
    moved = nodes.copy()
    moved[-1, 2, 1] += 3e-3
    moved[7, 0, 0] -= 1e-3
    assert not hierarchy.fitted(moved)
    # the change of a coordinate of size ~1: round-off eps / 3e-3 ~ 7e-14 relative
    assert hierarchy.refit(moved) == pytest.approx(3e-3, rel=1e-13)
    assert hierarchy.fitted(moved) and not hierarchy.fitted(nodes)
    last_bit = moved.copy()
    last_bit[-1, -1, -1] = np.nextafter(last_bit[-1, -1, -1], np.inf)
    assert not hierarchy.fitted(last_bit)

    trees = TreeCache()
    first = trees.hierarchy(nodes)
    R = first.R_max
    assert trees.hierarchy(np.ascontiguousarray(nodes + 0.1 * R)) is first
    # back where it was built, but the movements since add up to 0.35 R (0.1 R sqrt(3) twice)
    assert trees.hierarchy(nodes) is not first


@pytest.mark.serial  # it starts Python processes of its own
def test_build_cache_and_concurrent_builds(tmp_path):
    """Two processes building the kernel at once into an empty cache directory: both load
    it, one library named by the source hash remains, no temporary file is left."""
    env = {**os.environ, "CONTACT_UFL_CACHE_DIR": str(tmp_path)}
    code = "from contact_ufl.contact.search import compiled; compiled.kernel(); print('ok')"
    runs = [
        subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, text=True)
        for _ in range(2)
    ]
    outputs = [run.communicate(timeout=300)[0].strip() for run in runs]
    assert outputs == ["ok"] * 2
    files = sorted(p.name for p in tmp_path.iterdir())
    assert len(files) == 1 and files[0].startswith("search_kernel_") and files[0].endswith(".so")


@serial
def test_no_compiler_is_a_clear_error(monkeypatch):
    """Without any C compiler the error names what is missing."""
    monkeypatch.setenv("CC", "no-such-compiler")
    monkeypatch.setattr(compiled.shutil, "which", lambda name: None)
    with pytest.raises(compiled.CompilerNotFound, match="C compiler"):
        compiled._compiler()


def test_a_build_error_is_raised_on_every_rank(monkeypatch):
    """A kernel that cannot be built on rank 0 only: :func:`compiled.require` raises the
    build error on every rank, and making a contact problem calls it (its search builds the
    kernel on every rank, not only on the ranks with slave points, which search)."""
    comm = MPI.COMM_WORLD
    built = compiled.kernel

    def kernel():
        if comm.rank == 0:
            raise compiled.CompilerNotFound("no C compiler on rank 0")
        return built()

    monkeypatch.setattr(compiled, "kernel", kernel)
    with pytest.raises(compiled.CompilerNotFound, match="no C compiler on rank 0"):
        compiled.require(comm)
    monkeypatch.setattr(compiled, "kernel", built)
    required = []
    monkeypatch.setattr(compiled, "require", required.append)
    ContactProblem(scenes.hertz_2d(h_contact=0.05, depth=0.01).scene, verbose=False)
    assert len(required) == 1  # the one pair's search, on every rank


@serial
def test_numpy_search_on_request(monkeypatch):
    """The back end is the ``backend`` argument; without it ``CONTACT_UFL_SEARCH``, else the
    compiled search, for every facet kind; an unknown name is an error."""
    kinds = [(kind.nodes_per_facet, kind.gdim) for kind in FACET_KINDS]
    compiled_backend = closest_module.compiled_backend
    monkeypatch.delenv("CONTACT_UFL_SEARCH", raising=False)
    assert all(compiled_backend(None, n, gdim) for n, gdim in kinds)
    assert not any(compiled_backend("numpy", n, gdim) for n, gdim in kinds)
    monkeypatch.setenv("CONTACT_UFL_SEARCH", "numpy")
    assert not any(compiled_backend(None, n, gdim) for n, gdim in kinds)
    assert all(compiled_backend("compiled", n, gdim) for n, gdim in kinds)
    with pytest.raises(ValueError, match="back end 'fortran'"):
        closest_points(np.zeros((1, 2)), np.zeros((1, 2, 2)), backend="fortran")


@serial
def test_the_oracle_comparison_covers_every_facet_kind():
    """The surfaces of :func:`test_compiled_equals_numpy` hold every facet kind of the
    table (the NumPy search is the oracle of the compiled one for each)."""
    rng = np.random.default_rng(0)
    covered = {facet_kind(*make(rng, 8).shape[1:]) for make in SURFACES}
    assert covered == {kind.name for kind in FACET_KINDS}


@pytest.mark.parametrize("search", ["compiled", "numpy"])
@serial
def test_non_finite_input_is_an_error(search, monkeypatch):
    """A NaN or infinite slave point or master node is a clear error in either search (the
    compiled one paired such points silently), also when the same non-finite master is
    searched again with the same trees; finite nodes after it are searched as usual."""
    monkeypatch.setenv("CONTACT_UFL_SEARCH", search)
    rng = np.random.default_rng(4)
    nodes = triangle_soup(rng, 50)
    points = near_and_far(rng, nodes, 20)
    expected = closest_points(points, nodes, np.inf)
    bad_points = points.copy()
    bad_points[3, 1] = np.nan
    with pytest.raises(ValueError, match="slave points .* non-finite.*: 1 of 30, first row 3$"):
        closest_points(bad_points, nodes, np.inf)
    trees = TreeCache()
    closest_points(points, nodes, np.inf, trees)
    for value in (np.nan, np.inf):
        bad_nodes = nodes.copy()
        bad_nodes[7, 2, 0] = value
        for _ in range(2):  # the second time with the trees of the first
            with pytest.raises(
                ValueError, match="master nodes .* non-finite.*: 1 of 50, first row 7$"
            ):
                closest_points(points, bad_nodes, np.inf, trees)
    got = closest_points(points, nodes, np.inf, trees)
    np.testing.assert_array_equal(got.facet, expected.facet)


def test_non_finite_points_raised_on_every_rank():
    """The search of a contact problem (collective) raises a non-finite slave point of one
    rank on every rank."""
    comm = MPI.COMM_WORLD
    problem = ContactProblem(scenes.hertz_2d(h_contact=0.05, depth=0.01).scene, verbose=False)
    search = problem.contacts[0].kinematics.search
    points = search.slave.X.reshape(-1, search.gdim).copy()
    if comm.rank == 0 and len(points):
        points[0, 0] = np.inf
    elif comm.rank == 0:
        points = np.full((1, search.gdim), np.inf)
    with pytest.raises(ValueError, match=r"slave points .* non-finite.*first row 0 \(on rank 0\)"):
        search.exchange(search.master.X_nodes, points)


@pytest.mark.parametrize("make", [scenes.hertz_2d, scenes.hertz_3d])
def test_a_search_that_reuses_its_candidates_pairs_as_a_new_one(make):
    """The candidates' fixed data (order, fans, gathered columns) kept from one search to
    the next (the same candidates) give the pairing of a new search; candidates received in
    another order get the same data in the search order."""
    problem = ContactProblem(make(depth=0.01).scene, verbose=False)
    contact = problem.contacts[0]
    search, layout, u = contact.kinematics.search, problem.full_layout, contact.u
    search.pair(u, layout)
    first = search._candidates
    u.x.array[:] = -0.005 * u.function_space.tabulate_dof_coordinates()[:, : search.gdim].ravel()
    kept = search.pair(u, layout)
    current = search._candidates
    if MPI.COMM_WORLD.size == 1:  # on several ranks the exchange may send other facets
        assert current is first is not None
    assert search.candidates(current.table.copy()) is current  # the same rows: kept
    fresh = ClosestPointSearch(search.slave, search.master, search.radius, search.touching)
    new = fresh.pair(u, layout)
    for field in ("points", "nodes", "columns", "neighbourhood"):
        np.testing.assert_array_equal(getattr(kept, field), getattr(new, field))
    for field in ("facet", "xi", "y", "gap"):
        np.testing.assert_array_equal(
            getattr(kept.projection, field), getattr(new.projection, field)
        )
    assert MPI.COMM_WORLD.allreduce(np.count_nonzero(kept.paired), MPI.SUM) > 0
    reversed_ = search.candidates(current.table[::-1].copy())
    assert reversed_ is not current
    np.testing.assert_array_equal(reversed_.order, len(current.order) - 1 - current.order)
    for field in ("keys", "boundary", "flags", "gather", "fans", "counts"):
        np.testing.assert_array_equal(getattr(reversed_, field), getattr(current, field))


@serial
def test_stale_kernels_are_removed(tmp_path):
    """Of the kernels in the cache directory, those of other source hashes and the leftover
    temporary files changed over a day ago are removed; the current one, recent ones and
    other files are kept."""
    current = tmp_path / "search_kernel_current.so"
    names = [
        "search_kernel_old.so",
        "search_kernel_old.x1.tmp",
        "search_kernel_recent.so",
        "other_old.so",
        current.name,
    ]
    day_ago = time.time() - 2 * compiled.STALE_AGE
    for name in names:
        (tmp_path / name).write_text("")
        if name != "search_kernel_recent.so":
            os.utime(tmp_path / name, (day_ago, day_ago))
    removed = compiled.remove_stale(current)
    assert sorted(p.name for p in removed) == ["search_kernel_old.so", "search_kernel_old.x1.tmp"]
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted(["search_kernel_recent.so", "other_old.so", current.name])
    assert compiled.remove_stale(tmp_path / "missing" / "search_kernel_x.so") == []


@serial
def test_self_contact_bins_keep_their_trees(monkeypatch):
    """A self-contact search by normal bins keeps the trees of its bins in the caller's
    cache: a second search of the unchanged surface builds none, with the same results."""
    n = 4000
    t = -np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    ring = np.stack([np.cos(t), 0.06 * np.sin(t)], axis=1)
    facet_nodes = np.stack([np.arange(n), (np.arange(n) + 1) % n], axis=1)
    nodes = ring[facet_nodes]
    a1 = nodes[:, 1] - nodes[:, 0]
    normals = np.stack([a1[:, 1], -a1[:, 0]], axis=1)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    rule = SelfContact(facet_nodes, facet_nodes, normals)
    points = nodes.mean(axis=1)
    assert n > closest_module._DIRECTIONS_MIN
    built = []
    init = Hierarchy.__init__

    def counted(self, nodes):
        built.append(len(nodes))
        init(self, nodes)

    monkeypatch.setattr(Hierarchy, "__init__", counted)
    trees = TreeCache()
    first = closest_points(points, nodes, 0.05, trees, rule)
    assert len(built) > 1 and len(trees.parts) > 1
    built.clear()
    second = closest_points(points, nodes, 0.05, trees, rule)
    assert built == []
    np.testing.assert_array_equal(second.facet, first.facet)
    assert np.count_nonzero(first.facet >= 0) > n // 5


def spread_bits(v: np.ndarray) -> np.ndarray:
    """The 10 low bits of ``v`` spread to every third bit (bit ``i`` to bit ``3 i``)."""
    v = v & np.uint64(0x3FF)
    for shift, mask in ((16, 0x030000FF), (8, 0x0300F00F), (4, 0x030C30C3), (2, 0x09249249)):
        v = (v | (v << np.uint64(shift))) & np.uint64(mask)
    return v


def cell_order(points: np.ndarray) -> np.ndarray:
    """An order of the points along a Z-order (Morton) curve through the cells of a
    ``1024^gdim`` grid over their bounding box: the points of a cell, then of its neighbours,
    come one after the other (they walk the same branches of a tree while it is in cache).
    Stable: equal keys in the given order. The reference of the compiled search's order
    (``Hierarchy.order``)."""
    lo = points.min(axis=0)
    span = float((points.max(axis=0) - lo).max())
    if not (np.isfinite(span) and span > 0.0):
        return np.arange(points.shape[0])
    cell = np.minimum((points - lo) * (1024.0 / span), 1023.0).astype(np.uint64)
    key = spread_bits(cell[:, 0])
    for k in range(1, points.shape[1]):
        key |= spread_bits(cell[:, k]) << np.uint64(k)
    return np.argsort(key, kind="stable")


@serial
def test_compiled_order_is_the_cell_order():
    """The Z-order of the points computed in C (a radix sort) is the NumPy one
    (:func:`cell_order`, stable), in 2D and 3D, with repeated points; the
    identity for points that all coincide."""
    rng = np.random.default_rng(9)
    nodes = triangle_soup(rng, 20)
    tree = TreeCache().hierarchy(np.ascontiguousarray(nodes))
    for g in (2, 3):
        points = rng.normal(size=(3000, g)) * [1.0, 0.01, 5.0][:g]
        points = np.concatenate([points, points[:500]])  # equal keys: the given order kept
        np.testing.assert_array_equal(tree.order(points), cell_order(points))
        same = np.ones((7, g))
        np.testing.assert_array_equal(tree.order(same), np.arange(7))


@pytest.mark.parametrize(
    ("cells", "kind"),
    [(_triangle6_cells, "6-node triangles"), (_quadrilateral9_cells, "9-node quadrilaterals")],
    ids=["triangles6", "quadrilaterals9"],
)
@serial
def test_exact_ties_break_as_the_numpy_search(cells, kind, monkeypatch, verification):
    """Points above the shared vertices, edge midpoints and cell centres of a flat lattice
    of quadratic facets (given in two orders), where up to eight facets are at exactly the
    same distance and alignment: the compiled tie-break (in C) picks the facets of the
    NumPy one (the nearer centroid of the Bernstein control points, then the lower index),
    with the same closest points to round-off (measured 2.1e-15)."""
    m = 3
    s = np.linspace(0.0, 1.0, 2 * m + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    nodes = cells(np.stack([X, Y, np.zeros_like(X)], axis=-1), m)
    grid = np.linspace(0.0, 1.0, 4 * m + 1)
    gx, gy = (a.ravel() for a in np.meshgrid(grid, grid, indexing="ij"))
    points = np.concatenate(
        [np.stack([gx, gy, np.full_like(gx, height)], axis=1) for height in (0.25, -0.1)]
    )
    rng = np.random.default_rng(5)
    errors = []
    for order in (np.arange(len(nodes)), rng.permutation(len(nodes))):
        fast = closest_points(points, nodes[order], np.inf, backend="compiled")
        slow = closest_points(points, nodes[order], np.inf, backend="numpy")
        np.testing.assert_array_equal(fast.facet, slow.facet)
        errors += [np.abs(getattr(fast, k) - getattr(slow, k)).max() for k in FIELDS[:-1]]
    case = f"compiled search: exact ties on a flat lattice of {len(nodes)} {kind}"
    quantity = "max difference of xi, y, n, g, distance"
    verification(case, quantity, max(errors), 0.0, FLAT, NUMPY_SEARCH, kind="consistency")
    assert max(errors) <= FLAT


@pytest.mark.parametrize("offset", [-1e5, 3e4])
@serial
def test_far_from_the_origin(offset, monkeypatch):
    """Masters and points far from the origin (the single-precision boxes of the walk much
    wider than the facets): the compiled search finds the NumPy search's facets and closest
    points to round-off of the coordinates (measured equal)."""
    rng = np.random.default_rng(13)
    for make, nf in ((wavy_quads, 400), (triangle_soup, 300)):
        base = make(rng, nf)
        points = near_and_far(rng, base, 300) * 1e-3 + offset
        nodes = base * 1e-3 + offset
        fast = closest_points(points, nodes, np.inf, backend="compiled")
        slow = closest_points(points, nodes, np.inf, backend="numpy")
        np.testing.assert_array_equal(fast.facet, slow.facet)
        np.testing.assert_allclose(fast.y, slow.y, rtol=0, atol=1e-14 * abs(offset))
