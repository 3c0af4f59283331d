"""The partition of a multi-body mesh: every body split over all the ranks."""

from pathlib import Path

import dolfinx
import numpy as np
import numpy.typing as npt
import pytest
import scipy.sparse
from conftest import across_ranks
from mpi4py import MPI

from contact_ufl import gmshio
from contact_ufl.contact import ContactPair
from contact_ufl.errors import ContactInputError
from contact_ufl.gmshio import PARTITION_VARIABLE
from contact_ufl.materials import LinearElastic
from contact_ufl.partition import body_partitioner, surface_cells
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Body, Scene
from contact_ufl.verification.geometries import sphere_on_block_3d
from contact_ufl.verification.scenes import hertz_3d, patch

PRESSURE = 0.01
TIGHT = {"snes_rtol": 1e-13, "snes_atol": 1e-15}


def dual_graph(mesh: dolfinx.mesh.Mesh) -> scipy.sparse.csr_array:
    """Cells joined by a shared facet (this rank's cells, serial)."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    inner = np.flatnonzero(np.diff(f2c.offsets) == 2)
    a, b = f2c.array[f2c.offsets[inner]], f2c.array[f2c.offsets[inner] + 1]
    n = mesh.topology.index_map(tdim).size_local
    ones = np.ones(2 * len(a))
    return scipy.sparse.coo_array((ones, (np.r_[a, b], np.r_[b, a])), (n, n)).tocsr()


def adjacency_list(graph: scipy.sparse.csr_array) -> dolfinx.cpp.graph.AdjacencyList_int64:
    """The graph as the adjacency list a DOLFINx graph partitioner takes."""
    return dolfinx.cpp.graph.AdjacencyList_int64(
        graph.indices.astype(np.int64), graph.indptr.astype(np.int32)
    )


@pytest.mark.serial
@pytest.mark.parametrize("nparts", [2, 3])
def test_body_partitioner_splits_every_body(nparts):
    """On the serial 3D patch mesh: each body, and the slave and master surfaces, are
    shared by every part within 30%; a ghost goes to exactly the other parts of the cell's
    facet neighbours."""
    scene = patch(3, PRESSURE, quadrature_degree=2, subdivisions=1, cell="tetrahedron")
    graph = dual_graph(scene.mesh)
    adjacency = adjacency_list(graph)
    dest = body_partitioner()(MPI.COMM_SELF, nparts, adjacency, True)
    offsets, data = np.asarray(dest.offsets), np.asarray(dest.array)
    owner = data[offsets[:-1]]
    f2c = scene.mesh.topology.connectivity(2, 3)
    pair = scene.contacts[0]
    for tags, cells_of in (
        (scene.cell_tags, lambda idx: idx),
        (scene.facet_tags, lambda idx: f2c.array[f2c.offsets[idx]]),
    ):
        for tag in (*[b.tag for b in scene.bodies], pair.slave, pair.master):
            idx = tags.indices[tags.values == tag]
            if len(idx) == 0:
                continue
            count = np.bincount(owner[cells_of(idx)], minlength=nparts)
            assert count.min() > 0.7 * len(idx) / nparts, (tag, count)
    for cell in np.flatnonzero(np.diff(offsets) > 1)[:50]:
        neighbours = graph.indices[graph.indptr[cell] : graph.indptr[cell + 1]]
        expected = np.setdiff1d(owner[neighbours], [owner[cell]])
        assert np.array_equal(data[offsets[cell] + 1 : offsets[cell + 1]], expected)


def contact_cells(scene) -> dict[int, npt.NDArray[np.int32]]:
    """The cells (serial mesh) of each contact facet group of the scene's pair."""
    f2c = scene.mesh.topology.connectivity(scene.mesh.topology.dim - 1, scene.mesh.topology.dim)
    pair = scene.contacts[0]
    tags = scene.facet_tags
    return {
        key: f2c.array[f2c.offsets[tags.indices[tags.values == key]]]
        for key in (pair.slave, pair.master)
    }


@pytest.mark.serial
@pytest.mark.parametrize("nparts", [2, 3])
def test_contact_surfaces_are_split_evenly(nparts):
    """3D Hertz, coarse: the plain bodies split (each body cut where SCOTCH cuts it least)
    puts the ball's contact cap on one part and the block's contact face on another; with
    the contact cells marked, every part gets an equal share (within 10%) of each body and
    of each contact surface."""
    scene = hertz_3d(h_contact=0.05).scene
    graph = dual_graph(scene.mesh)
    adjacency = adjacency_list(graph)
    surfaces = contact_cells(scene)
    on_surface = np.zeros(graph.shape[0], dtype=bool)
    for cells in surfaces.values():
        on_surface[cells] = True

    def shares(partitioner) -> list[npt.NDArray[np.int64]]:
        dest = partitioner(MPI.COMM_SELF, nparts, adjacency, False)
        owner = np.asarray(dest.array)
        bodies = [scene.cell_tags.find(b.tag) for b in scene.bodies]
        return [np.bincount(owner[c], minlength=nparts) for c in (*bodies, *surfaces.values())]

    plain = shares(body_partitioner())
    assert max(c.max() / c.mean() for c in plain[2:]) > 1.5, plain  # the case worth testing
    for count in shares(body_partitioner(on_surface=on_surface)):
        assert count.max() <= 1.1 * count.mean() and count.min() >= 0.9 * count.mean(), count


@pytest.mark.serial
@pytest.mark.parametrize("nparts", [2, 3])
def test_each_contact_surface_of_a_body_is_split_evenly(nparts):
    """A body with two contact surfaces (the 3D Hertz block's top and bottom faces): marked
    as one surface, SCOTCH's split of the pair gives a part more than its share of one face;
    marked as two, every part gets an equal share (within 10%) of each."""
    scene = hertz_3d(h_contact=0.05).scene
    graph = dual_graph(scene.mesh)
    adjacency = adjacency_list(graph)
    f2c = scene.mesh.topology.connectivity(2, 3)
    faces = [
        f2c.array[f2c.offsets[scene.facet_tags.find(scene.tags[name])]]
        for name in ("block_contact", "block_bottom")
    ]

    def shares(labels: list[int]) -> list[npt.NDArray[np.int64]]:
        on_surface = np.zeros(graph.shape[0], dtype=np.int32)
        for cells, label in zip(faces, labels, strict=True):
            on_surface[cells] = label
        dest = body_partitioner(on_surface=on_surface)(MPI.COMM_SELF, nparts, adjacency, False)
        owner = np.asarray(dest.array)
        return [np.bincount(owner[cells], minlength=nparts) for cells in faces]

    union = shares([1, 1])
    assert max(c.max() / c.mean() for c in union) > 1.2, union  # the case worth testing
    for count in shares([1, 2]):
        assert count.max() <= 1.1 * count.mean() and count.min() >= 0.9 * count.mean(), count


@pytest.mark.serial
def test_surface_cells_are_the_cells_of_the_contact_facets():
    """:func:`surface_cells` finds, from vertex numbers alone, the cells of the facets given
    by their vertices (in any vertex order)."""
    scene = hertz_3d(h_contact=0.05).scene
    mesh = scene.mesh
    mesh.topology.create_connectivity(2, 0)
    c2v, f2v = mesh.topology.connectivity(3, 0), mesh.topology.connectivity(2, 0)
    surfaces = contact_cells(scene)
    facets = np.concatenate([scene.facet_tags.find(key) for key in surfaces])
    vertices = f2v.array.reshape(-1, 3)[facets][:, ::-1]
    labels = surface_cells([mesh.topology.cell_type], [c2v.array.astype(np.int64)], [[vertices]])
    expected = np.zeros(len(labels), dtype=np.int32)
    expected[np.concatenate(list(surfaces.values()))] = 1
    assert expected.sum() > 100 and np.array_equal(labels, expected)
    # one label per surface, the first for a cell on two
    slave, master = (f2v.array.reshape(-1, 3)[scene.facet_tags.find(key)] for key in surfaces)
    both = [[master], [slave], [master]]
    labels = surface_cells([mesh.topology.cell_type], [c2v.array.astype(np.int64)], both)
    cells = list(surfaces.values())
    assert set(labels[cells[0]]) == {2} and set(labels[cells[1]]) == {1}
    assert np.count_nonzero(labels) == len(np.unique(np.concatenate(cells)))


def test_unknown_partition_is_refused(monkeypatch):
    monkeypatch.setenv(PARTITION_VARIABLE, "metis")
    with pytest.raises(ContactInputError, match="CONTACT_UFL_PARTITION = 'metis' is unknown"):
        patch(2, PRESSURE)


#: The bound of the answers on all ranks (both partitions) against one rank's, relative:
#: solved to TIGHT, they differ by the round-off of factorisations of other orderings
#: (measured 9.0e-15 on the patch, 4.4e-15 on Hertz 3D, on 2 ranks).
TOL_RANKS = 5e-14


def summary(problem: ContactProblem) -> npt.NDArray[np.float64]:
    """The contact force, the multiplier's extremes and the displacement norm (the same on
    every rank; a rank may own no multiplier)."""
    comm = problem.comm
    lam = problem.contacts[0].lambda_N.x.array
    low, high = np.min(lam, initial=np.inf), np.max(lam, initial=-np.inf)
    u = problem.bulks[0].u.x.petsc_vec.norm()
    extremes = comm.allreduce(low, MPI.MIN), comm.allreduce(high, MPI.MAX)
    return np.array([*problem.contact_force(), *extremes, u])


def record_partitions(verification, case, partitions, alone) -> float:
    """Record the largest difference of the :func:`summary` of the runs on all ranks (each
    partition) from the run on one rank: the force over its norm, the others relative.
    Returns it."""
    dim = len(alone) - 3
    force = np.linalg.norm(alone[:dim])
    difference = max(
        max(
            np.linalg.norm(ours[:dim] - alone[:dim]) / force,
            *np.abs(ours[dim:] / alone[dim:] - 1.0),
        )
        for ours in partitions
    )
    quantity = "largest relative difference of F, min and max lambda_N, |u| (both partitions)"
    source = "the same scene on one rank"
    verification(case, quantity, difference, 0.0, TOL_RANKS, source, kind="consistency")
    return difference


def solve(monkeypatch, partition: str, comm=MPI.COMM_WORLD) -> ContactProblem:
    monkeypatch.setenv(PARTITION_VARIABLE, partition)
    scene = patch(2, PRESSURE, quadrature_degree=3, subdivisions=4, comm=comm)
    problem = ContactProblem(scene, verbose=False, petsc_options=TIGHT)
    problem.solve(num_steps=1)
    return problem


@across_ranks
def test_every_rank_owns_slave_points_and_answers_are_unchanged(monkeypatch, verification):
    """With the default partition every rank owns slave points of the patch scene (on two
    ranks DOLFINx's graph partition gives the whole slave body to one rank); the contact
    force, the multiplier's extremes and the displacement norm of either partition are
    those of one rank to solver tolerance (consistency)."""
    bodies, graph = solve(monkeypatch, "bodies"), solve(monkeypatch, "graph")
    comm = bodies.comm
    points = comm.allgather(len(bodies.contacts[0].projection.facet))
    assert min(points) > 0, points
    alone = summary(solve(monkeypatch, "bodies", MPI.COMM_SELF))
    case = f"patch 2D, quadrature degree 3, 4 subdivisions, {comm.size} ranks"
    difference = record_partitions(verification, case, [summary(bodies), summary(graph)], alone)
    assert difference <= TOL_RANKS


@across_ranks
def test_hertz_3d_slave_points_are_shared_evenly_and_answers_unchanged(monkeypatch, verification):
    """3D Hertz, coarse (the graph partition and the plain bodies split both put the ball's
    whole contact cap on one of two ranks): with the default partition every rank owns an
    equal share of the slave points (within 10%), and the contact force, the multiplier's
    extremes and the displacement norm of either partition are those of one rank to solver
    tolerance (consistency)."""

    def solve_hertz(partition: str, comm=MPI.COMM_WORLD) -> ContactProblem:
        monkeypatch.setenv(PARTITION_VARIABLE, partition)
        scene = hertz_3d(h_contact=0.05, comm=comm).scene
        problem = ContactProblem(scene, verbose=False, petsc_options=TIGHT)
        problem.solve(num_steps=1)
        return problem

    bodies, graph = solve_hertz("bodies"), solve_hertz("graph")
    comm = bodies.comm
    points = np.array(comm.allgather(len(bodies.contacts[0].projection.facet)))
    assert points.min() >= 0.9 * points.mean() and points.max() <= 1.1 * points.mean(), points
    alone = summary(solve_hertz("bodies", MPI.COMM_SELF))
    case = f"Hertz 3D, linear elastic, h_contact = 0.05, {comm.size} ranks"
    difference = record_partitions(verification, case, [summary(bodies), summary(graph)], alone)
    assert difference <= TOL_RANKS


def test_scene_from_gmsh_splits_its_pairs_surfaces_evenly(tmp_path):
    """``Scene.from_gmsh`` hands its pairs' facet groups to the partition: on the coarse 3D
    Hertz mesh read back from a file, every rank owns an equal share (within 10%) of the
    slave and of the master facets (counted by the owner of their cell)."""
    comm = MPI.COMM_WORLD
    path = Path(comm.bcast(str(tmp_path), root=0)) / "sphere_on_block.msh"
    sphere_on_block_3d(h_contact=0.05, h_far=0.25, master_ratio=1.0, msh_file=path, comm=comm)
    material = LinearElastic(1.0, 0.3)
    scene = Scene.from_gmsh(
        path,
        bodies=[Body("sphere", material, "sphere"), Body("block", material, "block")],
        contacts=[ContactPair("sphere_contact", "block_contact")],
    )
    mesh = scene.mesh
    mesh.topology.create_connectivity(2, 3)
    f2c = mesh.topology.connectivity(2, 3)
    owned = mesh.topology.index_map(3).size_local
    for name in ("sphere_contact", "block_contact"):
        cells = f2c.array[f2c.offsets[scene.facet_tags.find(scene.tags[name])]]
        count = np.array(comm.allgather(int(np.sum(cells < owned))))
        assert count.sum() > 50, (name, count)
        assert count.min() >= 0.9 * count.mean() and count.max() <= 1.1 * count.mean(), count


def test_a_failed_read_of_the_contact_facets_is_raised_on_every_rank(tmp_path, monkeypatch):
    """A gmsh error while the reading rank reads the contact surfaces' facets for the
    partition is a ``ContactInputError`` on every rank (no rank left waiting in the mesh's
    distribution)."""
    comm = MPI.COMM_WORLD
    path = Path(comm.bcast(str(tmp_path), root=0)) / "sphere_on_block.msh"
    sphere_on_block_3d(h_contact=0.1, h_far=0.3, master_ratio=1.0, msh_file=path, comm=comm)

    def broken(*args):
        raise RuntimeError("gmsh: unknown entity")

    monkeypatch.setattr(gmshio, "_facet_vertices", broken)
    with pytest.raises(ContactInputError, match="contact surfaces' facets.*unknown entity"):
        gmshio.read_gmsh(path, comm=comm, contact_surfaces=["sphere_contact"])
