"""Node-to-node oscillation of the contact multipliers in the 2D Hertz scene, one factor at a
time against the demo's default (``demos/hertz.py``), and in the 3D Hertz scene, P1 and P2.

The scene is the plane-strain Neo-Hookean half disc (R = 1, E = 1, nu = 0.3) pressed by
``depth`` = 0.005 (4 load steps) onto a block, the arc the slave surface, the library's
default ``eps_N``. The multiplier is read at its nodes, sorted along the slave surface, and
turned into a Cauchy pressure (times the nodal reference-over-current length ratio, each
node's two half segments); Hertz's solution (Johnson 1985, 4.2) is that of the computed
force. Per run:

``l2_error``
    ``||p_h - p||_L2 / (p0 sqrt(a))`` over ``|x| < 1.5 a`` (``p_h`` the piecewise linear
    interpolant of the nodal pressures along the current x, ``p0``, ``a`` Hertz's).
``osc``
    ``max |p_i - (p_{i-1} + p_{i+1}) / 2| / p0`` over the interior contact nodes (``i - 1``,
    ``i``, ``i + 1`` within ``|x| < a``): the second difference, as the brief defines it; it
    holds the smooth profile's own second difference, large next to the edge.
``osc_core``
    The same over ``|x| < 0.8 a``, of the error ``e_i = p_i - p(x_i)`` (the ellipse's own
    second difference removed): the oscillation of the discrete solution alone.
``osc_rms``
    The root mean square of those second differences, over ``p0`` (less sensitive than the
    largest to the number of nodes).
``alternation``
    Of the second differences of ``e`` over ``|x| < 0.8 a``, the fraction of neighbours of
    opposite sign (1: a pure zig-zag of period 2 nodes; about 0.5: noise; small: smooth).
``period``
    The wavelength (in slave node spacings) of the largest Fourier mode of ``e`` over
    ``|x| < 0.8 a`` (2: zig-zag; a master of spacing r h aliases to ``1 / |1/r - k|``).
``signs``
    The signs of those second differences, node by node.
``force_*``
    The same for the nodal contact force over the nodal length, ``(M lambda)_i / m_i``
    (``M`` the multipliers' mass matrix, ``m_i`` its row sums): the pressure a lumped (dual)
    multiplier basis reads from the same nodal forces (with the nodal ``lobatto`` rule the
    contact integrals lump ``M`` already: there it is ``lambda_N`` itself).
``recovered_*``
    The same measures for the L2 projection (consistent mass, onto the multiplier space) of
    the bulk traction ``nu . P N`` of the slave body (a post-processed traction, no
    multiplier involved), times the same length ratio.
``recovered_q6_*``, ``recovered_p2_*``, ``recovered_ufl_*``, ``recovered_p2_ufl_*``
    Local variants of it (:func:`projected_traction`): onto P1 with a degree-6 rule, onto
    Lagrange P2 of the slave surface (measured at the multiplier nodes, its vertices), and
    both with the stress of the displacement itself instead of the package's interpolated
    ``stress_field``; the P2 ones add ``osc_mid``, ``osc_mid_core``, ``osc_mid_rms``: the
    mid-side nodes' ``p_m - (p_a + p_b) / 2`` over their segment ``ab`` (see ``--dim 3``).

``--dim 3``: the 3D Hertz quarter model (:func:`run_3d`: linear elastic, so the nominal
pressure at the reference positions, as Hertz's small-strain solution compares), P1 and
P2 (``--degrees``; P2 on the curved mesh, the multipliers P1 unless
``--multiplier-degree 2``), one record per field (:data:`FIELDS_3D`, ``field``) and mesh:
``l2_error`` is ``||p_h - p||_L2 / (p0 sqrt(A))`` over ``r < 1.5 a`` of the field itself,
``A = pi a^2 / 4`` the quarter model's contact area; the oscillation is measured on the
slave surface mesh, ``|p_i - mean of its edge neighbours| / p0`` (in 2D the two neighbours:
the second difference above), ``osc`` the largest over the nodes in contact with their
neighbours, ``osc_core`` and ``osc_rms`` the largest and the rms of that of the error over
``r < 0.8 a`` (:func:`graph_oscillation`).

Variants (``--variants``, default all): ``default``; ``ratio0.5``, ``ratio1.0``,
``ratio2.0`` (master / slave size; 1.3 is the default); ``matching`` (ratio 1 with the same
contact-line nodes: the central parts of both contact curves, ``|x| < 0.15``, are
transfinite with the same x of their nodes); ``staggered`` (the same, the master's nodes
half a spacing off); ``sub4``, ``sub16`` (``quadrature_subdivisions``); ``qdeg7``
(``quadrature_degree``); ``lobatto`` (the 2-point Gauss-Lobatto rule, the slave nodes:
a nodal quadrature, i.e. a lumped multiplier mass and a node-to-segment gap),
``matching_lobatto`` (both); ``eps0.1``, ``eps10`` (``eps_N`` times the default); ``p2`` (P2
displacement on the curved mesh); ``swap`` (the block's top the slave, the coarser side);
``linear`` (small-strain linear elastic bulk); ``tiny`` (Neo-Hookean at depth 0.0005, h
scaled so that a / h is the same).

    python benchmarks/pressure_oscillation.py --json /tmp/zigzag/oscillation.json
    python benchmarks/pressure_oscillation.py --json ... --variants default matching --h 0.005
    python benchmarks/pressure_oscillation.py --dim 3 --json .../pressure_oscillation_3d.json
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import gmsh
import numpy as np
import resultfile
import ufl
from mpi4py import MPI

from contact_ufl import jit
from contact_ufl.contact import ContactPair
from contact_ufl.gmshio import generate_mesh
from contact_ufl.loads import Dirichlet
from contact_ufl.materials import LinearElastic, NeoHookean
from contact_ufl.problem import ContactProblem
from contact_ufl.results import recovered_pressure
from contact_ufl.scene import Body, Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.analytic import Hertz2D, plane_strain_modulus

R, E, NU = 1.0, 1.0, 0.3
DEPTH, STEPS = 0.005, 4
#: a / h about 5, 10, 20, 40 at DEPTH
H_LEVELS = [0.01, 0.005, 0.0025, 0.00125]
#: 3D meshes by displacement degree: h_contact, a / h about 3.4, 5.2, 8.2, 10 (P1) and
#: 2.9, 4.1, 5.2 (P2)
H_3D = {1: [0.03, 0.02, 0.0125, 0.01], 2: [0.035, 0.025, 0.02]}
#: the pressure fields of a 3D run: the multipliers, the nodal forces over the nodal areas,
#: the package's recovered pressure, and its local variants (:func:`projected_traction`)
FIELDS_3D = ("lambda", "force", "recovered", "recovered_p2", "recovered_ufl", "recovered_p2_ufl")
#: half-width of the transfinite central part of the contact curves (``matching``)
CENTRAL = 0.15
VARIANTS = {
    "default": {},
    "ratio0.5": {"ratio": 0.5},
    "ratio1.0": {"ratio": 1.0},
    "ratio2.0": {"ratio": 2.0},
    "matching": {"ratio": 1.0, "structured": "matching"},
    "staggered": {"ratio": 1.0, "structured": "staggered"},
    "sub4": {"subdivisions": 4},
    "sub16": {"subdivisions": 16},
    "qdeg7": {"quadrature_degree": 7},
    "lobatto": {"quadrature_rule": "lobatto", "quadrature_degree": 1},
    "matching_lobatto": {
        "ratio": 1.0,
        "structured": "matching",
        "quadrature_rule": "lobatto",
        "quadrature_degree": 1,
    },
    "eps0.1": {"eps_factor": 0.1},
    "eps10": {"eps_factor": 10.0},
    "p2": {"degree": 2},
    "swap": {"swap": True},
    "linear": {"material": "linear"},
    "tiny": {"depth": 0.0005, "h_scale": math.sqrt(0.1)},
}


# -- the mesh --------------------------------------------------------------------------
def _structured_build(h: float, kind: str) -> None:
    """The half disc on the block of :func:`geometries.hertz_2d` (ratio 1), the central parts
    ``|x| < CENTRAL`` of both contact curves transfinite with the same number of segments;
    the block's nodes then moved to the x of the disc's (``"matching"``) or half a spacing
    off (``"staggered"``) before the surfaces are meshed."""
    geo = gmsh.model.geo
    width, height, c = 4.0, 1.5, CENTRAL
    yc_c = R - math.sqrt(R * R - c * c)
    centre = geo.addPoint(0.0, R, 0.0)
    p_left, p_right = geo.addPoint(-R, R, 0.0), geo.addPoint(R, R, 0.0)
    a_left, a_right = geo.addPoint(-c, yc_c, 0.0), geo.addPoint(c, yc_c, 0.0)
    arcs = [
        geo.addCircleArc(p_left, centre, a_left),
        geo.addCircleArc(a_left, centre, a_right),
        geo.addCircleArc(a_right, centre, p_right),
    ]
    diameter = geo.addLine(p_right, p_left)
    disc = geo.addPlaneSurface([geo.addCurveLoop([*arcs, diameter])])
    q = [geo.addPoint(x, y, 0.0) for x, y in ((-2.0, -height), (2.0, -height), (2.0, 0.0))]
    q.append(geo.addPoint(-width / 2, 0.0, 0.0))
    b_right, b_left = geo.addPoint(c, 0.0, 0.0), geo.addPoint(-c, 0.0, 0.0)
    tops = [geo.addLine(q[2], b_right), geo.addLine(b_right, b_left), geo.addLine(b_left, q[3])]
    bottom, right, left = geo.addLine(q[0], q[1]), geo.addLine(q[1], q[2]), geo.addLine(q[3], q[0])
    block = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, *tops, left])])
    n = int(round(2.0 * math.asin(c / R) * R / h))
    geo.mesh.setTransfiniteCurve(arcs[1], n + 1)
    geo.mesh.setTransfiniteCurve(tops[1], n + 1)
    geo.synchronize()
    groups = [
        ("cylinder", 2, [disc]),
        ("block", 2, [block]),
        ("cylinder_contact", 1, arcs),
        ("cylinder_top", 1, [diameter]),
        ("block_contact", 1, tops),
        ("block_bottom", 1, [bottom]),
        ("block_sides", 1, [left, right]),
    ]
    next_tag = {2: 1, 1: 11}
    for name, dim, entities in groups:
        gmsh.model.addPhysicalGroup(dim, entities, tag=next_tag[dim], name=name)
        next_tag[dim] += 1
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", [geo.addPoint(0.0, 0.0, 0.0)])
    gmsh.model.geo.synchronize()
    sizes = []
    for surface in (disc, block):
        threshold = field.add("Threshold")
        for key, value in {
            "InField": distance,
            "SizeMin": h,
            "SizeMax": 0.2,
            "DistMin": 0.3 * R,
            "DistMax": 1.3 * R,
        }.items():
            field.setNumber(threshold, key, value)
        restrict = field.add("Restrict")
        field.setNumber(restrict, "InField", threshold)
        field.setNumbers(restrict, "SurfacesList", [surface])
        field.setNumber(restrict, "IncludeBoundary", 1)
        sizes.append(restrict)
    smallest = field.add("Min")
    field.setNumbers(smallest, "FieldsList", sizes)
    field.setAsBackgroundMesh(smallest)
    gmsh.model.mesh.generate(1)
    arc_tags, arc_x, _ = gmsh.model.mesh.getNodes(1, arcs[1], includeBoundary=True)
    x_disc = np.sort(arc_x.reshape(-1, 3)[:, 0])
    line_tags, line_x, _ = gmsh.model.mesh.getNodes(1, tops[1], includeBoundary=False)
    line_x = line_x.reshape(-1, 3)
    order = np.argsort(line_x[:, 0])
    targets = x_disc[1:-1]
    if kind == "staggered":
        targets = 0.5 * (x_disc[1:-1] + x_disc[2:])
    for k, tag in enumerate(line_tags[order]):
        x = float(targets[k])
        # parametric coordinate of the line b_right -> b_left: 0 at x = c, 1 at x = -c
        gmsh.model.mesh.setNode(int(tag), [x, 0.0, 0.0], [(c - x) / (2.0 * c)])
    gmsh.model.mesh.generate(2)


def make_mesh(h: float, ratio: float, structured: str | None, order: int, comm: MPI.Comm):
    """The mesh data of a variant: the package's Hertz geometry, or the structured one."""
    if structured is None:
        return geometries.hertz_2d(h_contact=h, master_ratio=ratio, order=order, comm=comm)
    options = {
        "Mesh.MeshSizeFromPoints": 0.0,
        "Mesh.MeshSizeFromCurvature": 0.0,
        "Mesh.MeshSizeExtendFromBoundary": 0.0,
        "Mesh.Algorithm": 6.0,
        "Mesh.ElementOrder": float(order),
    }
    return generate_mesh(
        comm,
        "hertz_structured",
        lambda: _structured_build(h, structured),
        2,
        options,
        contact_surfaces=("cylinder_contact", "block_contact"),
    )


# -- the nodal pressures -------------------------------------------------------------
def nodal_profile(problem, values: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The multiplier nodes of pair 0 (one rank), sorted by reference x: reference and
    current positions, ``lambda_N`` (or ``values``, nodal in the same space) and the
    Cauchy pressure (times the nodal reference-over-current length ratio)."""
    c = problem.contacts[0]
    space = c.slave.P1
    owned = space.dofmap.index_map.size_local
    X = space.tabulate_dof_coordinates()[:owned, :2]
    lam = (c.lambda_N.x.array if values is None else values)[:owned]
    blocks = c.slave.node_blocks()
    u = c.u.x.array.reshape(-1, 2)[blocks]
    order = np.argsort(X[:, 0])
    X, x, lam = X[order], X[order] + u[order], lam[order]
    L0 = np.linalg.norm(np.diff(X, axis=0), axis=1)
    L = np.linalg.norm(np.diff(x, axis=0), axis=1)
    ref = np.concatenate([[0.0], L0]) + np.concatenate([L0, [0.0]])
    cur = np.concatenate([[0.0], L]) + np.concatenate([L, [0.0]])
    return {"X": X, "x": x, "lambda_N": lam, "pressure": lam * ref / cur}


def oscillation(x: np.ndarray, p: np.ndarray, exact: Hertz2D) -> dict:
    """The measures of the module docstring for nodal pressures ``p`` at abscissae ``x``."""
    a, p0 = exact.a, exact.p0
    # L2 error over |x| < 1.5 a of the piecewise linear interpolant, by fine sampling
    keep = np.abs(x) < 1.5 * a
    first, last = max(np.argmax(keep) - 1, 0), min(len(x) - np.argmax(keep[::-1]), len(x) - 1)
    s = np.linspace(0.0, 1.0, 41)
    err2 = 0.0
    for i in range(first, last):
        xs = x[i] + s * (x[i + 1] - x[i])
        ph = p[i] + s * (p[i + 1] - p[i])
        inside = np.abs(xs) < 1.5 * a
        f = np.where(inside, (ph - exact.pressure(xs)) ** 2, 0.0)
        err2 += np.trapezoid(f, xs)
    l2 = math.sqrt(abs(err2)) / (p0 * math.sqrt(a))
    second = np.abs(p[1:-1] - 0.5 * (p[:-2] + p[2:])) / p0
    interior = (np.abs(x[:-2]) < a) & (np.abs(x[2:]) < a)
    osc = float(second[interior].max(initial=0.0))
    e = p - exact.pressure(x)
    core = np.abs(x) < 0.8 * a
    ec = e[core]
    d2 = ec[1:-1] - 0.5 * (ec[:-2] + ec[2:])
    osc_core = float(np.abs(d2).max(initial=0.0) / p0)
    signs = "".join("+" if v > 0 else "-" for v in d2)
    alternation = float(np.mean(np.sign(d2[1:]) != np.sign(d2[:-1]))) if len(d2) > 1 else 0.0
    detrended = ec - np.polyval(np.polyfit(x[core], ec, 2), x[core]) if len(ec) > 3 else ec
    spectrum = np.abs(np.fft.rfft(detrended))
    k = int(np.argmax(spectrum[1:]) + 1) if len(spectrum) > 1 else 0
    period = len(ec) / k if k else float("nan")
    return {
        "l2_error": l2,
        "osc": osc,
        "osc_core": osc_core,
        "osc_rms": float(np.sqrt(np.mean(d2**2)) / p0) if len(d2) else 0.0,
        "alternation": alternation,
        "period": period,
        "signs": signs,
        "error_rms_core": float(np.sqrt(np.mean(ec**2)) / p0) if len(ec) else 0.0,
    }


def _slave_forms(problem, integrand):
    """The multiplier space's mass matrix on the slave surface (scipy, owned rows) and the
    vector ``int integrand phi_i dS_o`` (``integrand`` a UFL expression, or ``None``)."""
    import dolfinx  # here: contact_ufl, imported first, loads its MPI and PETSc libraries

    c = problem.contacts[0]
    space = c.slave.P1
    w, v = ufl.TrialFunction(space), ufl.TestFunction(space)
    maps = [c.slave.entity_map]
    ds = c.ds.reconstruct(metadata={"quadrature_degree": 4})  # exact for the P1 mass
    mass = dolfinx.fem.assemble_matrix(jit.form(w * v * ds, entity_maps=maps))
    mass.scatter_reverse()
    M = mass.to_scipy()
    if integrand is None:
        return M, None
    rhs = dolfinx.fem.assemble_vector(jit.form(integrand * v * ds, entity_maps=maps))
    rhs.scatter_reverse(dolfinx.la.InsertMode.add)
    return M, rhs.array[: M.shape[0]]


def recovered_traction(problem) -> np.ndarray:
    """The package's recovered pressure (:func:`contact_ufl.results.recovered_pressure`:
    the L2 projection of ``nu . P N`` onto the slave surface), nodal."""
    return recovered_pressure(problem).x.array


def projected_traction(problem, degree: int, stress: str = "dg"):
    """A local variant of :func:`contact_ufl.results.recovered_pressure`: the L2 projection
    of ``nu . P N`` onto the Lagrange space of ``degree`` on the slave submesh (consistent
    mass, a degree-6 rule), ``P`` the package's ``stress_field`` (``"dg"``: the stress
    interpolated into DG of the displacement's degree minus one, as the package does) or
    the first Piola stress of the displacement itself (``"ufl"``). A dolfinx Function."""
    import dolfinx  # here: contact_ufl, imported first, loads its MPI and PETSc libraries
    import scipy.sparse.linalg

    from contact_ufl.estimate import stress_field

    c = problem.contacts[0]
    bulk = problem.bulk_of(c)
    if stress == "dg":
        P = stress_field(bulk)
    else:  # the slave body's stress: every body of these scenes has the same material
        assert all(b.material == bulk.bodies[0].material for b in bulk.bodies)
        P = bulk.first_piola(bulk.bodies[0])
    N = ufl.FacetNormal(bulk.V.mesh)
    space = dolfinx.fem.functionspace(c.slave.submesh, ("Lagrange", degree))
    w, v = ufl.TrialFunction(space), ufl.TestFunction(space)
    maps = [c.slave.entity_map]
    ds = c.ds.reconstruct(metadata={"quadrature_degree": 6})
    mass = dolfinx.fem.assemble_matrix(jit.form(w * v * ds, entity_maps=maps))
    mass.scatter_reverse()
    traction = ufl.dot(c.kinematics.nu, ufl.dot(P, N))
    rhs = dolfinx.fem.assemble_vector(jit.form(traction * v * ds, entity_maps=maps))
    rhs.scatter_reverse(dolfinx.la.InsertMode.add)
    M = mass.to_scipy()
    f = dolfinx.fem.Function(space)
    f.x.array[: M.shape[0]] = scipy.sparse.linalg.spsolve(M.tocsc(), rhs.array[: M.shape[0]])
    return f


def on_multiplier_nodes(problem, f) -> np.ndarray:
    """The values of ``f`` (a function on the slave submesh) at the multiplier nodes:
    interpolated into the multiplier space (a P2 ``f`` into P1: its vertex values)."""
    import dolfinx

    g = dolfinx.fem.Function(problem.contacts[0].slave.P1)
    g.interpolate(f)
    return g.x.array.copy()


def nodal_force_pressure(problem) -> np.ndarray:
    """The nodal contact force over the nodal length, ``(M lambda)_i / sum_j M_ij``: what a
    lumped (dual) multiplier basis would read from the same nodal forces."""
    M, _ = _slave_forms(problem, None)
    lam = problem.contacts[0].lambda_N.x.array[: M.shape[0]]
    if problem.contacts[0].pair.quadrature_rule == "lobatto":  # the nodal rule lumps M
        return lam.copy()
    return (M @ lam) / np.asarray(M.sum(axis=1)).ravel()


# -- the measures on the slave surface mesh (3D; the P2 mid-side nodes) ----------------
def surface_nodes(space) -> dict[str, np.ndarray]:
    """The nodes of a Lagrange ``space`` (degree 1 or 2) on the slave submesh, one rank:
    ``dof`` (the dof of each vertex, -1 for a vertex of no cell), ``X`` (the vertices'
    reference positions), ``edges`` (pairs of vertices, each edge once) and ``mid`` (the dof
    of each edge's mid-side node, degree 2; -1 otherwise)."""
    mesh = space.mesh
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim, 0)
    cells = mesh.topology.index_map(tdim).size_local
    nvc = tdim + 1
    vertices = mesh.topology.connectivity(tdim, 0).array.reshape(-1, nvc)[:cells]
    dofs = space.dofmap.list[:cells]
    count = mesh.topology.index_map(0).size_local + mesh.topology.index_map(0).num_ghosts
    dof = np.full(count, -1, np.int64)
    dof[vertices] = dofs[:, :nvc]
    X = np.zeros((count, 3))
    X[vertices] = mesh.geometry.x[mesh.geometry.dofmaps[0][:cells, :nvc]]
    used = dof >= 0
    assert np.allclose(space.tabulate_dof_coordinates()[dof[used]], X[used])
    local = [(0, 1)] if tdim == 1 else [(1, 2), (0, 2), (0, 1)]  # basix: edge k opposite k
    edges = np.concatenate([vertices[:, list(e)] for e in local])
    degree = space.ufl_element().basix_element.degree
    edges, first = np.unique(np.sort(edges, axis=1), axis=0, return_index=True)
    mid = np.full(len(edges), -1, np.int64)
    if degree == 2:
        mid = np.concatenate([dofs[:, nvc + k] for k in range(len(local))])[first]
    return {"dof": dof, "X": X, "edges": edges, "mid": mid, "tdim": tdim}


def graph_oscillation(nodes: dict, values: np.ndarray, exact, symmetry: bool = True) -> dict:
    """The node-to-node oscillation on the slave surface mesh of the nominal pressures
    ``values`` (dofs of the space of ``nodes``) against Hertz's profile ``exact`` (3D, of
    ``r = |(X, Y)|``): ``d_i = p_i - mean_j p_j`` over the edge neighbours ``j`` of vertex
    ``i``, the neighbours of a vertex on a symmetry plane of the quarter model (X = 0 or
    Y = 0) off that plane counted twice (their mirror images: the mean of the full model).
    ``osc``: ``max |d_i| / p0`` over the vertices in contact whose neighbours all are
    (``r < a``); ``osc_core``, ``osc_rms``: the largest and the rms of the same of the error
    ``e = p - p_exact`` over ``r < 0.8 a``; degree 2, ``osc_mid*``: the same of the mid-side
    nodes, ``p_m - (p_a + p_b) / 2`` over the edge ``ab``."""
    import scipy.sparse

    dof, X, edges = nodes["dof"], nodes["X"], nodes["edges"]
    r = np.linalg.norm(X[:, :2], axis=1) if nodes["tdim"] == 2 else np.abs(X[:, 0])
    p = np.where(dof >= 0, values[np.maximum(dof, 0)], 0.0)
    e = p - exact.pressure(r)
    i, j = np.concatenate([edges[:, 0], edges[:, 1]]), np.concatenate([edges[:, 1], edges[:, 0]])
    w = np.ones(len(i))
    if symmetry:
        tol = 1e-9
        for k in (0, 1):
            on = np.abs(X[:, k]) < tol
            w *= np.where(on[i] & ~on[j], 2.0, 1.0)
    n = len(X)
    W = scipy.sparse.csr_array((w, (i, j)), shape=(n, n))
    total = W.sum(axis=1)
    reach = scipy.sparse.csr_array((r[j], (i, j)), shape=(n, n)).max(axis=1).toarray().ravel()
    linked = total > 0
    safe = np.where(linked, total, 1.0)
    d, de = p - (W @ p) / safe, e - (W @ e) / safe
    inside = linked & (r < exact.a) & (reach < exact.a)
    core = linked & (r < 0.8 * exact.a) & (reach < 0.8 * exact.a)
    out = {
        "osc": float(np.abs(d[inside]).max(initial=0.0) / exact.p0),
        "osc_core": float(np.abs(de[core]).max(initial=0.0) / exact.p0),
        "osc_rms": float(np.sqrt(np.mean(de[core] ** 2)) / exact.p0) if core.any() else 0.0,
        "nodes_core": int(core.sum()),
    }
    mid = nodes["mid"]
    if (mid >= 0).any():
        middle = 0.5 * (X[edges[:, 0]] + X[edges[:, 1]])
        rm = np.linalg.norm(middle[:, :2], axis=1) if nodes["tdim"] == 2 else np.abs(middle[:, 0])
        pm = values[mid]
        em = pm - exact.pressure(rm)  # the mid-side node's exact value, at the chord's middle
        dm = pm - 0.5 * (p[edges[:, 0]] + p[edges[:, 1]])
        dme = em - 0.5 * (e[edges[:, 0]] + e[edges[:, 1]])
        ends = np.maximum(r[edges[:, 0]], r[edges[:, 1]])
        inside_m, core_m = ends < exact.a, ends < 0.8 * exact.a
        out |= {
            "osc_mid": float(np.abs(dm[inside_m]).max(initial=0.0) / exact.p0),
            "osc_mid_core": float(np.abs(dme[core_m]).max(initial=0.0) / exact.p0),
            "osc_mid_rms": float(np.sqrt(np.mean(dme[core_m] ** 2)) / exact.p0),
        }
    return out


def l2_error_3d(f, exact) -> float:
    """``||p_h - p||_L2 / (p0 sqrt(A))`` over ``r < 1.5 a`` of the slave surface (reference
    configuration), ``A = pi a^2 / 4`` the quarter model's contact area (the relative error
    ``||p_h - p|| / ||p||`` is sqrt(2) times it); ``f`` a function on the slave submesh."""
    import dolfinx

    mesh = f.function_space.mesh
    x = ufl.SpatialCoordinate(mesh)
    r2 = x[0] ** 2 + x[1] ** 2
    p = exact.p0 * ufl.sqrt(ufl.max_value(1.0 - r2 / exact.a**2, 0.0))
    inside = ufl.conditional(ufl.lt(r2, (1.5 * exact.a) ** 2), 1.0, 0.0)
    dx = ufl.Measure("dx", domain=mesh, metadata={"quadrature_degree": 10})
    value = dolfinx.fem.assemble_scalar(jit.form(inside * (f - p) ** 2 * dx))
    return math.sqrt(abs(value)) / (exact.p0 * math.sqrt(math.pi * exact.a**2 / 4.0))


def run_3d(h: float, degree: int, multiplier_degree: int = 1) -> list[dict]:
    """The 3D Hertz quarter model (:func:`contact_ufl.verification.scenes.hertz_3d`, linear
    elastic, depth 0.01 in 2 steps, the library's default eps) with displacement ``degree``
    at ``h_contact = h`` (the pair's ``multiplier_degree``: 2 with P2 only); one record per
    pressure field (:data:`FIELDS_3D`)."""
    import dolfinx

    from contact_ufl.verification.analytic import Hertz3D
    from contact_ufl.verification.runs import hertz_3d_run

    record, problem = hertz_3d_run(
        h, degree=degree, default_eps=True, multiplier_degree=multiplier_degree
    )
    exact = Hertz3D(record["P"], R, plane_strain_modulus(E, NU, E, NU))
    assert math.isclose(exact.a, record["a"])
    c = problem.contacts[0]
    multipliers = c.slave.P1
    force = dolfinx.fem.Function(multipliers)
    if multiplier_degree == 1:
        force.x.array[:] = nodal_force_pressure(problem)
    fields = {
        "lambda": c.lambda_N,
        # P2 multipliers: the row sums of their mass matrix vanish at the vertices (no reading)
        **({"force": force} if multiplier_degree == 1 else {}),
        "recovered": recovered_pressure(problem),
        "recovered_p2": projected_traction(problem, 2),
        "recovered_ufl": projected_traction(problem, 1, "ufl"),
        "recovered_p2_ufl": projected_traction(problem, 2, "ufl"),
    }
    common = {
        "dim": 3,
        "degree": degree,
        "multiplier_degree": multipliers.ufl_element().basix_element.degree,
        "h": h,
        "a_over_h": exact.a / h,
        "P": exact.P,
        "a": exact.a,
        "p0": exact.p0,
        "dofs": record["dofs"],
        "newton": record["newton_iterations"],
        "wall_s": record["wall_s"],
    }
    rows = []
    for name, f in fields.items():
        nodes = surface_nodes(f.function_space)
        rows.append(
            {
                **common,
                "field": name,
                "field_degree": f.function_space.ufl_element().basix_element.degree,
                "l2_error": l2_error_3d(f, exact),
                **graph_oscillation(nodes, f.x.array, exact),
            }
        )
    return rows


# -- one run --------------------------------------------------------------------------
def run(name: str, h: float, comm: MPI.Comm) -> dict:
    """Solve variant ``name`` at element size ``h`` (before the variant's ``h_scale``)."""
    v = VARIANTS[name]
    h = h * v.get("h_scale", 1.0)
    degree = v.get("degree", 1)
    data = make_mesh(h, v.get("ratio", 1.3), v.get("structured"), degree, comm)
    material = LinearElastic(E, NU) if v.get("material") == "linear" else NeoHookean(E, NU)
    slave, master = "cylinder_contact", "block_contact"
    if v.get("swap"):
        slave, master = master, slave
    pair = ContactPair(
        slave,
        master,
        quadrature_subdivisions=v.get("subdivisions", 1),
        quadrature_degree=v.get("quadrature_degree"),
        quadrature_rule=v.get("quadrature_rule", "gauss"),
    )
    depth = v.get("depth", DEPTH)
    scene = Scene.from_mesh_data(
        data,
        bodies=[Body("cylinder", material), Body("block", dataclasses.replace(material))],
        contacts=[pair],
        dirichlet=[
            Dirichlet("block_bottom", (0.0, 0.0)),
            Dirichlet("cylinder_top", lambda t: (0.0, -depth * t)),
        ],
    )
    problem = ContactProblem(scene, degree=degree, verbose=False)
    eps_default = float(problem.contacts[0].normal.eps_N.value)
    if "eps_factor" in v:
        problem.contacts[0].normal.eps_N.value = v["eps_factor"] * eps_default
    start = time.perf_counter()
    problem.solve(num_steps=STEPS)
    wall = time.perf_counter() - start
    force = abs(float(problem.contact_force()[1]))
    exact = Hertz2D(force, R, plane_strain_modulus(E, NU, E, NU))
    prof = nodal_profile(problem)
    x = prof["x"][:, 0]
    measures = oscillation(x, prof["pressure"], exact)
    rec = nodal_profile(problem, recovered_traction(problem))
    recovered = oscillation(x, rec["pressure"], exact)
    lumped = nodal_profile(problem, nodal_force_pressure(problem))
    forces = oscillation(x, lumped["pressure"], exact)
    extra = {}
    for key, degree_k, stress in (
        ("recovered_q6", 1, "dg"),
        ("recovered_p2", 2, "dg"),
        ("recovered_ufl", 1, "ufl"),
        ("recovered_p2_ufl", 2, "ufl"),
    ):
        f = projected_traction(problem, degree_k, stress)
        prof_k = nodal_profile(problem, on_multiplier_nodes(problem, f))
        extra |= {f"{key}_{k}": val for k, val in oscillation(x, prof_k["pressure"], exact).items()}
        if degree_k == 2:  # the mid-side nodes (nominal: the length ratio is smooth)
            mids = graph_oscillation(surface_nodes(f.function_space), f.x.array, exact, False)
            extra |= {f"{key}_{k}": mids[k] for k in ("osc_mid", "osc_mid_core", "osc_mid_rms")}
    core = np.abs(x) < exact.a
    return {
        "variant": name,
        "h": h,
        "a_over_h": exact.a / h,
        "degree": degree,
        "eps_N": float(problem.contacts[0].normal.eps_N.value),
        "eps_default": eps_default,
        "force": force,
        "a": exact.a,
        "p0": exact.p0,
        "nodes_in_contact": int(core.sum()),
        **measures,
        **{f"recovered_{k}": val for k, val in recovered.items()},
        **{f"force_{k}": val for k, val in forces.items()},
        **extra,
        "newton": sum(r.newton_iterations for r in problem.history.steps),
        "wall_s": wall,
        "profile": {
            "x": x.tolist(),
            "pressure": prof["pressure"].tolist(),
            "recovered": rec["pressure"].tolist(),
            "force": lumped["pressure"].tolist(),
        },
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    parser.add_argument("--h", type=float, nargs="+", help="h_contact list")
    parser.add_argument("--dim", type=int, choices=(2, 3), default=2)
    parser.add_argument("--degrees", type=int, nargs="+", default=[1, 2], help="3D only")
    parser.add_argument("--multiplier-degree", type=int, default=1, help="3D, with P2 only")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    if comm.size != 1:
        raise SystemExit("one rank: the nodal profile is gathered on one process")
    if args.dim == 3:
        main_3d(args)
        return
    args.h = args.h or H_LEVELS
    records = []
    print(
        f"{'variant':>10} {'h':>8} {'a/h':>5} {'L2':>7} {'osc':>7} {'osc_core':>8} "
        f"{'alt':>5} {'period':>6} {'rec_core':>8} {'rec_L2':>7} {'f_core':>7} {'f_L2':>7} "
        f"{'newton':>6} {'s':>5}"
    )
    for name in args.variants:
        for h in args.h:
            r = run(name, h, comm)
            records.append(r)
            print(
                f"{name:>10} {r['h']:8.5f} {r['a_over_h']:5.1f} {r['l2_error']:7.4f} "
                f"{r['osc']:7.4f} {r['osc_core']:8.4f} {r['alternation']:5.2f} "
                f"{r['period']:6.2f} {r['recovered_osc_core']:8.4f} "
                f"{r['recovered_l2_error']:7.4f} {r['force_osc_core']:7.4f} "
                f"{r['force_l2_error']:7.4f} {r['newton']:6d} {r['wall_s']:5.1f}",
                flush=True,
            )
            resultfile.write(args.json, records)


def main_3d(args) -> None:
    """The 3D rows: each degree on its meshes (:data:`H_3D`, or ``--h``)."""
    records = []
    print(
        f"{'P':>2} {'h':>7} {'a/h':>5} {'field':>16} {'L2':>7} {'osc':>7} {'osc_core':>8} "
        f"{'osc_rms':>7} {'mid_core':>8} {'s':>5}"
    )
    for degree in args.degrees:
        for h in args.h or H_3D[degree]:
            for r in run_3d(h, degree, args.multiplier_degree):
                records.append(r)
                print(
                    f"{degree:>2} {h:7.4f} {r['a_over_h']:5.1f} {r['field']:>16} "
                    f"{r['l2_error']:7.4f} {r['osc']:7.4f} {r['osc_core']:8.4f} "
                    f"{r['osc_rms']:7.4f} {r.get('osc_mid_core', math.nan):8.4f} "
                    f"{r['wall_s']:5.1f}",
                    flush=True,
                )
            resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
