"""The pre-tensioned drumhead, a flat membrane (or string) with stretched edges: its
supports, its tensioned start (:func:`pretension`), and a solid indenter pressed into it
(:func:`indented_drumhead`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.loads import Dirichlet
from contact_ufl.materials import (
    NeoHookean,
)
from contact_ufl.scene import Body, Domain, Scene
from contact_ufl.verification import geometries


def drumhead_supports(
    a: float, stretch: float, quarter: bool = False, dim: int = 3
) -> list[Dirichlet]:
    """Supports of the pre-tensioned drumhead of
    :func:`~contact_ufl.verification.membrane_meshes.drumhead` (``dim`` 2: the string).

    Each framed edge moves out by ``(stretch - 1) a`` normal to itself, in its plane, and is
    held at ``z = 0`` (a string's ends at ``y = 0``); its tangential motion is free (a
    roller), so the equi-biaxial stretch ``u = (stretch - 1) (x, y, 0)`` (the string's ``u =
    (stretch - 1) (x, 0)``) is the exact state under no other load. A quarter (half string)
    is held normally on its symmetry edges ``"x0"`` (and ``"y0"``).
    """
    from contact_ufl.verification.membrane_meshes import DRUMHEAD_EDGES

    if not stretch > 0.0:
        raise ValueError(f"stretch must be positive, got {stretch}")
    shift = (stretch - 1.0) * a
    edges = {k: v for k, v in DRUMHEAD_EDGES.items() if v[0] < dim - 1}
    names = [k for k in edges if k.endswith("max")] if quarter else list(edges)
    supports = []
    for name in names:
        axis, sign = edges[name]
        supports += [
            Dirichlet(name, sign * shift, component=axis),
            Dirichlet(name, 0.0, component=dim - 1),
        ]
    if quarter:
        supports += [Dirichlet(k, 0.0, component=i) for i, k in enumerate(["x0", "y0"][: dim - 1])]
    return supports


def pretensioned_drumhead(
    n: int = 8,
    a: float = 0.5,
    stretch: float = 1.05,
    pressure: float = 0.0,
    law=None,
    quarter: bool = False,
    dim: int = 3,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Domain:
    """A flat square membrane ``[-a, a]^2`` in ``z = 0`` (or its quarter; ``dim`` 2: the
    string ``[-a, a]`` on ``y = 0``, or its half), its edges stretched by ``stretch``
    (:func:`drumhead_supports`), under the follower pressure ``pressure * t`` along ``n0 =
    +z`` (``direction=(0, 0, 1)``; a string's ``+y``).

    A flat membrane has no stiffness normal to itself where it is unstretched: start the
    solve from the tensioned state with :func:`pretension` (before the first solve), which
    the edge supports then hold. Without it, the first Newton iterate has the stretched edges
    around an unstretched interior: with no pressure (a solid pressed into the drumhead) its
    tangent is singular (``DIVERGED_LINEAR_SOLVE`` at every cut-back); a follower
    pressure couples the transverse to the in-plane motion and Newton converges, but in 11-12
    iterations where the pre-tensioned start takes 3. For
    the default :class:`~contact_ufl.membranes.MembraneNeoHookean` (``mu = 1``, ``t0 = 0.01``)
    the Cauchy tension is ``mu t0 (1 - stretch^-6)``
    (:func:`~contact_ufl.verification.analytic.equibiaxial_tension_neo_hookean`), a string's
    ``mu t0 (stretch - stretch^-3)``
    (:func:`~contact_ufl.verification.analytic.tube_hoop_tension_neo_hookean`). The cells are
    ``"membrane"``: a solid pressed into it from above contacts them (``n0`` points up, to the
    indenter).
    """
    from contact_ufl.loads import FollowerPressure
    from contact_ufl.membranes import MembraneNeoHookean
    from contact_ufl.verification import membrane_meshes

    law = law or MembraneNeoHookean(1.0, 0.01)
    data = membrane_meshes.drumhead(comm, a, n, quarter, dim)
    loads = [FollowerPressure("membrane", lambda t: pressure * t)] if pressure else []
    return Domain(
        data.mesh,
        data.cell_tags,
        data.facet_tags,
        [Body("membrane", law)],
        drumhead_supports(a, stretch, quarter, dim),
        loads,
        groups=dict(data.groups),
        name="drumhead",
        direction=tuple(np.eye(dim)[dim - 1]),
    )


def pretension(problem, stretch: float, domain: int = 0) -> None:
    """Start ``problem`` from the flat membrane of ``problem.bulks[domain]`` (in a plane
    ``z = const`` about the origin, e.g. :func:`pretensioned_drumhead`; a string on a line
    ``y = const``) stretched equi-biaxially: ``u = (stretch - 1) (x, y, 0)`` (a string's
    ``(stretch - 1) (x, 0)``).

    The solver starts from the problem's fields as they are when it is made (its first use):
    call this before the first solve. Newton's first iterate is then a tensioned membrane,
    whose transverse stiffness ``T Laplace`` is regular.
    """
    if problem._solver is not None:
        raise ValueError("pretension must be set before the first solve (the solver exists)")
    bulk = problem.bulks[domain]
    if not bulk.membrane:
        raise ValueError(f"domain {domain} is not a membrane")
    gdim = bulk.V.mesh.geometry.dim
    X = bulk.V.tabulate_dof_coordinates()[:, :gdim]
    u = np.zeros_like(X)
    u[:, : gdim - 1] = (stretch - 1.0) * X[:, : gdim - 1]
    bulk.u.x.array[:] = u.ravel()


def retagged_membrane(domain: Domain, tag: int) -> Domain:
    """The one-body membrane ``domain`` with its cells tagged ``tag`` (its body, cell group,
    contact surface and the loads on its cells keep their names): bodies of several meshes
    need distinct tags for :func:`~contact_ufl.results.body_resultants`."""
    mesh = domain.mesh
    tdim = mesh.topology.dim
    (body,) = domain.bodies
    cells = domain.cell_tags.indices
    cell_tags = dolfinx.mesh.meshtags(mesh, tdim, cells, np.full_like(cells, tag))
    groups = {
        name: (dim, tag if dim == tdim and old == body.tag else old)
        for name, (dim, old) in domain.groups.items()
    }
    loads = [
        dataclasses.replace(load, tag=tag) if domain.on_cells(load) else load
        for load in domain.loads
    ]
    return dataclasses.replace(
        domain,
        cell_tags=cell_tags,
        bodies=[dataclasses.replace(body, tag=tag)],
        loads=loads,
        tags={},
        groups=groups,
    )


@dataclass
class IndentedDrumhead:
    """A solid indenter pressed into the pre-tensioned drumhead, and its data."""

    scene: Scene
    radius: float
    depth: float
    gap: float
    a: float
    stretch: float
    law: object


def indented_drumhead(
    dim: int = 2,
    n: int = 32,
    a: float = 0.5,
    stretch: float = 1.05,
    radius: float = 0.25,
    depth: float = 0.06,
    gap: float = 0.005,
    E: float = 100.0,
    nu: float = 0.3,
    h_contact: float | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> IndentedDrumhead:
    """A stiff solid indenter pressed into the pre-tensioned drumhead of
    :func:`pretensioned_drumhead` (its centre under the indenter), on meshes of their own.

    ``dim`` 2: the half disc of :func:`~contact_ufl.verification.geometries.hertz_2d` (radius
    ``radius``, split off its block by
    :func:`~contact_ufl.verification.geometries.split_by_cells`) over the whole string
    drumhead ``[-a, a]`` (``2 n`` intervals); ``dim`` 3: the quarter hemisphere of
    :func:`~contact_ufl.verification.geometries.hemisphere_3d` over the quarter drumhead
    ``[0, a]^2`` (``n`` cells along ``a``), both held normally on their symmetry planes.
    The indenter's lowest point starts ``gap`` above the membrane; its flat top
    (``"cylinder_top"``, ``"indenter_top"``) moves down by ``depth t``. The indenter's
    contact face is the slave, the membrane's cells (``"membrane"``, cell tag 100) the
    two-sided master; the membrane's normal points up, to the indenter. Start the solve
    with :func:`pretension` on domain 1 (the drumhead).
    """
    law = _membrane_law()
    drumhead = retagged_membrane(
        pretensioned_drumhead(n, a, stretch, quarter=dim == 3, dim=dim, law=law, comm=comm), 100
    )
    if dim == 2:
        h = 0.02 * radius if h_contact is None else h_contact
        data = geometries.hertz_2d(
            radius=radius,
            block=(4.0 * radius, 1.5 * radius),
            gap=gap,
            h_contact=h,
            h_far=0.2 * radius,
            comm=comm,
        )
        (data,) = geometries.split_by_cells(data, ["cylinder"])
        names = ("cylinder_contact", "cylinder_top")
        supports = [Dirichlet("cylinder_top", lambda t: (0.0, -depth * t))]
    elif dim == 3:
        data = geometries.hemisphere_3d(
            radius=radius, gap=gap, h_contact=h_contact, quarter=True, comm=comm
        )
        names = ("indenter_contact", "indenter_top")
        supports = [
            Dirichlet("indenter_top", lambda t: (0.0, 0.0, -depth * t)),
            Dirichlet("indenter_x0", 0.0, component=0),
            Dirichlet("indenter_y0", 0.0, component=1),
        ]
    else:
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    indenter = Domain.from_mesh_data(
        data, bodies=[Body(1, NeoHookean(E, nu), "indenter")], dirichlet=supports, name="indenter"
    )
    pair = ContactPair(names[0], "membrane")
    scene = Scene(domains=[indenter, drumhead], contacts=[pair])
    return IndentedDrumhead(scene, radius, depth, gap, a, stretch, law)


def _membrane_law():
    from contact_ufl.membranes import MembraneNeoHookean

    return MembraneNeoHookean(1.0, 0.01)
