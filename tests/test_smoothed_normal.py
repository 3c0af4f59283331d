"""The smoothed master normal of 3D master surfaces: the fans of the facet nodes, the normal's
continuity across facet edges, its NumPy twin against UFL, and the bound on the fan size; and
the default master normal (smoothed in 2D, facet in 3D)."""

import dataclasses

import dolfinx
import numpy as np
import pytest
import ufl
from conftest import across_ranks
from mpi4py import MPI

from contact_ufl.contact import master as master_module
from contact_ufl.contact.master import CYCLIC_ORDER, MeshMaster, node_fans
from contact_ufl.contact.obstacles import RigidPlane
from contact_ufl.contact.pair import ContactPair
from contact_ufl.contact.search import FACET_EDGES, shape_functions
from contact_ufl.contact.search.normals import fan_normals, smoothed_normals_3d
from contact_ufl.errors import ContactInputError
from contact_ufl.layout import StackedLayout
from contact_ufl.problem import ContactProblem
from contact_ufl.verification.geometries import tag_single_body
from contact_ufl.verification.scenes import curved_pair, warp_saddle
from contact_ufl.verification.taylor_cases import curved_case, smooth_field

#: what the smoothed normal is (docs/guide/contact.md): area-weighted nodal normals over each
#: node's fan of facets, interpolated over each facet
DEFINITION = "the smoothed normal's definition, computed here another way"

#: reference coordinates of the vertices of a triangle and a quadrilateral (basix order)
REFERENCE_VERTICES = {
    3: np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
    4: np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]),
}


def test_fans_of_a_square_split_into_four_triangles(verification):
    """Centre 4 of the square 0-1-2-3 (counter-clockwise seen from +z): a closed fan of four
    triangles; a corner: an open fan of two, padded with the node itself."""
    triangles = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    fans = node_fans(MPI.COMM_SELF, triangles, 3)
    assert fans.shape == (4, 3, 5)
    assert fans[0, 2].tolist() == [0, 1, 2, 3, 0]  # closed: the first neighbour again
    assert fans[0, 0].tolist() == [1, 4, 3, 0, 0]  # open: from the facet with none before
    X = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.2]])
    nodes = np.concatenate([X[triangles], X[fans.reshape(4, -1)]], axis=1)
    normals = fan_normals(nodes, 3)
    corner = np.cross(X[1] - X[0], X[4] - X[0]) + np.cross(X[4] - X[0], X[3] - X[0])
    errors = [
        np.abs(normals[0, 2] - [0.0, 0.0, 1.0]).max(),  # the apex of a symmetric pyramid
        np.abs(normals[0, 0] - corner / np.linalg.norm(corner)).max(),
    ]
    case = "nodal normals of a pyramid over the unit square (four triangles)"
    for quantity, error, reference in (
        ("largest |nodal normal - e_z| at the apex", errors[0], "(0, 0, 1): the symmetry"),
        ("largest |nodal normal - area-weighted sum| at a corner", errors[1], "the two facets"),
    ):
        verification(case, quantity, error, reference, "< 1e-15", "closed form")
    assert errors[0] < 1e-15 and errors[1] < 1e-15


def test_fans_reject_a_pinched_surface():
    """Two triangles that meet at one node only: that node's facets are not one fan."""
    triangles = np.array([[0, 1, 2], [0, 3, 4]])
    with pytest.raises(ContactInputError, match="one fan"):
        node_fans(MPI.COMM_SELF, triangles, 3)


def warped_box_top(comm: MPI.Comm, cell: str):
    """The top of a warped box as a smoothed master surface, and the nodal normals of its
    facets at a smooth displacement ``(nf, nn, 3)``."""
    cell_type = getattr(dolfinx.mesh.CellType, cell)
    mesh = dolfinx.mesh.create_box(
        comm,
        [[0.0, 0.0, 0.0], [1.0, 1.0, 0.5]],
        [6, 6, 2],
        cell_type,
        ghost_mode=dolfinx.mesh.GhostMode.shared_facet,
    )
    _, facet_tags = tag_single_body(mesh, [lambda x: np.isclose(x[2], 0.5)])
    warp_saddle(mesh)
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (3,)))
    u = dolfinx.fem.Function(V)
    u.interpolate(lambda x: smooth_field(x, 0.05, 3))
    master = MeshMaster(u, facet_tags, 1, smoothed=True)
    normals = fan_normals(master.candidates(StackedLayout([V])).nodes, master.nn)
    return master, u, normals


@pytest.mark.parametrize("cell", ["tetrahedron", "hexahedron"])
def test_nodal_normals_gather_the_facets_of_every_rank(cell, verification):
    """The nodal normals of the carried fans are those of all the facets around each node,
    wherever they live: compared with the sum of the corner normals of every facet of every
    rank. On two ranks the master surface (the top of one box) is split between them: this
    test is meant for 2 ranks too (the gathering across ranks is what it checks), although
    test_fans_are_the_same_on_any_number_of_ranks compares the same scene with one rank."""
    master, u, normals = warped_box_top(MPI.COMM_WORLD, cell)
    nn, comm = master.nn, MPI.COMM_WORLD
    # the reference: the corner normals of all facets of all ranks, summed at their nodes
    ids = np.concatenate(comm.allgather(master.global_nodes.astype(np.int64)))
    X = np.concatenate(comm.allgather(master.current_nodes()))
    cyclic = list(CYCLIC_ORDER[nn])
    ids, X = ids[:, cyclic], X[:, cyclic]
    corner = np.cross(np.roll(X, -1, axis=1) - X, np.roll(X, 1, axis=1) - X)
    nodes, inverse = np.unique(ids, return_inverse=True)
    summed = np.zeros((len(nodes), 3))
    np.add.at(summed, inverse.ravel(), corner.reshape(-1, 3))
    summed /= np.linalg.norm(summed, axis=1, keepdims=True)
    expected = summed[np.searchsorted(nodes, master.global_nodes)]
    error = comm.allreduce(np.abs(normals - expected).max(initial=0.0), MPI.MAX)
    case = f"smoothed normal, warped box top ({cell}), {comm.size} rank" + "s" * (comm.size > 1)
    quantity = "largest |nodal normal - sum of the corner normals of all ranks' facets|"
    verification(case, quantity, error, 0.0, "< 1e-14", DEFINITION, kind="consistency")
    assert error < 1e-14  # round-off: 1.4e-15 measured on 2 ranks
    assert comm.allreduce(len(normals), MPI.SUM) == (72 if nn == 3 else 36)  # 6 x 6 squares
    if comm.size > 1:  # every rank holds master facets, and fans reach the other's nodes
        mine = np.isin(master._ring, master.global_nodes)
        assert comm.allreduce(master.num_facets, MPI.MIN) > 0
        assert comm.allreduce(int(np.count_nonzero(~mine)), MPI.MIN) > 0


def fans_by_key(master: MeshMaster) -> np.ndarray:
    """The fans of the master's facets with their nodes named by input index."""
    comm = master.V.mesh.comm
    ids = np.concatenate(comm.allgather(master.global_nodes.astype(np.int64).ravel()))
    keys = np.concatenate(comm.allgather(master.node_keys.astype(np.int64).ravel()))
    ids, first = np.unique(ids, return_index=True)
    return keys[first][np.searchsorted(ids, master._ring)]


@across_ranks
@pytest.mark.parametrize("cell", ["tetrahedron", "hexahedron"])
def test_fans_are_the_same_on_any_number_of_ranks(cell, verification):
    """The fans start at partition-independent nodes: the fans (nodes named by input index,
    in order) and the nodal normals of the distributed surface are those of the same surface
    on one rank."""
    master, _, normals = warped_box_top(MPI.COMM_WORLD, cell)
    whole, _, whole_normals = warped_box_top(MPI.COMM_SELF, cell)
    order = np.lexsort(whole.node_keys.T[::-1])
    ordered = whole.node_keys[order]
    at = order[[np.flatnonzero((ordered == k).all(axis=1))[0] for k in master.node_keys]]
    assert np.array_equal(whole.node_keys[at], master.node_keys)
    assert np.array_equal(fans_by_key(whole)[at], fans_by_key(master))
    difference = np.abs(whole_normals[at] - normals).max(initial=0.0)
    difference = MPI.COMM_WORLD.allreduce(difference, MPI.MAX)
    case = f"smoothed normal, warped box top ({cell}), {MPI.COMM_WORLD.size} ranks"
    quantity = "largest |nodal normal - one rank's|"
    source = "the same surface on one rank"
    verification(case, quantity, difference, 0.0, "< 1e-14", source, kind="consistency")
    assert difference < 1e-14


def test_too_many_facets_around_a_node(monkeypatch):
    """The bound on the nodes carried to a slave point is named when exceeded."""
    monkeypatch.setattr(master_module, "MAX_FACETS_AROUND_NODE", 3)
    scene = curved_pair(3, cell="hexahedron")
    pair = dataclasses.replace(scene.contacts[0], master_normal="smoothed")
    with pytest.raises(ContactInputError, match="MAX_FACETS_AROUND_NODE = 3"):
        ContactProblem(dataclasses.replace(scene, contacts=[pair]), verbose=False)


def edge_jumps(problem, normal: str) -> np.ndarray:
    """The jump of the master normal across every interior edge of the (deformed) master
    surface: evaluated at a point of the edge from the facets on either side (all ranks)."""
    master, comm = problem.contacts[0].master, problem.comm
    nn = master.nn
    candidates = master.candidates(problem.full_layout)
    nodes = np.concatenate(comm.allgather(candidates.nodes))
    ids = np.concatenate(comm.allgather(master.global_nodes.astype(np.int64)))
    ref = REFERENCE_VERTICES[nn]
    keys, normals = [], []
    for a, b in FACET_EDGES[nn]:  # the point 0.3 of the way from the smaller node index
        lo = np.where(ids[:, a] < ids[:, b], a, b)
        hi = np.where(ids[:, a] < ids[:, b], b, a)
        xi = 0.7 * ref[lo] + 0.3 * ref[hi]
        if normal == "smoothed":
            normals.append(smoothed_normals_3d(xi, nodes, nn))
        else:
            dN = shape_functions(nn, 3, xi)[1]
            a1, a2 = (np.einsum("pa,pad->pd", dN[:, :, k], nodes[:, :nn]) for k in range(2))
            n = np.cross(a1, a2)
            normals.append(n / np.linalg.norm(n, axis=1, keepdims=True))
        keys.append(np.sort(ids[:, [a, b]], axis=1))
    keys, normals = np.concatenate(keys), np.concatenate(normals)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    shared = np.flatnonzero(counts[inverse.ravel()] == 2)
    order = shared[np.argsort(inverse.ravel()[shared], kind="stable")]
    first, second = normals[order[0::2]], normals[order[1::2]]
    assert len(first) > 20
    return np.linalg.norm(first - second, axis=1)


@pytest.mark.serial  # 2 ranks: test_taylor's smoothed 3D normal, the fans' gather test
@pytest.mark.parametrize("cell", ["tetrahedron", "hexahedron"])
def test_smoothed_normal_is_continuous_across_edges(cell, verification):
    """At a point of an edge the two facets sharing it give the same smoothed normal (they
    interpolate the same nodal normals along it); their facet normals differ (the surface
    is deformed and curved)."""
    problem = curved_case(3, master_normal="smoothed", cell=cell)[0]
    jump = edge_jumps(problem, "smoothed").max()
    case = f"smoothed normal, deformed curved master ({cell})"
    quantity = "largest jump of the normal across a facet edge"
    source = "the smoothed normal's definition: continuous from facet to facet"
    verification(case, quantity, jump, 0.0, "< 1e-15", source, kind="consistency")
    assert jump < 1e-15  # round-off
    assert edge_jumps(problem, "facet").max() > 1e-2


@pytest.mark.serial  # 2 ranks: test_taylor's smoothed 3D normal, the fans' gather test
@pytest.mark.parametrize("cell", ["tetrahedron", "hexahedron"])
def test_smoothed_normal_twin_is_the_ufl_normal(cell, verification):
    """The search's NumPy normal (the pairing's, for results) is the UFL normal of the forms,
    and it is not the facet normal."""
    problem = curved_case(3, master_normal="smoothed", cell=cell)[0]
    c = problem.contacts[0]
    k, slave = c.kinematics, c.slave
    twin = dolfinx.fem.Function(slave.point_space((3,)))
    slave.set_at_points(twin, c.projection.normal)
    facet = dolfinx.fem.Function(slave.point_space((3,)))
    slave.set_at_points(facet, curved_case(3, cell=cell)[0].contacts[0].projection.normal)

    def integral(f):
        form = dolfinx.fem.form(
            k.mask * ufl.dot(k.nu - f, k.nu - f) * slave.ds, entity_maps=[slave.entity_map]
        )
        return problem.comm.allreduce(dolfinx.fem.assemble_scalar(form), MPI.SUM)

    mismatch = np.sqrt(integral(twin))
    case = f"smoothed normal, deformed curved master ({cell})"
    quantity = "L2 norm of the UFL normal minus the NumPy normal on the slave surface"
    source = "the search's NumPy normal and the forms' UFL normal (two implementations)"
    verification(case, quantity, mismatch, 0.0, "< 1e-15", source, kind="consistency")
    assert mismatch < 1e-15  # round-off
    assert integral(facet) > 1e-6


def test_default_master_normal_rule():
    """``master_normal=None`` (the default) is the smoothed normal on a 2D solid master of
    a degree-1 displacement, the facet normal in 3D, with degree 2, on a membrane, in
    self-contact and on an obstacle; an explicit choice is kept."""
    pair = ContactPair(1, 2)
    assert pair.master_normal is None
    assert pair.resolved_master_normal(2, 1, False) == "smoothed"
    assert pair.resolved_master_normal(3, 1, False) == "facet"
    assert pair.resolved_master_normal(2, 2, False) == "facet"
    assert pair.resolved_master_normal(2, 1, True) == "facet"
    assert ContactPair(1, 1).resolved_master_normal(2, 1, False) == "facet"
    plane = RigidPlane((0.0, 0.0), (0.0, 1.0))
    assert ContactPair(1, plane).resolved_master_normal(2, 1, False) == "facet"
    for normal in ("facet", "smoothed"):
        explicit = ContactPair(1, 2, master_normal=normal)
        assert explicit.resolved_master_normal(2, 1, False) == normal
        assert explicit.resolved_master_normal(3, 1, False) == normal
    with pytest.raises(
        ContactInputError, match="master_normal must be 'facet', 'smoothed' or None"
    ):
        ContactPair(1, 2, master_normal="nodal").validate(MPI.COMM_WORLD)


@pytest.mark.serial  # on 2 ranks: this file's rank comparisons
@pytest.mark.parametrize("dim, expected", [(2, "smoothed"), (3, "facet")])
def test_default_master_normal_of_a_problem(dim, expected):
    """A problem resolves the default: its pair has the smoothed normal in 2D (gathering the
    two neighbours of each segment: 4 nodes a point) and the facet normal in 3D."""
    problem = ContactProblem(curved_pair(dim), verbose=False)
    contact = problem.contacts[0]
    assert contact.pair.master_normal == expected
    assert contact.master.smoothed == (expected == "smoothed")
    assert contact.master.nx == (4 if dim == 2 else contact.master.nn)
