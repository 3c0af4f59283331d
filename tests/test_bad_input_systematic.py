"""Invalid input tried systematically: each case gives a ContactInputError naming the problem
(the group, the parameter, the value), on every rank at once, when the scene, the material,
the problem or the search is made; never a hang, a crash or a silent wrong answer.

Runs on 1 and 2 ranks: every rank makes the same bad input and must raise the same error.
"""

import dataclasses
import time
import warnings

import basix.ufl
import dolfinx
import numpy as np
import pytest
from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.contact.search import closest_points
from contact_ufl.errors import ContactInputError, CrackWarning
from contact_ufl.loads import (
    BodyForce,
    DeadForce,
    DeadTraction,
    Dirichlet,
    FollowerForce,
    FollowerPressure,
)
from contact_ufl.materials import LinearElastic, NeoHookean, SaintVenantKirchhoff
from contact_ufl.membranes import MembraneCompressibleNeoHookean, MembraneNeoHookean, MembraneSVK
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Body, Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.geometries import tag_single_body

NAN, INF = float("nan"), float("inf")
SOLID = NeoHookean(1.0, 0.3)


# -- the scenes the bad input goes into ---------------------------------------------------------


def patch(data=None, bodies=None, contacts=None, dirichlet=None, loads=None) -> Scene:
    """The 2D patch test (two stacked blocks, groups by name) with one part replaced."""
    return Scene.from_mesh_data(
        data or geometries.patch_2d(),
        bodies=bodies or [Body("upper", SOLID), Body("lower", SOLID)],
        contacts=contacts or [ContactPair("upper_contact", "lower_contact", eps_N=10.0)],
        dirichlet=dirichlet
        or [Dirichlet("lower_bottom", (0.0, 0.0)), Dirichlet("upper_left", 0.0, component=0)],
        loads=loads or [DeadTraction("upper_top", lambda t: (0.0, -0.01 * t))],
    )


def problem(scene: Scene) -> ContactProblem:
    return ContactProblem(scene, verbose=False)


def with_empty_groups():
    """The patch's mesh data with a facet group 'empty_facets' (tag 99) and a cell group
    'empty_cells' (tag 42) that exist by name but hold no entities."""
    data = geometries.patch_2d()
    groups = dict(data.groups, empty_facets=(1, 99), empty_cells=(2, 42))
    return dataclasses.replace(data, groups=groups)


def pair(**changes) -> Scene:
    return patch(contacts=[ContactPair("upper_contact", "lower_contact", **changes)])


def mesh_on_rank_0(cells, x, cell: str, gdim: int | None = None) -> dolfinx.mesh.Mesh:
    """The P1 mesh of ``cells`` and the points ``x``, given on rank 0 and distributed with
    shared-facet ghosts."""
    cells, x = np.asarray(cells, dtype=np.int64), np.asarray(x, dtype=float)
    gdim = gdim or x.shape[1]
    if MPI.COMM_WORLD.rank != 0:
        cells, x = np.empty((0, cells.shape[1]), np.int64), np.empty((0, gdim))
    element = basix.ufl.element("Lagrange", cell, 1, shape=(gdim,))
    partitioner = dolfinx.mesh.create_cell_partitioner(dolfinx.mesh.GhostMode.shared_facet, 2)
    return dolfinx.mesh.create_mesh(MPI.COMM_WORLD, cells, element, x, partitioner=partitioner)


def one_body(mesh, material=SOLID) -> Scene:
    """One body on ``mesh`` (cell tag 1), held on its facets at y = 0 (facet tag 1)."""
    cells, facets = tag_single_body(mesh, [lambda x: np.isclose(x[1], 0.0)])
    held = Dirichlet(1, (0.0,) * mesh.geometry.dim)
    return Scene(mesh, cells, facets, [Body(1, material)], dirichlet=[held])


def grid(nx: int, ny: int) -> tuple[np.ndarray, np.ndarray]:
    """The nodes of an ``nx`` x ``ny`` grid on [0, nx] x [0, ny] and its quadrilaterals
    (vertices in DOLFINx's tensor-product order)."""
    X, Y = np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0))
    x = np.stack([X.ravel(), Y.ravel()], axis=1)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny)))
    n0 = j * (nx + 1) + i
    return np.stack([n0, n0 + 1, n0 + nx + 1, n0 + nx + 2], axis=1), x


def triangles(nx: int, ny: int) -> tuple[np.ndarray, np.ndarray]:
    """The grid of :func:`grid` with each square split into two triangles."""
    quads, x = grid(nx, ny)
    return np.concatenate([quads[:, [0, 1, 3]], quads[:, [0, 3, 2]]]), x


def bad_coordinates(value: float):
    """The patch with one node of each rank's part at ``value``."""
    data = geometries.patch_2d()
    data.mesh.geometry.x[0, 0] = value
    return problem(patch(data))


def twisted_quadrilateral():
    """Two quadrilaterals, the first with two vertices swapped: a bow tie."""
    cells, x = grid(2, 1)
    cells[0] = cells[0][[0, 1, 3, 2]]
    return problem(one_body(mesh_on_rank_0(cells, x, "quadrilateral")))


def folded_triangles():
    """A 2 x 2 triangle grid with its centre node moved across its neighbours' edges."""
    cells, x = triangles(2, 2)
    x[4] = (2.5, 1.2)
    return problem(one_body(mesh_on_rank_0(cells, x, "triangle")))


def flat_triangle():
    """A triangle and, beside it, one with its three vertices on a line (zero area)."""
    x = np.array([[0, 0], [1, 0], [2, 0], [0.5, 1], [1.5, 0]])
    return problem(one_body(mesh_on_rank_0([[0, 1, 3], [1, 2, 4]], x, "triangle")))


def flat_tetrahedron():
    """Two tetrahedra, the second with its four vertices in one plane."""
    x = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0.0]], dtype=float)
    return problem(one_body(mesh_on_rank_0([[0, 1, 2, 3], [0, 1, 2, 4]], x, "tetrahedron")))


def surface_in_3d_as_solid():
    """A triangle mesh in 3D given a solid material."""
    cells, x = triangles(2, 2)
    x3 = np.column_stack([x, np.zeros(len(x))])
    return problem(one_body(mesh_on_rank_0(cells, x3, "triangle"), SOLID))


def solid_as_membrane():
    mesh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
    return problem(one_body(mesh, MembraneNeoHookean(1.0, 0.01)))


def line_as_solid():
    mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_WORLD, 4)
    cells, facets = tag_single_body(mesh, [lambda x: np.isclose(x[0], 0.0)])
    return problem(Scene(mesh, cells, facets, [Body(1, SOLID)], dirichlet=[Dirichlet(1, 0.0)]))


POINTS = np.array([[0.5, 0.1], [1.5, -0.2]])
SEGMENTS = np.array([[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [2.0, 0.0]]])


def with_value(array: np.ndarray, value: float) -> np.ndarray:
    bad = array.copy()
    bad.flat[1] = value
    return bad


def at_zero(value):
    """A callable of t that is ``value`` at t = 0 (finite later)."""
    return lambda t: value if t == 0.0 else (0.0, 0.0)


# -- the cases: (what is made, the message's regex) ------------------------------------------

NAMES = [
    (
        lambda: patch(contacts=[ContactPair("nonexistent", "lower_contact")]),
        r"contact pair 0, slave surface: no physical group is named 'nonexistent'; cell groups",
        "unknown-slave",
    ),
    (
        lambda: patch(contacts=[ContactPair("uper_contact", "lower_contact")]),
        r"slave surface: .*'uper_contact'.*; did you mean 'upper_contact'\?",
        "mistyped-slave",
    ),
    (
        lambda: patch(contacts=[ContactPair("upper_contact", "lower_contat")]),
        r"master surface: .*'lower_contat'.*; did you mean 'lower_contact'\?",
        "mistyped-master",
    ),
    (
        lambda: patch(dirichlet=[Dirichlet("lower_botom", (0.0, 0.0))]),
        r"Dirichlet 'lower_botom'.*did you mean 'lower_bottom'\?",
        "mistyped-dirichlet",
    ),
    (
        lambda: patch(loads=[DeadTraction("upper_tpo", (0.0, -0.01))]),
        r"DeadTraction 'upper_tpo'.*did you mean 'upper_top'\?",
        "mistyped-load",
    ),
    (
        lambda: patch(bodies=[Body("uper", SOLID), Body("lower", SOLID)]),
        r"body 'uper'.*did you mean 'upper'\?",
        "mistyped-body",
    ),
    (
        lambda: patch(bodies=[Body("upper_top", SOLID), Body("lower", SOLID)]),
        r"body 'upper_top'.*physical group 'upper_top' has dimension 1 .*a cell group",
        "body-on-facet-group",
    ),
    (
        lambda: patch(dirichlet=[Dirichlet("lower", (0.0, 0.0))]),
        r"Dirichlet 'lower'.*physical group 'lower' has dimension 2 .*a facet group",
        "dirichlet-on-cell-group",
    ),
    (
        lambda: patch(contacts=[ContactPair("upper", "lower_contact")]),
        r"slave surface: physical group 'upper' has dimension 2",
        "slave-on-cell-group",
    ),
    (
        lambda: patch(loads=[BodyForce("upper_top", (0.0, -1.0))]),
        r"BodyForce 'upper_top'.*physical group 'upper_top' has dimension 1 .*a cell group",
        "body-force-on-facet-group",
    ),
]

EMPTY = [
    (
        lambda: problem(patch(with_empty_groups(), dirichlet=[Dirichlet("empty_facets", 0.0)])),
        r"Dirichlet: facet tag 99 does not exist or has no facets \(physical group "
        r"'empty_facets'\)",
        "empty-dirichlet-group",
    ),
    (
        lambda: problem(patch(with_empty_groups(), loads=[DeadForce("empty_facets", (0.0, -1.0))])),
        r"DeadForce: facet tag 99 does not exist or has no facets \(physical group "
        r"'empty_facets'\)",
        "empty-load-group",
    ),
    (
        lambda: problem(
            patch(with_empty_groups(), contacts=[ContactPair("empty_facets", "lower_contact")])
        ),
        r"contact pair 0, slave surface: facet tag 99 \(physical group 'empty_facets'\) is empty",
        "empty-slave-group",
    ),
    (
        lambda: problem(
            patch(with_empty_groups(), contacts=[ContactPair("upper_contact", "empty_facets")])
        ),
        r"contact pair 0, master surface: facet tag 99 \(physical group 'empty_facets'\) is empty",
        "empty-master-group",
    ),
    (
        lambda: problem(
            patch(with_empty_groups(), bodies=[Body("empty_cells", SOLID), Body("lower", SOLID)])
        ),
        r"body empty_cells: cell tag 42 \(physical group 'empty_cells'\) has no cells",
        "empty-body-group",
    ),
    (
        lambda: problem(patch(with_empty_groups(), loads=[BodyForce("empty_cells", (0.0, 1.0))])),
        r"BodyForce: cell tag 42 does not exist or has no cells \(physical group 'empty_cells'\)",
        "empty-body-force-group",
    ),
]

MATERIALS = [
    (lambda: NeoHookean(NAN, 0.3), r"Young's modulus must be positive and finite, got E = nan"),
    (lambda: NeoHookean(INF, 0.3), r"Young's modulus must be positive and finite, got E = inf"),
    (lambda: NeoHookean(1.0, NAN), r"Poisson's ratio must lie in \(-1, 0.5\), got nu = nan"),
    (lambda: SaintVenantKirchhoff(-INF, 0.3), r"got E = -inf"),
    (lambda: SaintVenantKirchhoff(1.0, INF), r"got nu = inf"),
    (lambda: LinearElastic(NAN, 0.3), r"got E = nan"),
    (lambda: LinearElastic(1.0, -1.0), r"got nu = -1.0"),
    (lambda: J2Plasticity(1.0, 0.3, NAN), r"yield stress must be .*yield_stress = nan"),
    (lambda: J2Plasticity(1.0, 0.3, INF), r"yield stress must be .*yield_stress = inf"),
    (lambda: J2Plasticity(1.0, 0.3, 0.01, NAN), r"hardening modulus .*hardening = nan"),
    (lambda: J2Plasticity(1.0, 0.3, 0.01, INF), r"hardening modulus .*hardening = inf"),
    (lambda: J2Plasticity(INF, 0.3, 0.01), r"got E = inf"),
    (lambda: MembraneNeoHookean(NAN, 0.01), r"mu must be positive and finite, got mu = nan"),
    (lambda: MembraneNeoHookean(1.0, 0.0), r"thickness must be .*thickness = 0.0"),
    (lambda: MembraneSVK(1.0, 0.3, -0.01), r"thickness must be .*thickness = -0.01"),
    (lambda: MembraneSVK(1.0, NAN, 0.01), r"got nu = nan"),
    (lambda: MembraneCompressibleNeoHookean(INF, 0.3, 0.01), r"E must be .*got E = inf"),
    (lambda: MembraneCompressibleNeoHookean(1.0, 0.3, INF), r"thickness = inf"),
]

LOADS = [
    (
        DeadTraction("upper_top", (NAN, -0.01)),
        r"DeadTraction 'upper_top' \(tag \d+\): the value at t = 0 is not finite: \[nan, ",
    ),
    (DeadForce("upper_top", (INF, 0.0)), r"DeadForce 'upper_top' .*not finite: \[inf, 0.0\]"),
    (
        BodyForce("upper", at_zero((0.0, NAN))),
        r"BodyForce 'upper' \(tag \d+\): the value at t = 0 is not finite",
    ),
    (FollowerPressure("upper_top", NAN), r"FollowerPressure 'upper_top' .*not finite: nan"),
    (FollowerForce("upper_top", INF, (0.0, -1.0)), r"FollowerForce 'upper_top' .*finite: inf"),
    (
        FollowerForce("upper_top", 1.0, (NAN, -1.0)),
        r"direction must be a nonzero vector of dimension 2, got \(nan, -1.0\)",
    ),
]

PRESCRIBED = [
    (Dirichlet("lower_bottom", (NAN, 0.0)), r"'lower_bottom' \(tag \d+\).*not finite"),
    (Dirichlet("lower_bottom", INF, component=1), r"'lower_bottom' .*not finite: inf"),
    (Dirichlet("lower_bottom", at_zero((0.0, NAN))), r"'lower_bottom' .*not finite"),
    (
        Dirichlet("lower_bottom", lambda t, x: np.full(x.shape, INF)),
        r"'lower_bottom' \(tag \d+\): value\(0, x\) is not finite",
    ),
]

MESHES = [
    (lambda: bad_coordinates(NAN), r"mesh nodes have non-finite coordinates .*nan", "nan-node"),
    (lambda: bad_coordinates(INF), r"mesh nodes have non-finite coordinates .*inf", "inf-node"),
    (twisted_quadrilateral, r"1 cells of the mesh are turned inside out", "twisted-quad"),
    (folded_triangles, r"the mesh folds over itself: \d+ facets", "folded-triangles"),
    (flat_triangle, r"1 cells of the mesh are flat \(zero area or volume\)", "flat-triangle"),
    (flat_tetrahedron, r"1 cells of the mesh are flat", "flat-tetrahedron"),
    (
        surface_in_3d_as_solid,
        r"solid bodies need a 2D \(plane strain\) or 3D mesh of full dimension; got "
        r"topological dimension 2 in 3D",
        "surface-as-solid",
    ),
    (
        solid_as_membrane,
        r"membrane bodies need a membrane mesh .*topological dimension 2 in 2D",
        "solid-as-membrane",
    ),
    (line_as_solid, r"solid bodies need a 2D \(plane strain\) or 3D mesh, got 1D", "line-as-solid"),
]

PARAMETERS = [
    (dict(mu=-0.1), r"mu must be >= 0 and finite, got mu = -0.1"),
    (dict(mu=NAN), r"got mu = nan"),
    (dict(mu=INF), r"got mu = inf"),
    (dict(eps_N=0.0), r"eps_N must be positive, got eps_N = 0.0"),
    (dict(eps_N=-1.0), r"eps_N = -1.0"),
    (dict(eps_N=NAN), r"eps_N = nan"),
    (dict(eps_N=INF), r"eps_N = inf"),
    (dict(mu=0.3, eps_T=-1.0), r"eps_T must be positive, got eps_T = -1.0"),
    (dict(mu=0.3, eps_T=NAN), r"eps_T = nan"),
    (dict(search_radius=0.0), r"search_radius must be positive, got search_radius = 0.0"),
    (dict(search_radius=NAN), r"search_radius = nan"),
    (dict(overlap_ramp=-1.0), r"overlap_ramp = -1.0"),
    (dict(quadrature_subdivisions=0), r"quadrature_subdivisions must be >= 1, got 0"),
]

SEARCH = [
    ((POINTS, with_value(SEGMENTS, NAN)), r"the master nodes .* non-finite .*: 1 of 2"),
    ((POINTS, with_value(SEGMENTS, INF)), r"the master nodes .* non-finite"),
    ((with_value(POINTS, NAN), SEGMENTS), r"the slave points .* non-finite .*: 1 of 2"),
    ((POINTS, SEGMENTS[0]), r"nodes must have shape \(nf, nodes_per_facet, gdim\), got \(2, 2\)"),
    ((POINTS, SEGMENTS[..., :1]), r"unsupported master facet: 2 nodes in 1D"),
    ((POINTS, np.zeros((2, 5, 2))), r"unsupported master facet: 5 nodes in 2D"),
    ((np.zeros((2, 3)), SEGMENTS), r"points must have shape \(np, 2\), got \(2, 3\)"),
    ((POINTS[0], SEGMENTS), r"points must have shape \(np, 2\), got \(2,\)"),
    ((POINTS, [[[0.0, 0.0], [1.0]]]), r"nodes must be an array of numbers"),
    ((POINTS, SEGMENTS, NAN), r"radius must be non-negative, got nan"),
    ((POINTS, SEGMENTS, -1.0), r"radius must be non-negative, got -1.0"),
]


def search(args, backend):
    return lambda: closest_points(*args, backend=backend)


CASES = [pytest.param(make, message, id=name) for make, message, name in NAMES + EMPTY + MESHES]
CASES += [
    pytest.param(make, message, id=f"material-{k}") for k, (make, message) in enumerate(MATERIALS)
]
CASES += [
    pytest.param(lambda load=load: problem(patch(loads=[load])), message, id=f"load-{k}")
    for k, (load, message) in enumerate(LOADS)
]
CASES += [
    pytest.param(lambda bc=bc: problem(patch(dirichlet=[bc])), message, id=f"dirichlet-{k}")
    for k, (bc, message) in enumerate(PRESCRIBED)
]
CASES += [
    pytest.param(lambda c=changes: problem(pair(**c)), message, id=f"pair-{k}")
    for k, (changes, message) in enumerate(PARAMETERS)
]
CASES += [
    pytest.param(search(args, backend), message, id=f"search-{backend}-{k}")
    for backend in ("compiled", "numpy")
    for k, (args, message) in enumerate(SEARCH)
]


@pytest.mark.parametrize("make, message", CASES)
def test_bad_input_is_refused_on_every_rank(make, message):
    """Every rank raises a ContactInputError whose message matches, within seconds."""
    comm = MPI.COMM_WORLD
    start = time.perf_counter()
    try:
        make()
        raised: Exception | None = None
    except Exception as error:  # any error is gathered: no rank leaves the others waiting
        raised = error
    elapsed = comm.allreduce(time.perf_counter() - start, MPI.MAX)
    errors = comm.allgather(None if raised is None else (type(raised).__name__, str(raised)))
    for error in errors:
        assert error is not None and error[0] == "ContactInputError", errors
    assert errors.count(errors[0]) == len(errors), errors  # the same error on every rank
    assert isinstance(raised, ContactInputError)
    with pytest.raises(ContactInputError, match=message):
        raise raised
    assert elapsed < 10.0


@pytest.mark.parametrize("backend", ["compiled", "numpy"])
def test_an_empty_master_leaves_every_point_unpaired(backend):
    """An empty set of master facets is not an error at the search (a rank whose points are
    far from the master gets none): every point is unpaired, at infinite distance. An empty
    master *surface* is refused when the problem is made (the cases above)."""
    proj = closest_points(POINTS, np.zeros((0, 2, 2)), backend=backend)
    assert np.all(proj.facet == -1) and np.all(np.isinf(proj.distance))


def test_a_crack_within_one_body_warns_and_touching_bodies_do_not():
    """Two triangles of one body meeting at coincident but distinct nodes (a cut nobody
    asked for) warn, naming the body; the same two triangles as two bodies (touching at the
    start: legitimate) do not, and neither does a triangle mesh whatever the vertex order
    of its cells (the orientation of a simplex is no error)."""
    x = np.array([[0, 0], [1, 0], [0, 1], [1, 0], [0, 1], [1, 1.0]])
    cells = np.array([[0, 1, 2], [3, 5, 4]])
    mesh = mesh_on_rank_0(cells, x, "triangle")
    with pytest.warns(CrackWarning, match=r"4 boundary nodes of body on tag 1 coincide"):
        one_body(mesh).validate()
    tdim = mesh.topology.dim
    local = np.arange(mesh.topology.index_map(tdim).size_local, dtype=np.int32)
    centre = dolfinx.mesh.compute_midpoints(mesh, tdim, local)
    values = np.where(centre[:, 0] + centre[:, 1] < 1.0, 1, 2).astype(np.int32)
    cell_tags = dolfinx.mesh.meshtags(mesh, tdim, local, values)
    _, facets = tag_single_body(mesh, [lambda x: np.isclose(x[1], 0.0)])
    bodies = [Body(1, SOLID), Body(2, SOLID)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Scene(mesh, cell_tags, facets, bodies, dirichlet=[Dirichlet(1, (0.0, 0.0))]).validate()
        cells, x = triangles(2, 2)
        cells[::2] = cells[::2][:, [0, 2, 1]]  # reverse every other triangle
        one_body(mesh_on_rank_0(cells, x, "triangle")).validate()
