"""Flat membranes in contact: pressed onto a block stretched with it (a membrane patch test,
:func:`membrane_on_block`), and pressed onto a rigid plane and pulled by one edge (stick
and slip, :func:`membrane_dragged_on_plane`).
"""

from __future__ import annotations

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair, RigidPlane
from contact_ufl.loads import Dirichlet
from contact_ufl.materials import (
    NeoHookean,
)
from contact_ufl.scene import Body, Domain, Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.scenes.drumheads import _membrane_law, retagged_membrane


def _flat_membrane_domain(
    a: float, n: int, dim: int, supports: list, loads: list, comm: MPI.Comm, law=None
) -> Domain:
    """The quarter drumhead ``[0, a]^2`` in ``z = 0`` (the half string ``[0, a]`` on ``y =
    0``) as a membrane domain with ``supports`` and ``loads``, its normal pointing down
    (``n0 = -e_z``: a positive pressure pushes it down), its cells tag 100."""
    from contact_ufl.verification import membrane_meshes

    data = membrane_meshes.drumhead(comm, a, n, quarter=True, dim=dim)
    domain = Domain(
        data.mesh,
        data.cell_tags,
        data.facet_tags,
        [Body("membrane", law or _membrane_law())],
        supports,
        loads,
        groups=dict(data.groups),
        name="membrane",
        direction=tuple(-np.eye(dim)[dim - 1]),
    )
    return retagged_membrane(domain, 100)


def membrane_on_block(
    dim: int = 2,
    n: int = 4,
    a: float = 0.5,
    height: float = 0.25,
    stretch: float = 1.05,
    pressure: float = 0.01,
    E: float = 1.0,
    nu: float = 0.3,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """A flat membrane pressed by a follower pressure onto a solid block, both stretched in
    their plane: a membrane patch test.

    The membrane is the quarter drumhead ``[0, a]^2`` in ``z = 0`` (``dim`` 2: the half string
    ``[0, a]``), the slave, its normal down; the block ``[0, a]^{d-1} x [-height, 0]``
    (Neo-Hookean, quadrilaterals or hexahedra, ``n`` along ``a``: its top matches the
    membrane's grid), the master. From t = 0 to 1 the follower pressure ``pressure * t``
    pushes the membrane down while the edges ``x = a`` (and ``y = a``) of both move out by
    ``(stretch - 1) a t``; the edges ``x = 0`` (``y = 0``) are held normally, the block's
    bottom vertically. Both stretch alike in their plane, so the grids stay matched and the
    exact solution is homogeneous: the membrane flat on the block's flat top, with the
    contact pressure (per current area) equal to ``pressure`` everywhere, the nominal
    multiplier ``lambda_N = pressure * s^(d-1)``, and the bottom's reaction ``pressure (s
    a)^(d-1)``. Groups: membrane ``"membrane"`` (tag 100), ``"x0"``, ``"xmax"`` (``"y0"``,
    ``"ymax"``); block ``"block"`` (tag 1), ``"block_top"``, ``"block_bottom"``,
    ``"block_x0"``, ``"block_xmax"`` (``"block_y0"``, ``"block_ymax"``).
    """
    from contact_ufl.loads import FollowerPressure

    axes = range(dim - 1)
    edges = {"x0": (0, 0.0), "xmax": (0, a), "y0": (1, 0.0), "ymax": (1, a)}
    edges = {k: v for k, v in edges.items() if v[0] in axes}

    def moved(value: float):
        return lambda t: (stretch - 1.0) * value * t

    in_plane = [Dirichlet(k, moved(v), component=axis) for k, (axis, v) in edges.items()]
    membrane = _flat_membrane_domain(
        a, n, dim, in_plane, [FollowerPressure("membrane", lambda t: pressure * t)], comm
    )
    lo, hi = np.zeros(dim), np.full(dim, a)
    lo[-1], hi[-1] = -height, 0.0
    m = max(1, round(n * height / a))
    if dim == 2:
        mesh = dolfinx.mesh.create_rectangle(
            comm,
            [lo, hi],
            [n, m],
            dolfinx.mesh.CellType.quadrilateral,
            ghost_mode=dolfinx.mesh.GhostMode.shared_facet,
        )
    else:
        mesh = dolfinx.mesh.create_box(
            comm,
            [lo, hi],
            [n, n, m],
            dolfinx.mesh.CellType.hexahedron,
            ghost_mode=dolfinx.mesh.GhostMode.shared_facet,
        )
    faces = {"block_top": (dim - 1, 0.0), "block_bottom": (dim - 1, -height)}
    faces.update({f"block_{k}": v for k, v in edges.items()})
    markers = [lambda x, k=k, v=v: np.isclose(x[k], v) for k, v in faces.values()]
    cells, facets = geometries.tag_single_body(mesh, markers)
    block = Domain(
        mesh,
        cells,
        facets,
        [Body(1, NeoHookean(E, nu), "block")],
        [Dirichlet("block_bottom", 0.0, component=dim - 1)]
        + [Dirichlet(f"block_{k}", moved(v), component=axis) for k, (axis, v) in edges.items()],
        groups={"block": (dim, 1)} | {k: (dim - 1, i + 1) for i, k in enumerate(faces)},
        name="block",
    )
    pair = ContactPair("membrane", "block_top", quadrature_degree=3)
    return Scene(domains=[membrane, block], contacts=[pair])


def membrane_dragged_on_plane(
    n: int = 32,
    a: float = 0.5,
    stretch: float = 1.02,
    pressure: float = 0.01,
    pull: float = 0.002,
    mu: float = 0.3,
    dim: int = 2,
    width: int = 4,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> tuple[Scene, RigidPlane]:
    """A pre-tensioned membrane strip pressed onto a rigid plane by a follower pressure, then
    pulled by one edge: a frictional stick and slip.

    ``dim`` 2: the string ``[0, a]`` on ``y = 0`` (``n`` intervals); ``dim`` 3: the strip
    ``[0, a] x [0, b]``, ``b = a width / n``, in ``z = 0`` (``n x width`` quadrilaterals). It
    lies on the :class:`~contact_ufl.contact.obstacles.RigidPlane` ``y = 0``
    (``z = 0``) with friction coefficient ``mu``, its normal down (a positive pressure pushes
    it onto the plane). Its edges are held on the plane and stretched by ``stretch``: ``u_x
    = 0`` on ``"x0"``, ``(stretch - 1) a`` on ``"xmax"`` (3D: ``u_y = 0`` on ``"y0"``,
    ``(stretch - 1) b`` on ``"ymax"``; start the solve with :func:`pretension`). From t = 0
    to 1 the pressure grows to ``pressure``; from t = 1 to 2 it is held and the edge ``x =
    a`` is pulled out by a further ``pull (t - 1)``. Near the pulled edge the strip slips
    (``|lambda_T| = mu lambda_N``; its tension falls by ``mu lambda_N`` per unit reference
    length), beyond that it sticks.

    The contact surface is the cells ``"membrane"`` (tag 100) with no vertex on a held edge;
    the cells along the edges, ``"membrane_edges"`` (tag 101, the same law and pressure),
    are not in it: a multiplier at a node whose displacement is prescribed would constrain
    it twice (normally and, in stick, tangentially), and the Jacobian is then singular
    (``DIVERGED_LINEAR_SOLVE`` at every cut-back). The multiplier equations use
    the two-point Lobatto rule per direction (at the vertices: lumped, so the P1 multipliers
    are the contact tractions at the nodes). Returns the scene and the plane.
    """
    from contact_ufl.loads import FollowerPressure

    shift = (stretch - 1.0) * a
    data, planes = _strip(n, a, dim, width, comm)
    mesh = data.mesh
    x = mesh.geometry.x[mesh.geometry.dofmaps[0]]  # (cells, vertices, 3)
    held = np.zeros(x.shape[:2], dtype=bool)
    for axis, value in planes.values():
        held |= np.isclose(x[..., axis], value, atol=1e-9 * a)
    edge_cells = held.any(axis=1)
    cells = np.arange(len(x), dtype=np.int32)
    values = np.where(edge_cells, 101, 100).astype(np.int32)
    cell_tags = dolfinx.mesh.meshtags(mesh, dim - 1, cells, values)
    groups = {k: v for k, v in data.groups.items() if v[0] == dim - 2}
    groups.update({"membrane": (dim - 1, 100), "membrane_edges": (dim - 1, 101)})
    law = _membrane_law()
    normal = dim - 1
    supports = [
        Dirichlet("x0", 0.0, component=0),
        Dirichlet("xmax", lambda t: shift + pull * max(t - 1.0, 0.0), component=0),
    ]
    if dim == 3:
        b = planes["ymax"][1]
        supports += [
            Dirichlet("y0", 0.0, component=1),
            Dirichlet("ymax", (stretch - 1.0) * b, component=1),
        ]
    supports += [Dirichlet(edge, 0.0, component=normal) for edge in planes]

    def p(t: float) -> float:
        return pressure * min(t, 1.0)

    domain = Domain(
        mesh,
        cell_tags,
        data.facet_tags,
        [Body("membrane", law, "membrane"), Body("membrane_edges", law, "membrane_edges")],
        supports,
        [FollowerPressure("membrane", p), FollowerPressure("membrane_edges", p)],
        groups=groups,
        name="membrane",
        direction=tuple(-np.eye(dim)[normal]),
    )
    up = np.eye(dim)[normal]
    plane = RigidPlane(tuple(0.0 * up), tuple(up))
    pair = ContactPair("membrane", plane, mu=mu, quadrature_rule="lobatto", quadrature_degree=1)
    return Scene(domains=[domain], contacts=[pair]), plane


def _strip(n: int, a: float, dim: int, width: int, comm: MPI.Comm):
    """The string ``[0, a]`` (``dim`` 2) or the strip ``[0, a] x [0, a width / n]`` in ``z
    = 0`` (``dim`` 3, ``n x width`` quadrilaterals) with its edges; returns the mesh data and
    the edges' planes."""
    from contact_ufl.verification import membrane_meshes

    if dim == 2:
        planes = {"x0": (0, 0.0), "xmax": (0, a)}
        return membrane_meshes.drumhead(comm, a, n, quarter=True, dim=2), planes
    if dim != 3:
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    b = a * width / n
    xs, ys = np.linspace(0.0, a, n + 1), np.linspace(0.0, b, width + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    x = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    i, j = np.meshgrid(np.arange(n), np.arange(width), indexing="ij")
    n00 = (i * (width + 1) + j).ravel()  # node i (width + 1) + j at (xs[i], ys[j])
    cells = np.stack([n00, n00 + width + 1, n00 + 1, n00 + width + 2], 1)
    mesh = membrane_meshes._create(
        comm, "quadrilateral", cells, x, False, dolfinx.mesh.GhostMode.shared_facet
    )
    planes = {"x0": (0, 0.0), "xmax": (0, a), "y0": (1, 0.0), "ymax": (1, b)}
    return membrane_meshes.with_tags(mesh, planes, name="membrane"), planes
