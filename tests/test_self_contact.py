"""Self-contact: a surface searched against itself (the admissibility of pairs), and a slot
in a block pressed until it closes on itself.

Verified against a closed form: a block cut through by a slot with non-matching faces,
pressed shut, carries the uniform pressure of uniaxial strain (a patch test in
self-contact); and by Taylor tests of the tangent. Equilibrium, action = reaction (property
(e)) and the mirror symmetry of symmetric scenes hold by construction (consistency); the
self-contact search is compared with a two-surface pair on the same slot (consistency).
"""

import basix.ufl
import dolfinx
import numpy as np
import pytest
from conftest import across_ranks, assert_taylor_slopes
from mpi4py import MPI
from scipy.spatial import ConvexHull
from test_taylor import SLOPE_TOL, record_slopes

import contact_ufl as cu
from contact_ufl.contact.search import (
    SelfContact,
    TreeCache,
    closest_points,
    numpy_search,
    release_master_side,
)
from contact_ufl.contact.search import closest as closest_module
from contact_ufl.contact.search.numpy_facets import MasterFacets
from contact_ufl.errors import ContactInputError
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes
from contact_ufl.verification.geometries import tag_single_body
from contact_ufl.verification.taylor_cases import sliding_direction

SLOT = "slot closing on itself, 2D, Neo-Hookean, 20 x 10 quadrilaterals"
SLOT_3D = "slot closing on itself, 3D, Neo-Hookean, 20 x 2 x 10 hexahedra"
RING = "half ring squeezed between two plates until its hole closes"
EQUILIBRIUM = "the equilibrium of a converged solve"
ACTION = "action = reaction, property (e): the master shape functions sum to one"
MIRROR = "the mirror symmetry of the scene and its mesh"
RANKS = "the same scene solved on one rank"
#: the self-contact slot against the two-surface pair: top reaction (relative) and the
#: tractions (over the largest)
PAIR_REACTION = 5e-5
PAIR_TRACTION = 5e-3
#: the ring's departure from symmetry about y = 0 (one arc of the hole is the slave)
RING_ASYMMETRY = 2e-4


def _slit_2d(n: int = 40, a: float = 1.0, b: float = 0.06):
    """The boundary of an elliptic hole (half-axes ``a``, ``b``) in a body around it:
    segments traversed clockwise, so that the normal points into the hole (out of the body)."""
    t = -np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    ring = np.stack([a * np.cos(t), b * np.sin(t)], axis=1)
    facet_nodes = np.stack([np.arange(n), (np.arange(n) + 1) % n], axis=1)
    return ring[facet_nodes], facet_nodes


def _slit_3d(b: float = 0.1):
    """A thin box cavity ``[0, 1]^2 x [0, b]``: triangles of its surface, normals inward."""
    g = np.linspace(0.0, 1.0, 6)
    X, Y = np.meshgrid(g, g)
    pts = []
    for z in (0.0, b):
        pts.append(np.stack([X.ravel(), Y.ravel(), np.full(X.size, z)], axis=1))
    pts = np.unique(np.concatenate(pts), axis=0)
    hull = ConvexHull(pts)
    tri = hull.simplices.copy()
    nodes = pts[tri]
    outward = hull.equations[:, :3]
    normal = np.cross(nodes[:, 1] - nodes[:, 0], nodes[:, 2] - nodes[:, 0])
    flip = np.einsum("fd,fd->f", normal, outward) > 0  # make them point inward
    tri[flip] = tri[flip][:, [0, 2, 1]]
    return pts[tri], tri


def _facet_points(nodes: np.ndarray, facet_nodes: np.ndarray):
    """Centroids of the facets as the slave points, with their facets' nodes and normals."""
    points = nodes.mean(axis=1)
    a1 = nodes[:, 1] - nodes[:, 0]
    if nodes.shape[2] == 2:
        n = np.stack([a1[:, 1], -a1[:, 0]], axis=1)
    else:
        n = np.cross(a1, nodes[:, 2] - nodes[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return points, SelfContact(facet_nodes, facet_nodes, n)


def _brute_force(points, nodes, rule: SelfContact, radius=np.inf):
    """Distance and facet of each point over its admissible facets, one point at a time."""
    centre = MasterFacets(nodes).axis
    dist = np.full(len(points), np.inf)
    for p, x in enumerate(points):
        f = np.arange(len(nodes))
        ok = rule.admissible(np.full(f.size, p), f, centre)
        if ok.any():
            proj = closest_points(x[None], nodes[ok], radius)
            dist[p] = proj.distance[0]
    return dist


@pytest.mark.parametrize("slit", [_slit_2d, _slit_3d])
def test_self_contact_matches_brute_force(slit):
    nodes, facet_nodes = slit()
    points, rule = _facet_points(nodes, facet_nodes)
    # without the rule every point finds its own facet at distance zero
    plain = closest_points(points, nodes)
    assert np.all(plain.distance < 1e-12)
    proj = closest_points(points, nodes, self_contact=rule)
    expected = _brute_force(points, nodes, rule)
    assert np.all(proj.facet >= 0)
    np.testing.assert_allclose(proj.distance, expected, rtol=1e-12, atol=1e-14)
    # the partner faces the point: opposed normals, and it is not the point's own facet
    f = proj.facet
    assert np.all(np.einsum("pd,pd->p", proj.normal, rule.point_normals) < 0)
    assert not np.any(f == np.arange(len(points)))
    # the partner is across the slit: the points are in front of it (negative proximity)
    assert np.all(proj.gap < 0)


@pytest.mark.parametrize("slit", [_slit_2d, _slit_3d])
@pytest.mark.parametrize("radius", [np.inf, 0.11])
def test_self_contact_searched_again(slit, radius):
    """A self-contact surface searched again (its KD-trees reused): the same distances as
    facet by facet."""
    nodes, facet_nodes = slit()
    points, rule = _facet_points(nodes, facet_nodes)
    trees = TreeCache()
    closest_points(points, nodes, radius, trees, rule)
    proj = closest_points(points, nodes, radius, trees, rule)
    expected = _brute_force(points, nodes, rule)
    paired = expected <= radius
    np.testing.assert_array_equal(proj.facet >= 0, paired)
    np.testing.assert_allclose(proj.distance[paired], expected[paired], rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("slit", [_slit_2d, _slit_3d])
@pytest.mark.parametrize("radius", [np.inf, 0.11])
def test_self_contact_by_normal_bins(slit, radius, monkeypatch):
    """The search by normal bins (as on a large surface) skips, for each bin of points, the
    facets that face the same way, and finds the same partners as the plain search."""
    nodes, facet_nodes = slit()
    points, rule = _facet_points(nodes, facet_nodes)
    reference = closest_points(points, nodes, radius, self_contact=rule)
    monkeypatch.setattr(closest_module, "_DIRECTIONS_MIN", 0)
    sizes = []
    search = closest_module._search

    def counted(points, nodes, *args):
        sizes.append(len(nodes))
        return search(points, nodes, *args)

    monkeypatch.setattr(closest_module, "_search", counted)
    proj = closest_points(points, nodes, radius, self_contact=rule)
    assert len(sizes) > 1 and max(sizes) < len(nodes)  # bins, each without some facets
    np.testing.assert_array_equal(proj.facet, reference.facet)
    for field in ("xi", "y", "normal", "gap", "distance", "sliding"):
        np.testing.assert_array_equal(getattr(proj, field), getattr(reference, field))
    expected = _brute_force(points, nodes, rule)
    paired = expected <= radius
    np.testing.assert_array_equal(proj.facet >= 0, paired)
    np.testing.assert_allclose(proj.distance[paired], expected[paired], rtol=1e-12, atol=1e-14)


def test_self_contact_across_an_elliptic_slit():
    """The points of each arc find the other arc across the slit, symmetrically about y = 0."""
    nodes, facet_nodes = _slit_2d(n=80, b=0.05)
    points, rule = _facet_points(nodes, facet_nodes)
    proj = closest_points(points, nodes, self_contact=rule)
    middle = np.abs(points[:, 0]) < 0.9
    assert np.all(np.sign(proj.y[middle, 1]) == -np.sign(points[middle, 1]))
    # the partner of the mirror image (x, -y) of a point is the mirror image of its partner
    mirror = points * [1.0, -1.0]
    image = np.argmin(np.linalg.norm(points[:, None] - mirror[None], axis=2), axis=0)
    np.testing.assert_allclose(points[image], mirror, atol=1e-14)
    np.testing.assert_allclose(proj.y[image], proj.y * [1.0, -1.0], atol=1e-14)
    np.testing.assert_allclose(proj.distance[image], proj.distance, rtol=1e-13)


@pytest.mark.parametrize("slit", [_slit_2d, _slit_3d])
def test_self_contact_blocks_and_order(slit, monkeypatch):
    """Blocks of points and the spatial order map the points to their own facets."""
    nodes, facet_nodes = slit()
    points, rule = _facet_points(nodes, facet_nodes)
    reference = closest_points(points, nodes, self_contact=rule)
    monkeypatch.setattr(numpy_search, "_BLOCK", 7)
    monkeypatch.setattr(closest_module, "_SORT", 0)
    proj = closest_points(points, nodes, self_contact=rule)
    np.testing.assert_array_equal(proj.facet, reference.facet)
    np.testing.assert_array_equal(proj.distance, reference.distance)


def test_self_contact_within_a_radius():
    """A radius shorter than the slit's width leaves every point unpaired (no fallback to
    the excluded neighbours); a radius just over it pairs the middle points."""
    nodes, facet_nodes = _slit_2d(n=80, b=0.05)
    points, rule = _facet_points(nodes, facet_nodes)
    short = closest_points(points, nodes, radius=0.05, self_contact=rule)
    width = _brute_force(points, nodes, rule)
    np.testing.assert_array_equal(short.facet >= 0, width <= 0.05)
    assert np.count_nonzero(short.facet >= 0) < len(points)
    wide = closest_points(points, nodes, radius=0.11, self_contact=rule)
    np.testing.assert_array_equal(wide.facet >= 0, width <= 0.11)
    np.testing.assert_allclose(wide.distance[wide.facet >= 0], width[width <= 0.11], rtol=1e-12)


def test_one_pass_per_facing_couple():
    """Of two facing facets only the one of lower vertex key keeps its points paired: no
    couple of facets is paired both ways (the constraint is imposed once)."""
    nodes, facet_nodes = _slit_2d(n=80, b=0.05)
    points, rule = _facet_points(nodes, facet_nodes)  # point k is the centroid of facet k
    proj = closest_points(points, nodes, self_contact=rule)
    partner = proj.facet.copy()
    assert np.all(partner >= 0)
    release_master_side(proj, rule)
    kept = proj.facet >= 0
    np.testing.assert_array_equal(kept, facet_nodes[partner].min(axis=1) > facet_nodes.min(axis=1))
    assert np.all(proj.gap[~kept] == -np.inf)
    couples = set(zip(np.flatnonzero(kept).tolist(), proj.facet[kept].tolist(), strict=True))
    assert not any((f, F) in couples for F, f in couples)
    assert 0 < np.count_nonzero(kept) < len(points)


def test_self_contact_of_a_flat_surface_finds_nothing():
    """A flat surface never faces itself: no admissible pair."""
    x = np.linspace(0.0, 1.0, 11)
    line = np.stack([x, np.zeros_like(x)], axis=1)
    facet_nodes = np.stack([np.arange(10), np.arange(1, 11)], axis=1)
    nodes = line[facet_nodes]
    points, rule = _facet_points(nodes, facet_nodes)
    proj = closest_points(points, nodes, self_contact=rule)
    assert np.all(proj.facet == -1)


def test_self_contact_shapes_are_checked():
    nodes, facet_nodes = _slit_2d()
    points, rule = _facet_points(nodes, facet_nodes)
    bad = SelfContact(rule.point_nodes[:-1], rule.facet_nodes, rule.point_normals)
    with pytest.raises(ValueError, match="self_contact must hold"):
        closest_points(points, nodes, self_contact=bad)


# -- a slot closing on itself -------------------------------------------------------------


def _slot_mesh(comm: MPI.Comm, nx: int = 20, ny: int = 10) -> dolfinx.mesh.Mesh:
    """The block [0, 2] x [0, 1] in nx x ny quadrilaterals without the cells of one row
    between x = 0.5 and 1.5: a slot 0.1 high, y in [0.5, 0.6]."""
    X, Y = np.meshgrid(np.linspace(0, 2, nx + 1), np.linspace(0, 1, ny + 1))
    x = np.stack([X.ravel(), Y.ravel()], axis=1)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny)))
    keep = ~((j == ny // 2) & (i >= nx // 4) & (i < 3 * nx // 4))
    n0 = j[keep] * (nx + 1) + i[keep]
    cells = np.stack([n0, n0 + 1, n0 + nx + 1, n0 + nx + 2], axis=1)
    return _mesh_from_rank_0(comm, cells, x, "quadrilateral")


def _mesh_from_rank_0(
    comm: MPI.Comm, cells: np.ndarray, x: np.ndarray, cell_type: str
) -> dolfinx.mesh.Mesh:
    """The P1 mesh of ``cells`` (rows of indices into the points ``x``; the points no cell
    uses are dropped), given on rank 0 and distributed with shared-facet ghosts."""
    used = np.unique(cells)
    cells, x = np.searchsorted(used, cells), x[used]
    if comm.rank != 0:
        cells, x = np.empty((0, cells.shape[1]), np.int64), np.empty((0, x.shape[1]))
    element = basix.ufl.element("Lagrange", cell_type, 1, shape=(x.shape[1],))
    partitioner = dolfinx.mesh.create_cell_partitioner(dolfinx.mesh.GhostMode.shared_facet, 2)
    return dolfinx.mesh.create_mesh(comm, cells, element, x, partitioner=partitioner)


def _in_slot(x, y0=0.5, y1=0.6):
    e = 1e-9
    return (x[0] > 0.5 - e) & (x[0] < 1.5 + e) & (x[1] > y0 - e) & (x[1] < y1 + e)


def _slot_scene(comm: MPI.Comm, self_contact: bool = True, depth: float = 0.15) -> cu.Scene:
    """The slotted block clamped at y = 0 (tag 1), its top (tag 2) moved down by ``depth``:
    the slot closes. Self-contact of the slot's surface (tag 3), or the classical pair of its
    lower face (tag 3, slave) and upper face (tag 4, master); eps_N = E / (slot length)."""
    mesh = _slot_mesh(comm)
    sides = [lambda x: np.isclose(x[1], 0.0), lambda x: np.isclose(x[1], 1.0)]
    if self_contact:
        sides.append(_in_slot)
        pairs = [cu.ContactPair(3, 3, eps_N=1.0)]
    else:
        sides += [lambda x: _in_slot(x, 0.5, 0.5), lambda x: _in_slot(x, 0.6, 0.6)]
        pairs = [cu.ContactPair(3, 4, eps_N=1.0)]
    cells, facets = tag_single_body(mesh, sides)
    return cu.Scene(
        mesh,
        cells,
        facets,
        [cu.Body(1, cu.NeoHookean(1.0, 0.3))],
        contacts=pairs,
        dirichlet=[cu.Dirichlet(1, (0.0, 0.0)), cu.Dirichlet(2, lambda t: (0.0, -depth * t))],
    )


def _solved(comm: MPI.Comm, self_contact: bool = True) -> ContactProblem:
    problem = ContactProblem(_slot_scene(comm, self_contact), verbose=False)
    problem.solve(num_steps=4)
    return problem


def _point_tractions(problem: ContactProblem) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reference positions, partner facet flags and normal tractions of all slave points."""
    c = problem.contacts[0]
    proj = c.kinematics.projection
    t_N = c.normal.traction_at_points(proj)
    X = c.slave.X.reshape(-1, problem.gdim)
    gathered = problem.comm.allgather((X, proj.facet >= 0, t_N))
    return tuple(np.concatenate([g[k] for g in gathered]) for k in range(3))


def _contact_resultant(problem: ContactProblem) -> np.ndarray:
    """The contact residual summed over the nodes of the (one) body, on all ranks."""
    R = problem.contact_residual()
    local = R.array[problem.block_rows(0)].reshape(-1, problem.gdim).sum(axis=0)
    return problem.comm.allreduce(local, MPI.SUM)


def _mirror_image(X: np.ndarray, mirror: np.ndarray) -> np.ndarray:
    """For each point of ``mirror`` (the mirror images of the points ``X``) the index of the
    point of ``X`` at it (asserted to be there)."""
    image = np.argmin(np.linalg.norm(X[:, None] - mirror[None], axis=2), axis=0)
    np.testing.assert_allclose(X[image], mirror, atol=1e-12)
    return image


def _iterations(problem: ContactProblem) -> list[int]:
    """Newton iterations of the accepted steps."""
    return [s.newton_iterations for s in problem.history.steps]


def _assert_same_run(
    alone: ContactProblem, problem: ContactProblem, quantity, rel: float, record, case, name
):
    """``alone`` (one rank) and ``problem``: the same ``quantity(problem)`` to ``rel`` of its
    norm (recorded with ``record`` as ``name`` of ``case``), and the same Newton
    iterations."""
    a, b = quantity(alone), quantity(problem)
    difference = np.abs(a - b).max() / np.linalg.norm(a)
    record(case, name, difference, 0.0, f"< {rel:g}", RANKS, kind="consistency")
    assert difference <= rel
    assert _iterations(alone) == _iterations(problem)


def _record_balance(record, case, quantity, ratio, bound, source):
    """Record a consistency check ``ratio < bound`` (a relative resultant or asymmetry)."""
    record(case, quantity, ratio, 0.0, f"< {bound:g}", source, kind="consistency")


@pytest.fixture(scope="module")
def closed_slot():
    return _solved(MPI.COMM_WORLD)


@pytest.mark.serial  # 2 ranks: test_slot_same_result_on_any_number_of_ranks
def test_slot_closes_on_itself(closed_slot, verification):
    """The slot pressed shut: Newton converges quadratically (a single pass: the lower face
    is the slave, the upper face its master). Consistency checks, which hold by
    construction: the block is in equilibrium, the contact forces on the one body cancel
    (property (e)) and the result is symmetric about x = 1 (as the scene and its mesh)."""
    problem = closed_slot
    assert _iterations(problem) == [3, 3, 4, 4]
    assert problem.active_points() >= 12
    # equilibrium: the two supports' reactions balance (the contact forces are internal)
    top = problem.reaction(2)
    assert top[1] < -0.2
    balance = np.linalg.norm(problem.reaction([1, 2])) / np.linalg.norm(top)
    quantity = "|sum of the support reactions| / |top reaction|"
    _record_balance(verification, SLOT, quantity, balance, 1e-12, EQUILIBRIUM)
    assert balance < 1e-12
    # property (e): the contact residual sums to zero over the body (slave and master sides
    # on the same body), while its slave side alone does not
    slave_side = problem.contact_force()
    assert slave_side[1] < -0.05
    resultant = np.linalg.norm(_contact_resultant(problem)) / np.linalg.norm(slave_side)
    quantity = "|contact resultant on the body| / |slave side's|"
    _record_balance(verification, SLOT, quantity, resultant, 1e-14, ACTION)
    assert resultant < 1e-14
    # one pass: only the lower face's points are paired; symmetric tractions about x = 1
    X, paired, t_N = _point_tractions(problem)
    assert np.all(np.isclose(X[paired, 1], 0.5))
    assert np.count_nonzero(t_N > 0) >= 12
    image = _mirror_image(X, np.stack([2.0 - X[:, 0], X[:, 1]], axis=1))
    asymmetry = np.abs(t_N[image] - t_N).max() / t_N.max()
    quantity = "largest |t_N(2 - x) - t_N(x)| / largest t_N"
    _record_balance(verification, SLOT, quantity, asymmetry, 1e-12, MIRROR)
    assert asymmetry < 1e-12


@pytest.mark.serial  # 2 ranks: test_slot_same_result_on_any_number_of_ranks
def test_slot_self_contact_equals_the_two_surface_pair(closed_slot, verification):
    """The same slot with the classical pair (lower face slave, upper face master): the same
    contact up to the multiplier space (a consistency check of the self-contact search
    against the two-surface one). The self-contact slave surface also holds the side walls
    and the upper face (unpaired: lambda_N = 0 there), and the multiplier equation ties
    lambda_N to t_N in L2 over the whole slave surface, so lambda_N differs near the slot's
    ends: the tractions by 0.2% of the peak at the edge of the contact zone (bound
    PAIR_TRACTION), the top reaction by 2.9e-5 (PAIR_REACTION)."""
    classical = _solved(MPI.COMM_WORLD, self_contact=False)
    assert _iterations(classical) == _iterations(closed_slot)
    assert classical.active_points() == closed_slot.active_points()
    a, b = closed_slot.reaction(2), classical.reaction(2)
    reaction = np.linalg.norm(a - b) / np.linalg.norm(b)
    X, _, t_self = _point_tractions(closed_slot)
    Y, _, t_classical = _point_tractions(classical)
    lower = np.isclose(X[:, 1], 0.5)
    mine, theirs = np.lexsort(X[lower].T), np.lexsort(Y.T)
    np.testing.assert_allclose(X[lower][mine], Y[theirs], atol=1e-14)
    traction = np.abs(t_self[lower][mine] - t_classical[theirs]).max() / t_classical.max()
    source = "the same slot with a two-surface pair (lower face slave, upper face master)"
    for quantity, value, bound in (
        ("|top reaction difference| / |top reaction|", reaction, PAIR_REACTION),
        ("largest t_N difference / largest t_N", traction, PAIR_TRACTION),
    ):
        verification(SLOT, quantity, value, 0.0, f"< {bound:g}", source, kind="consistency")
    assert reaction < PAIR_REACTION
    assert traction < PAIR_TRACTION


@across_ranks
def test_slot_same_result_on_any_number_of_ranks(closed_slot, verification):
    """One rank and this communicator's ranks: the same reaction (to round-off: 2e-16
    measured) and Newton iterations."""
    _assert_same_run(
        _solved(MPI.COMM_SELF),
        closed_slot,
        lambda p: p.reaction(2),
        1e-12,
        verification,
        f"{SLOT}, all ranks against one",
        "largest top reaction difference / |top reaction|",
    )


def _cut_block_mesh(comm: MPI.Comm) -> dolfinx.mesh.Mesh:
    """The block [0, 2] x [0, 1] cut through by the slot y in [0.5, 0.6]: its lower part in
    10 x 5 quadrilaterals, its upper part in 7 x 4 (the faces of the slot do not match;
    the lower part's nodes come first, so its face has the lower vertex keys)."""
    points, cells, offset = [], [], 0
    for nx, ny, y0, y1 in ((10, 5, 0.0, 0.5), (7, 4, 0.6, 1.0)):
        X, Y = np.meshgrid(np.linspace(0, 2, nx + 1), np.linspace(y0, y1, ny + 1))
        points.append(np.stack([X.ravel(), Y.ravel()], axis=1))
        i, j = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny)))
        n0 = offset + j * (nx + 1) + i
        cells.append(np.stack([n0, n0 + 1, n0 + nx + 1, n0 + nx + 2], axis=1))
        offset += (nx + 1) * (ny + 1)
    return _mesh_from_rank_0(comm, np.concatenate(cells), np.concatenate(points), "quadrilateral")


def test_slot_closed_through_the_block_patch_test(verification):
    """A contact patch test in self-contact: one body, the block cut through by a slot whose
    faces do not match, one self-contact surface (both faces). The sides are held normally,
    the bottom clamped, the top moved down by 0.15: once the slot (0.1) has closed, both
    parts are in the same uniaxial strain, stretch ``s = 1 - 0.05 / 0.9``, and the
    multiplier is the uniform pressure of the Neo-Hookean energy in plane strain, ``p =
    mu (1/s - s) - lambda ln(s) / s``. With the composite rule of the patch test (8
    sub-segments) the multipliers at the slave points are within 1e-3 of it (4.8e-4
    measured, as in tests/test_patch.py), the top reaction within 5e-8 (1.7e-8)."""
    mesh = _cut_block_mesh(MPI.COMM_WORLD)
    e = 1e-9
    cells, facets = tag_single_body(
        mesh,
        [
            lambda x: np.isclose(x[1], 0.0),
            lambda x: np.isclose(x[1], 1.0),
            lambda x: (x[1] > 0.5 - e) & (x[1] < 0.6 + e),
            lambda x: np.isclose(x[0], 0.0) | np.isclose(x[0], 2.0),
        ],
    )
    E, nu, depth, width = 1.0, 0.3, 0.15, 2.0
    scene = cu.Scene(
        mesh,
        cells,
        facets,
        [cu.Body(1, cu.NeoHookean(E, nu))],
        contacts=[cu.ContactPair(3, 3, eps_N=E, quadrature_subdivisions=8)],
        dirichlet=[
            cu.Dirichlet(1, (0.0, 0.0)),
            cu.Dirichlet(2, lambda t: (0.0, -depth * t)),
            cu.Dirichlet(4, 0.0, component=0),
        ],
    )
    problem = ContactProblem(scene, verbose=False, petsc_options={"snes_rtol": 1e-13})
    problem.solve(num_steps=4)
    mu, lmbda = E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    stretch = 1.0 - (depth - 0.1) / 0.9
    pressure = mu * (1.0 / stretch - stretch) - lmbda * np.log(stretch) / stretch
    c = problem.contacts[0]
    active = c.active()
    X = c.slave.X.reshape(-1, 2)
    # one pass: the points of the lower face are paired, all of them, those of the upper not
    lower = np.isclose(X[:, 1], 0.5)
    assert np.array_equal(active, lower)
    assert problem.comm.allreduce(int(lower.sum())) == 10 * 2 * 8
    deviation = np.abs(c.multiplier_at_points()[active] / pressure - 1.0).max(initial=0.0)
    deviation = problem.comm.allreduce(deviation, op=MPI.MAX)
    reaction = abs(problem.reaction(2)[1] / (-width * pressure) - 1.0)
    case = "slot through a block, self-contact of non-matching faces (patch test)"
    source = "uniaxial strain of a Neo-Hookean solid in plane strain: closed form"
    closed_form = "p = mu (1/s - s) - lambda ln(s) / s"
    quantity = "largest |lambda_N / p - 1| at the slave points"
    verification(case, quantity, deviation, closed_form, "< 1e-3", source)
    verification(case, "|top reaction / (p w) - 1|", reaction, closed_form, "< 5e-8", source)
    assert deviation < 1e-3
    assert reaction < 5e-8


def test_self_contact_of_a_flat_face_is_refused():
    """The top face of a square as a self-contact pair: it never faces itself."""
    mesh = dolfinx.mesh.create_unit_square(
        MPI.COMM_WORLD, 4, 4, ghost_mode=dolfinx.mesh.GhostMode.shared_facet
    )
    cells, facets = tag_single_body(
        mesh, [lambda x: np.isclose(x[1], 0.0), lambda x: np.isclose(x[1], 1.0)]
    )
    scene = cu.Scene(
        mesh,
        cells,
        facets,
        [cu.Body(1, cu.NeoHookean(1.0, 0.3))],
        contacts=[cu.ContactPair(2, 2)],
        dirichlet=[cu.Dirichlet(1, (0.0, 0.0))],
    )
    with pytest.raises(ContactInputError, match="never faces itself"):
        ContactProblem(scene, verbose=False)


def test_frictional_self_contact_is_refused():
    with pytest.raises(ContactInputError, match="self-contact pair .* is frictionless"):
        cu.ContactPair(3, 3, mu=0.2).validate(MPI.COMM_WORLD)


def test_taylor_of_the_closed_slot(closed_slot, verification):
    """The tangent at the closed slot (the lower face pressed by the upper one, both sides of
    one surface and of one body): second-order remainders along a smooth direction that
    deforms the block and changes the multipliers."""
    problem = closed_slot
    dz = sliding_direction(problem, 1, np.zeros(2), amplitude=0.02, multiplier=0.01)
    steps = [1e-3 * 2.0**-k for k in range(4)]
    result = assert_taylor_slopes(problem, dz, steps, tol=SLOPE_TOL)
    record_slopes(verification, f"Taylor test, {SLOT}", result, tol=SLOPE_TOL)


def _slot_mesh_3d(comm: MPI.Comm, nx: int = 20, ny: int = 2, nz: int = 10) -> dolfinx.mesh.Mesh:
    """The block [0, 2] x [0, 0.2] x [0, 1] in nx x ny x nz hexahedra without the cells of
    one layer between x = 0.5 and 1.5: a slot through the block, z in [0.5, 0.6]."""
    g = [np.linspace(0, 2, nx + 1), np.linspace(0, 0.2, ny + 1), np.linspace(0, 1, nz + 1)]
    Z, Y, X = np.meshgrid(g[2], g[1], g[0], indexing="ij")
    x = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    k, j, i = (
        a.ravel() for a in np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    )
    keep = ~((k == nz // 2) & (i >= nx // 4) & (i < 3 * nx // 4))
    sy, sz = nx + 1, (nx + 1) * (ny + 1)
    n0 = k[keep] * sz + j[keep] * sy + i[keep]
    corners = [0, 1, sy, sy + 1]
    cells = np.stack([n0 + c for c in corners] + [n0 + sz + c for c in corners], axis=1)
    return _mesh_from_rank_0(comm, cells, x, "hexahedron")


@pytest.mark.serial  # on 2 ranks: this file's rank comparisons
def test_slot_closes_on_itself_in_3d(verification):
    """The slot through a 3D block (plane strain by u_y = 0 on the sides y = 0, 0.2) pressed
    shut: quadratic Newton; equilibrium, property (e) and symmetric tractions about x = 1
    (consistency checks, as in 2D)."""
    comm = MPI.COMM_WORLD
    mesh = _slot_mesh_3d(comm)
    e = 1e-9
    cells, facets = tag_single_body(
        mesh,
        [
            lambda x: np.isclose(x[2], 0.0),
            lambda x: np.isclose(x[2], 1.0),
            lambda x: (x[0] > 0.5 - e) & (x[0] < 1.5 + e) & (x[2] > 0.5 - e) & (x[2] < 0.6 + e),
            lambda x: np.isclose(x[1], 0.0) | np.isclose(x[1], 0.2),
        ],
    )
    scene = cu.Scene(
        mesh,
        cells,
        facets,
        [cu.Body(1, cu.NeoHookean(1.0, 0.3))],
        contacts=[cu.ContactPair(3, 3, eps_N=1.0)],
        dirichlet=[
            cu.Dirichlet(1, (0.0, 0.0, 0.0)),
            cu.Dirichlet(2, lambda t: (0.0, 0.0, -0.15 * t)),
            cu.Dirichlet(4, 0.0, component=1),
        ],
    )
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=4)
    assert _iterations(problem) == [3, 3, 4, 4]
    assert problem.active_points() >= 60
    top = problem.reaction(2)
    assert top[2] < -0.05
    balance = np.linalg.norm(problem.reaction([1, 2, 4])) / np.linalg.norm(top)
    quantity = "|sum of the support reactions| / |top reaction|"
    _record_balance(verification, SLOT_3D, quantity, balance, 1e-12, EQUILIBRIUM)
    assert balance < 1e-12
    slave_side = problem.contact_force()
    assert slave_side[2] < -0.01
    resultant = np.linalg.norm(_contact_resultant(problem)) / np.linalg.norm(slave_side)
    quantity = "|contact resultant on the body| / |slave side's|"
    _record_balance(verification, SLOT_3D, quantity, resultant, 1e-14, ACTION)
    assert resultant < 1e-14
    X, _, t_N = _point_tractions(problem)
    image = _mirror_image(X, X * [-1.0, 1.0, 1.0] + [2.0, 0.0, 0.0])
    asymmetry = np.abs(t_N[image] - t_N).max() / t_N.max()
    quantity = "largest |t_N(2 - x) - t_N(x)| / largest t_N"
    _record_balance(verification, SLOT_3D, quantity, asymmetry, 1e-12, MIRROR)
    assert asymmetry < 1e-12


# -- a ring squeezed between two plates until its hole closes ----------------------------


def _ring_problem(comm: MPI.Comm, depth: float = 0.8, steps: int = 10) -> ContactProblem:
    """The half ring of :func:`~contact_ufl.verification.scenes.squeezed_ring` squeezed
    between the plates until its hole closes, in ``steps`` steps."""
    problem = ContactProblem(scenes.squeezed_ring(depth, comm=comm), verbose=False)
    problem.solve(num_steps=steps)
    return problem


@pytest.fixture(scope="module")
def squeezed_ring():
    return _ring_problem(MPI.COMM_WORLD)


def _displacement(problem: ContactProblem) -> tuple[np.ndarray, np.ndarray]:
    """Coordinates and displacements of all the nodes (of all ranks)."""
    u = problem.bulks[0].u
    V = u.function_space
    n = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:n, :2]
    values = u.x.array.reshape(-1, 2)[:n]
    gathered = problem.comm.allgather((x, values))
    return tuple(np.concatenate([g[k] for g in gathered]) for k in range(2))


@pytest.mark.serial  # 2 ranks: test_ring_same_result_on_any_number_of_ranks
def test_ring_hole_closes_on_itself(squeezed_ring, verification):
    """The plates' forces balance each other and the cut; the self-contact forces cancel on
    the ring (property (e)) while its slave side alone carries most of the plates' force
    (consistency checks, by construction); the result is symmetric about y = 0 up to the
    one-pass choice of slave arc (RING_ASYMMETRY of the largest displacement)."""
    problem = squeezed_ring
    top, bottom, inner = problem.contacts
    plates = [problem.obstacle_reaction(c.pair.master) for c in (top, bottom)]
    assert plates[0][1] < -0.3
    total = problem.reaction(1) + plates[0] + plates[1]
    balance = np.linalg.norm(total) / np.linalg.norm(plates[0])
    quantity = "|plates' and cut's reactions| / |top plate's|"
    _record_balance(verification, RING, quantity, balance, 1e-12, EQUILIBRIUM)
    assert balance < 1e-12
    # the self pair: in contact over a good part of the hole, its resultant on the ring zero
    assert problem.comm.allreduce(int(inner.active().sum())) >= 30
    slave_side = problem.contact_force(2)
    assert slave_side[1] < -0.25
    plates_slave_side = problem.contact_force(0) + problem.contact_force(1)
    plates_balance = np.linalg.norm(plates_slave_side) / np.linalg.norm(plates[0])
    quantity = "|contact forces of the two plates on the ring| / |top plate's|"
    _record_balance(verification, RING, quantity, plates_balance, 1e-12, EQUILIBRIUM)
    assert plates_balance < 1e-12
    resultant = np.linalg.norm(_contact_resultant(problem)) / np.linalg.norm(slave_side)
    quantity = "|contact resultant on the ring| / |self pair's slave side|"
    _record_balance(verification, RING, quantity, resultant, 1e-14, ACTION)
    assert resultant < 1e-14
    # symmetry about y = 0: u(x, -y) = (u_x, -u_y)(x, y)
    X, U = _displacement(problem)
    image = _mirror_image(X, X * [1.0, -1.0])
    asymmetry = np.abs(U[image] * [1.0, -1.0] - U).max() / np.abs(U).max()
    quantity = "largest |u mirrored about y = 0 - u| / largest |u|"
    _record_balance(verification, RING, quantity, asymmetry, RING_ASYMMETRY, MIRROR)
    assert asymmetry < RING_ASYMMETRY


@across_ranks
def test_ring_same_result_on_any_number_of_ranks(squeezed_ring, verification):
    """One rank and this communicator's ranks: the same self-contact force (to round-off:
    7e-16 measured) and Newton iterations."""
    _assert_same_run(
        _ring_problem(MPI.COMM_SELF),
        squeezed_ring,
        lambda p: p.contact_force(2),
        1e-12,
        verification,
        f"{RING}, all ranks against one",
        "largest self pair's contact force difference / its norm",
    )
