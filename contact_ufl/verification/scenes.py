"""Ready-made scenes of the verification problems, shared by tests, demos and benchmarks.

Each function meshes its geometry (:mod:`contact_ufl.verification.geometries`) and returns a
:class:`~contact_ufl.scene.Scene` with the bodies, supports, loads and contact pair, plus the
data needed to compare with the analytic solution.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair, RigidPlane, RigidSphere
from contact_ufl.gmshio import MeshData
from contact_ufl.loads import DeadTraction, Dirichlet, FollowerForce
from contact_ufl.materials import (
    Hyperelastic,
    LinearElastic,
    NearlyIncompressibleWarning,
    NeoHookean,
)
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.scene import Body, Domain, Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.analytic import plane_strain_modulus


def rotation_2d(angle: float) -> np.ndarray:
    """The 2x2 rotation matrix of ``angle`` (radians)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def _solids(**materials: Hyperelastic | J2Plasticity) -> list[Body]:
    """One body per cell group (``group=material``), named after its group."""
    return [Body(group, material, group) for group, material in materials.items()]


def _on_rigid_flat(scene: Scene) -> Scene:
    """``scene`` with the master surface of its contact pair made the rigid plane ``y = 0``
    (:class:`~contact_ufl.contact.obstacles.RigidPlane`, normal ``+y``)."""
    pair = dataclasses.replace(scene.contacts[0], master=RigidPlane((0.0, 0.0), (0.0, 1.0)))
    return dataclasses.replace(scene, contacts=[pair])


@dataclass
class HertzScene:
    """The 2D Hertz scene and its analytic data."""

    scene: Scene
    radius: float
    E_star: float
    h_contact: float


def hertz_2d(
    h_contact: float = 0.005,
    depth: float = 0.02,
    E: float = 1.0,
    nu: float = 0.3,
    E_flat: float | None = None,
    nu_flat: float = 0.3,
    eps_factor: float = 1.0,
    quadrature_degree: int | None = None,
    h_far: float = 0.2,
    mu: float = 0.0,
    shift: float = 0.0,
    rotation: float = 0.0,
    gap: float = 0.0,
    comm: MPI.Comm = MPI.COMM_WORLD,
    order: int = 1,
    refine_radius: float = 0.3,
) -> HertzScene:
    """Plane-strain Hertz problem: an elastic half disc (R = 1) pressed onto an elastic block.

    The flat top of the half disc is moved down by ``depth``; the bottom of the block is
    clamped. The slave surface is the disc's arc (the finer mesh), the master the block top.

    Parameters
    ----------
    h_contact
        Element size near the contact (the block is 1.3 times coarser).
    depth
        Prescribed displacement of the top of the disc at t = 1.
    E, nu
        Material of the disc (Neo-Hookean).
    E_flat, nu_flat
        Material of the block (default: the disc's E; a large value gives a rigid-like flat).
    eps_factor
        ``eps_N = eps_factor * E / h_contact``.
    quadrature_degree
        Quadrature degree of the contact integrals (default of :class:`ContactPair`).
    h_far
        Element size far from the contact.
    mu
        Friction coefficient.
    shift
        Horizontal displacement of the top of the disc from t = 1 to t = 2 (the vertical one
        is held at ``depth``): the Cattaneo-Mindlin loading.
    rotation
        Rotate the whole scene (geometry and prescribed displacements) by this angle
        (radians) about the origin: a frame-indifferent model gives rotated results.
    gap
        Initial gap between the disc and the block (``depth`` includes it).
    order
        Geometry order of the mesh (2: the disc's arc is curved, for a degree-2
        displacement).
    refine_radius
        Radius of the zone of size ``h_contact``, in units of the disc's radius.
    """
    E_flat = E if E_flat is None else E_flat
    sm = geometries.hertz_2d(
        h_contact=h_contact,
        h_far=h_far,
        gap=gap,
        order=order,
        refine_radius=refine_radius,
        comm=comm,
    )
    R = rotation_2d(rotation)
    sm.mesh.geometry.x[:, :2] = sm.mesh.geometry.x[:, :2] @ R.T
    pair = ContactPair(
        "cylinder_contact",
        "block_contact",
        eps_N=eps_factor * E / h_contact,
        mu=mu,
        quadrature_degree=quadrature_degree,
    )
    scene = Scene.from_mesh_data(
        sm,
        bodies=_solids(cylinder=NeoHookean(E, nu), block=NeoHookean(E_flat, nu_flat)),
        contacts=[pair],
        dirichlet=[
            Dirichlet("block_bottom", (0.0, 0.0)),
            Dirichlet(
                "cylinder_top", lambda t: R @ (shift * max(t - 1.0, 0.0), -depth * min(t, 1.0))
            ),
        ],
    )
    return HertzScene(scene, 1.0, plane_strain_modulus(E, nu, E_flat, nu_flat), h_contact)


@dataclass
class Hertz3DScene:
    """The 3D Hertz scene (a quarter model) and its analytic data."""

    scene: Scene
    radius: float
    E_star: float
    h_contact: float
    symmetry_factor: float = 4.0
    """The full force is this times the quarter model's."""


def hertz_3d(
    h_contact: float = 0.0125,
    depth: float = 0.01,
    E: float = 1.0,
    nu: float = 0.3,
    E_flat: float | None = None,
    nu_flat: float = 0.3,
    flat: str = "elastic",
    block: tuple[float, float] = (1.0, 1.0),
    h_far: float = 0.25,
    master_ratio: float = 1.0,
    refine_radius: float = 0.15,
    growth: float = 0.3,
    contact_zone: float = 0.3,
    eps_factor: float = 1.0,
    quadrature_degree: int | None = None,
    quadrature_subdivisions: int = 1,
    h_edge: float | None = None,
    edge_width: float | None = None,
    order: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Hertz3DScene:
    """3D Hertz problem, quarter model: an elastic half ball (R = 1) pressed onto an elastic
    block (or onto a rigid flat), small-strain linear elastic bulk (:class:`LinearElastic`,
    the material of Hertz's solution).

    The geometry is :func:`~contact_ufl.verification.geometries.sphere_on_block_3d`: the
    quarter ``x, y >= 0`` of both bodies, graded about the point of first contact, and (with
    ``h_edge``) about the circle where the contact zone is expected to end, ``r = 1.03
    sqrt(R depth)`` (the contact radius these supports give, within 1%: Hertz's ``sqrt(R d)``
    with ``d`` the approach of distant points, slightly more than ``depth``). The flat
    top of the half ball is moved down by ``depth`` (its vertical displacement only); the
    faces on the symmetry planes x = 0 and y = 0 are held normally; the block's bottom is
    held vertically. The slave surface is the ball's (the finer mesh), the master the
    block's top (or the :class:`~contact_ufl.contact.obstacles.RigidPlane` z = 0).

    Parameters
    ----------
    h_contact
        Element size within ``refine_radius`` of the contact point (the block
        ``master_ratio`` times coarser there: by default as fine, the two surface meshes
        still not matching; a coarser block is the stiffer, and its error adds to the
        ball's: p0 is 2.3% high at 1.3, 1.9% at 1.0).
    depth
        Prescribed displacement of the top of the half ball at t = 1.
    E, nu
        Material of the half ball.
    E_flat, nu_flat
        Material of the block (default: the ball's E).
    flat
        ``"elastic"`` (the block) or ``"rigid"`` (a rigid plane; the mesh has no block).
    block
        ``(w, height)`` of the quarter block ``[0, w]^2 x [-height, 0]``.
    h_far, master_ratio, refine_radius, growth, contact_zone
        Grading of the mesh (see :func:`~contact_ufl.verification.geometries.sphere_on_block_3d`).
    h_edge, edge_width
        Element size of the ball within ``edge_width`` (default ``2.5 h_edge``) of the
        expected edge of the contact zone (the block ``master_ratio`` times coarser); ``None``:
        no such refinement.
    eps_factor
        ``eps_N = eps_factor * E / h_contact``.
    quadrature_degree, quadrature_subdivisions
        Quadrature rule of the contact integrals (see :class:`ContactPair`); default degree
        2 with ``order`` 1, 4 with ``order`` 2. P1: degree 2 (three points per slave facet)
        gives the errors of the pair's default degree 3 (six points) to 0.1%, with half the
        points to search. P2 (h_contact = 0.05): degree 2 gives p0 2.5% low, degree 4 (six
        points) 0.6% high.
    order
        Geometry order of the mesh (2: the ball's surface is curved, for a degree-2
        displacement, ``ContactProblem(scene, degree=2)``).
    """
    if flat not in ("elastic", "rigid"):
        raise ValueError(f"flat must be 'elastic' or 'rigid', not {flat!r}")
    rigid = flat == "rigid"
    E_flat = E if E_flat is None else E_flat
    if quadrature_degree is None:
        quadrature_degree = 2 if order == 1 else 4
    radius = 1.0
    edge = None
    if h_edge is not None:
        edge = (1.03 * np.sqrt(radius * depth), h_edge, edge_width or 2.5 * h_edge)
    sm = geometries.sphere_on_block_3d(
        radius=radius,
        block=None if rigid else block,
        h_contact=h_contact,
        h_far=h_far,
        master_ratio=master_ratio,
        refine_radius=refine_radius,
        growth=growth,
        contact_zone=contact_zone,
        edge=edge,
        order=order,
        comm=comm,
    )
    bodies = [Body("sphere", LinearElastic(E, nu), "sphere")]
    supports = [
        Dirichlet("sphere_top", lambda t: -depth * t, component=2),
        Dirichlet("sphere_x0", 0.0, component=0),
        Dirichlet("sphere_y0", 0.0, component=1),
    ]
    if rigid:
        master = RigidPlane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
        E_star = E / (1.0 - nu**2)
    else:
        master = "block_contact"
        E_star = plane_strain_modulus(E, nu, E_flat, nu_flat)
        bodies.append(Body("block", LinearElastic(E_flat, nu_flat), "block"))
        supports += [
            Dirichlet("block_bottom", 0.0, component=2),
            Dirichlet("block_x0", 0.0, component=0),
            Dirichlet("block_y0", 0.0, component=1),
        ]
    pair = ContactPair(
        "sphere_contact",
        master,
        eps_N=eps_factor * E / h_contact,
        quadrature_degree=quadrature_degree,
        quadrature_subdivisions=quadrature_subdivisions,
    )
    scene = Scene.from_mesh_data(sm, bodies=bodies, contacts=[pair], dirichlet=supports)
    return Hertz3DScene(scene, radius, E_star, h_contact)


def patch(
    dim: int = 2,
    pressure: float = 0.01,
    E: float = 1.0,
    nu: float = 0.3,
    quadrature_degree: int | None = None,
    subdivisions: int = 1,
    cell: str | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
    mu: float = 0.0,
    **mesh_options,
) -> Scene:
    """Contact patch test: a uniform dead pressure through a flat non-matching interface.

    Two identical Neo-Hookean blocks stacked (the upper one the slave); the top of the upper
    block carries the nominal traction ``-pressure e_z``; the lower block is supported
    normally at its bottom; the faces x = 0 (and y = 0 in 3D) of both blocks are held
    normally. The exact solution is a homogeneous deformation with ``lambda_N = pressure``
    everywhere on the interface.

    Parameters
    ----------
    dim
        2 (:func:`~contact_ufl.verification.geometries.patch_2d`) or 3
        (:func:`~contact_ufl.verification.geometries.patch_3d`).
    cell
        Cell type of the meshes (default: simplices).
    mu
        Friction coefficient of the interface.
    mesh_options
        Passed to the mesh generator (element sizes).
    """
    if dim == 2:
        sm = geometries.patch_2d(cell=cell or "triangle", comm=comm, **mesh_options)
        sides = {0: ("upper_left", "lower_left")}
    else:
        sm = geometries.patch_3d(cell=cell or "tetrahedron", comm=comm, **mesh_options)
        sides = {0: ("upper_x0", "lower_x0"), 1: ("upper_y0", "lower_y0")}
    material = NeoHookean(E, nu)
    traction = np.zeros(dim)
    traction[-1] = -pressure
    supports = [Dirichlet("lower_bottom", 0.0, component=dim - 1)]
    supports += [Dirichlet(name, 0.0, component=k) for k, names in sides.items() for name in names]
    pair = ContactPair(
        "upper_contact",
        "lower_contact",
        eps_N=10.0 * E,
        mu=mu,
        quadrature_degree=quadrature_degree,
        quadrature_subdivisions=subdivisions,
    )
    return Scene.from_mesh_data(
        sm,
        bodies=_solids(upper=material, lower=material),
        contacts=[pair],
        dirichlet=supports,
        loads=[DeadTraction("upper_top", lambda t: traction * t)],
    )


E_STEEL = 200e9
"""Young's modulus of steel (Pa), of the force-driven scenes."""


def hertz_2d_driven(
    driven_by: str,
    value: float,
    gap: float = 0.0,
    h_contact: float = 0.02,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """The 2D Hertz half disc on a block (steel), driven through the disc's flat top.

    Parameters
    ----------
    driven_by
        ``"force"``: a dead traction of resultant ``value`` (downwards, at t = 1) on the top,
        whose horizontal motion is held; the disc is held in the vertical direction only by
        the contact. ``"displacement"``: the top is moved down by ``value``.
    value
        The force or the displacement at t = 1.
    gap
        Initial gap between the disc and the block.
    h_contact
        Element size near the contact (0.2 far from it).

    Notes
    -----
    The disc's vertical radius (its axis, group ``"cylinder_axis"`` of
    :func:`geometries.hertz_2d`) is held horizontally in both drivings: a symmetry
    condition (the symmetric solution has ``u_x = 0`` there). Without it the force-driven
    disc, whose top is held only horizontally, is free to turn about its centre: the top's
    points move vertically, which the dead traction allows, and a circle turning about its
    centre slides over itself, which a frictionless contact does not resist. Only the
    facets of the discrete arc hold that rotation, with a stiffness of order ``F R`` whose
    sign changes with the load and the active set (against some 1000 ``F R`` with the axis
    held). Where it passes through zero, which depends on the mesh and the master normal,
    the tangent is singular: Newton wanders along the rotation with the active set fixed,
    the step is cut back, and the disc tilts. Held, the scene needs no cut-back. A failed
    step of the disc free to turn says so (:meth:`NewtonSolver.diagnose
    <contact_ufl.newton.NewtonSolver.diagnose>`).
    """
    if driven_by not in ("force", "displacement"):
        raise ValueError(f"driven_by must be 'force' or 'displacement', not {driven_by!r}")
    mesh = geometries.hertz_2d(h_contact=h_contact, h_far=0.2, gap=gap, comm=comm, axis=True)
    steel = NeoHookean(E_STEEL, 0.3)
    supports = [Dirichlet("block_bottom", (0.0, 0.0)), Dirichlet("cylinder_axis", 0.0, component=0)]
    loads = []
    if driven_by == "force":
        width = 2.0  # the flat top of the half disc of radius 1
        supports.append(Dirichlet("cylinder_top", 0.0, component=0))
        loads.append(DeadTraction("cylinder_top", lambda t: (0.0, -value * t / width)))
    else:
        supports.append(Dirichlet("cylinder_top", lambda t: (0.0, -value * t)))
    return Scene.from_mesh_data(
        mesh,
        bodies=[Body("cylinder", steel), Body("block", steel)],
        contacts=[ContactPair("cylinder_contact", "block_contact")],
        dirichlet=supports,
        loads=loads,
    )


def patch_3d_pressed(
    pressure: float,
    gap: float,
    cell: str = "tetrahedron",
    quadrature_degree: int = 2,
    subdivisions: int = 4,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """The 3D contact patch test of :func:`patch` in steel, from a ``gap``: the upper block
    is held in the pressing direction only by the contact and pushed by the dead
    ``pressure``; the default augmentation parameter (``eps_N = None``)."""
    scene = patch(
        3,
        pressure,
        E=E_STEEL,
        quadrature_degree=quadrature_degree,
        subdivisions=subdivisions,
        cell=cell,
        gap=gap,
        comm=comm,
    )
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=None)
    return scene


def curved_pair(
    dim: int,
    comm: MPI.Comm = MPI.COMM_WORLD,
    E: float = 1.0,
    nu: float = 0.3,
    eps_N: float = 10.0,
    cell: str = "tetrahedron",
    order: int = 1,
) -> Scene:
    """Two bodies with curved contact surfaces and no supports (for Taylor tests).

    ``dim = 2``: a half disc above a block with a circular top; ``dim = 3``: a half cylinder
    above a block with a cylindrical top of crossed axis, or with ``cell="hexahedron"`` the
    hexahedral stacked boxes of :func:`~contact_ufl.verification.geometries.patch_3d` warped
    (:func:`warp_saddle`) so that their common surface is a saddle; the lower body is the
    finer (element size 0.1 against 1/6), so a partition into two ranks splits it and its
    master surface. ``order``: that of the geometry of the gmsh meshes (2: curved cells).
    """
    if dim == 3 and cell == "hexahedron":
        sm = geometries.patch_3d(cell=cell, h_lower=0.1, comm=comm)
        warp_saddle(sm.mesh)
        names = ("upper", "lower", "upper_contact", "lower_contact")
    elif dim == 2:
        sm = geometries.curved_2d(h_contact=0.05, h_far=0.3, order=order, comm=comm)
        names = ("cylinder", "block", "cylinder_contact", "block_contact")
    else:
        sm = geometries.cylinders_3d(h_contact=0.15, h_far=0.4, order=order, comm=comm)
        names = ("upper", "lower", "upper_contact", "lower_contact")
    return Scene.from_mesh_data(
        sm,
        bodies=[
            Body(names[0], NeoHookean(E, nu), "upper"),
            Body(names[1], NeoHookean(E, nu), "lower"),
        ],
        contacts=[ContactPair(names[2], names[3], eps_N=eps_N)],
    )


def warp_saddle(mesh: dolfinx.mesh.Mesh, depth: float = 0.2) -> None:
    """Move the nodes of a mesh of the unit-square boxes vertically (in place) by
    ``depth ((x - 1/2)^2 - (y - 1/2)^2 / 2)``: flat faces ``z = c`` become saddles."""
    x = mesh.geometry.x
    x[:, 2] += depth * ((x[:, 0] - 0.5) ** 2 - 0.5 * (x[:, 1] - 0.5) ** 2)


def plastic_indentation(
    depth: float = 0.02,
    yield_stress: float | None = 0.01,
    h_contact: float = 0.01,
    E_cylinder: float = 10.0,
    E_block: float = 1.0,
    nu: float = 0.3,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """A stiff half disc (R = 1) pressed into an elastoplastic block and lifted off again.

    The Hertz geometry (:func:`hertz_2d`); the block is :class:`J2Plasticity` with
    ``yield_stress`` (perfectly plastic; ``None``: Neo-Hookean, the elastic control). The
    disc's top moves down by ``depth`` from t = 0 to 1 and back up to its start from t = 1
    to 2: a plastic block keeps an imprint, an elastic one springs back.
    """
    hertz = hertz_2d(
        h_contact=h_contact, depth=depth, E=E_cylinder, nu=nu, E_flat=E_block, nu_flat=nu, comm=comm
    )
    scene, tags = hertz.scene, hertz.scene.tags
    cylinder, block = scene.bodies
    if yield_stress is not None:
        block = Body(block.tag, J2Plasticity(E_block, nu, yield_stress), block.name)

    def lowered(t: float) -> tuple[float, float]:
        return 0.0, -depth * (t if t <= 1.0 else max(2.0 - t, 0.0))

    return dataclasses.replace(
        scene,
        bodies=[cylinder, block],
        dirichlet=[
            Dirichlet(tags["block_bottom"], (0.0, 0.0)),
            Dirichlet(tags["cylinder_top"], lowered),
        ],
    )


def pushed_block(
    mu: float = 0.3,
    pressure: float = 0.01,
    push: float = 0.05,
    E: float = 1.0,
    nu: float = 0.3,
    subdivisions: int = 4,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """A block pressed onto a flat, then pushed tangentially (stick, then slip).

    The upper block of the 2D patch scene carries the dead pressure ``pressure`` on its top
    for pseudo-time 0 to 1 (then held); from t = 1 to 2 its top is moved horizontally by
    ``push (t - 1)``. The lower block is clamped at its bottom. The tangential contact force
    grows in stick and saturates at ``mu`` times the normal force when the block slides.
    """
    scene = patch(2, pressure, E, nu, subdivisions=subdivisions, mu=mu, comm=comm)
    tags = scene.tags
    return dataclasses.replace(
        scene,
        dirichlet=[
            Dirichlet(tags["lower_bottom"], (0.0, 0.0)),
            Dirichlet(tags["upper_top"], lambda t: push * max(t - 1.0, 0.0), component=0),
        ],
        loads=[DeadTraction(tags["upper_top"], lambda t: (0.0, -pressure * min(t, 1.0)))],
    )


def ironing(
    mu: float = 0.3,
    h_punch: float = 0.05,
    h_block: float = 0.2,
    depth: float = 1.0,
    slide: float = 10.0,
    master_normal: str = "smoothed",
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """The 2D "shallow ironing" problem (Yang, Laursen & Meng 2005; Poulios & Renard 2015).

    A Neo-Hookean block 12 x 4 (E = 6.896e8, nu = 0.32) clamped at its bottom, and a ten times
    stiffer punch 1.2 wide and 1.2 tall whose bottom is a circular segment of radius 0.75
    (:func:`~contact_ufl.verification.geometries.ironing_2d`), 0.2 above the block and 0.2 from its
    left end. The punch's top is pressed down by ``depth`` from t = 0 to 1 (0.8 into the block),
    then moved along the block by ``slide`` from t = 1 to 2. The slave surface is the punch's arc
    and sides (the finer mesh), the master surface the block's top, with the smoothed normal by
    default (the punch slides over many master vertices).
    """
    sm = geometries.ironing_2d(h_punch=h_punch, h_block=h_block, comm=comm)
    dirichlet = [
        Dirichlet("block_bottom", (0.0, 0.0)),
        Dirichlet("punch_top", _punch_path(depth, slide, 2)),
    ]
    return _ironing_scene(sm, mu, h_block, master_normal, dirichlet)


def _punch_path(depth: float, slide: float, dim: int) -> Callable[[float], tuple]:
    """The ironing punch top's motion: down by ``depth`` from t = 0 to 1, then along the
    block by ``slide`` from t = 1 to 2 (in 3D z held)."""

    def path(t: float) -> tuple:
        return (slide * max(t - 1.0, 0.0), -depth * min(t, 1.0)) + (0.0,) * (dim - 2)

    return path


def _ironing_scene(
    sm: MeshData, mu: float, h_block: float, master_normal: str, dirichlet: list
) -> Scene:
    """The shallow ironing's bodies (a Neo-Hookean block, E = 6.896e8, nu = 0.32, and a ten
    times stiffer punch) and its pair (the punch's arc and sides on the block's top, eps_N =
    E_block / h_block) on the mesh data ``sm`` of either ironing geometry."""
    E_block, E_punch, nu = 6.896e8, 6.896e9, 0.32
    pair = ContactPair(
        "punch_contact",
        "block_contact",
        eps_N=E_block / h_block,
        mu=mu,
        search_radius=1.0,
        master_normal=master_normal,
    )
    return Scene.from_mesh_data(
        sm,
        bodies=_solids(punch=NeoHookean(E_punch, nu), block=NeoHookean(E_block, nu)),
        contacts=[pair],
        dirichlet=dirichlet,
    )


def ironing_3d(
    mu: float = 0.3,
    h_die: float = 0.3,
    h_slab: float = 0.5,
    depth: float = 1.4,
    slide: float = 4.0,
    master_normal: str = "smoothed",
    slave: str = "slab",
    quadrature_degree: int | None = 2,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """The 3D ironing problem of Puso & Laursen (2004, example 2, "ironing").

    A Neo-Hookean slab 9 x 4 x 3 (E = 1, nu = 0.3) clamped at its bottom, and a die whose
    bottom is a cylinder of radius 3 with axis across the slab, 5.2 wide (overhanging the
    slab's width 4), a thousand times stiffer (E = 1000, nu = 0.499), its lowest line touching
    the slab 2.5 from its end (:func:`~contact_ufl.verification.geometries.ironing_3d`). The
    die's top is pressed down by ``depth`` (1.4) from t = 0 to 1, then moved along the slab
    by ``slide`` (4) from t = 1 to 2.

    The slave surface is the slab's top by default (``slave="slab"``), the master surface
    the die's cylinder, with the smoothed normal (node fans): the die is wider than the
    slab, so no slave point in contact ever reaches the master's boundary. With
    ``slave="die"`` the die's points beyond the slab's side edges (which bulge out under
    the die) are paired and released in turn at the master's boundary edge, a 2-cycle of
    Newton that stalls the pressing with mu = 0.3 and makes every sliding step take 11 to
    29 iterations with mu = 0 (3 to 5 with ``slave="slab"``). ``quadrature_degree`` is that
    of the contact integrals (2: three points per triangle; each point of the smoothed
    normal carries 27 master nodes, and the cost of the tangent grows with the square of
    the points per facet; ``None``: the pair's default, 3).

    The data are those of the LLNL Smith example ``die-on-slab`` that reproduces the
    publication (the publication's pressing time 0.2 and total time 1.5 are mapped to 1 and 2
    here; the path is the same).
    """
    if slave not in ("slab", "die"):
        raise ValueError(f"slave must be 'slab' or 'die', got {slave!r}")
    sm = geometries.ironing_3d(h_die=h_die, h_slab=h_slab, comm=comm)
    E_slab = 1.0
    surfaces = ["slab_contact", "die_contact"]
    if slave == "die":
        surfaces.reverse()
    pair = ContactPair(
        *surfaces,
        eps_N=E_slab / h_slab,
        mu=mu,
        search_radius=1.0,
        quadrature_degree=quadrature_degree,
        master_normal=master_normal,
    )
    with warnings.catch_warnings():  # the die is near rigid: its locking does not matter
        warnings.simplefilter("ignore", NearlyIncompressibleWarning)
        die = NeoHookean(1000.0 * E_slab, 0.499)
    return Scene.from_mesh_data(
        sm,
        bodies=_solids(die=die, slab=NeoHookean(E_slab, 0.3)),
        contacts=[pair],
        dirichlet=[
            Dirichlet("slab_bottom", (0.0, 0.0, 0.0)),
            Dirichlet("die_top", lambda t: (slide * max(t - 1.0, 0.0), 0.0, -depth * min(t, 1.0))),
        ],
    )


@dataclass
class BeamsScene:
    """The two-beam showcase scene and the data of its beam-theory estimates."""

    scene: Scene
    geometry: geometries.BeamPair
    E: float
    nu: float
    load: float

    @property
    def bending_stiffness(self) -> float:
        """``EI`` of the upper beam (bending towards the lower one)."""
        g = self.geometry
        return self.E * g.width * g.height**3 / 12.0

    @property
    def lower_bending_stiffness(self) -> float:
        """``EI`` of the lower beam."""
        g = self.geometry
        return self.E * g.lower_width * g.lower_height**3 / 12.0

    def two_springs(self, P: float) -> tuple[float, float]:
        """Beam-theory estimate ``(N, w)`` of the contact force and the upper tip deflection.

        The upper beam is a cantilever of length ``L`` with tip stiffness ``k1 = 3 EI / L^3``;
        the lower one, loaded at ``a = lower_arm`` from its clamp, has ``k2 = 3 EI_2 / a^3``.
        Contact starts at ``P_c = k1 gap``; then ``N = (P - P_c) k2 / (k1 + k2)`` and the tip
        deflects by ``gap + N / k2`` (before, by ``P / k1`` and ``N = 0``). A point contact:
        it holds while only the tip corner touches (with ``clamps = "opposite"``, or at
        small load).
        """
        g = self.geometry
        k1 = 3.0 * self.bending_stiffness / g.length**3
        k2 = 3.0 * self.lower_bending_stiffness / g.lower_arm**3
        P_c = k1 * g.gap
        if P <= P_c:
            return 0.0, P / k1
        N = (P - P_c) * k2 / (k1 + k2)
        return N, g.gap + N / k2


def beams(
    mu: float = 0.0,
    load: float = 5.0,
    divisions: int = 4,
    E: float = 1.0e3,
    nu: float = 0.3,
    geometry: geometries.BeamPair | None = None,
    eps_factor: float = 0.1,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> BeamsScene:
    """Two Neo-Hookean cantilevers, the upper one pushed at its free tip by a follower force.

    The beams of :func:`~contact_ufl.verification.geometries.beams_3d` (by default clamped on
    the same side, the lower one nearer the upper tip:
    :class:`~contact_ufl.verification.geometries.BeamPair`). The free end section of the upper
    beam carries the follower force :class:`FollowerForce` of magnitude ``load * t * EI / L^2``
    (``t`` the pseudo-time), directed along the carried reference direction ``-e_z``: it stays
    perpendicular to the deformed beam axis. The upper beam bends down and its tip meets the
    lower beam; the lower beam, pressed by a shorter lever, turns faster, and the upper beam's
    underside bends onto it and slides along it (with ``clamps = "opposite"`` only the tip
    corner touches). Slave: the bottom of the upper beam above the lower one; master: the top of
    the lower beam from ``master_start``; ``eps_N = eps_factor E / h`` with ``h`` the upper
    element size.

    Parameters
    ----------
    mu
        Friction coefficient.
    load
        Final follower force in units of ``EI / L^2``.
    divisions
        Hexahedra through the height of each beam.
    E, nu
        Neo-Hookean material of both beams.
    geometry
        Lengths (default :class:`contact_ufl.verification.geometries.BeamPair`).
    eps_factor
        Scale of the augmentation parameter. The default 0.1 keeps ``eps_N`` nearer the
        stiffness of slender beams than ``E / h`` (which is the stiffness scale of a solid):
        with ``eps_factor = 1`` the first Newton iterate at the first touch penetrates so
        deeply that the active set cycles and the step is cut back.
    """
    geometry = geometry or geometries.BeamPair()
    sm = geometries.beams_3d(geometry, divisions=divisions, comm=comm)
    material = NeoHookean(E, nu)
    EI = E * geometry.width * geometry.height**3 / 12.0
    P_end = load * EI / geometry.length**2
    h = geometry.height / divisions
    pair = ContactPair(
        "upper_contact",
        "lower_contact",
        eps_N=eps_factor * E / h,
        mu=mu,
        search_radius=geometry.gap + geometry.height,
        quadrature_degree=3,
        quadrature_rule="lobatto",
    )
    scene = Scene.from_mesh_data(
        sm,
        bodies=_solids(upper=material, lower=material),
        contacts=[pair],
        dirichlet=[Dirichlet(clamp, (0.0, 0.0, 0.0)) for clamp in ("upper_clamp", "lower_clamp")],
        loads=[FollowerForce("upper_tip", lambda t: P_end * t, (0.0, 0.0, -1.0))],
    )
    return BeamsScene(scene, geometry, E, nu, load)


# -- rigid obstacles ---------------------------------------------------------------------------


def hertz_on_rigid_flat(
    h_contact: float = 0.005,
    depth: float = 0.005,
    E: float = 1.0,
    nu: float = 0.3,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> HertzScene:
    """Plane-strain Hertz on a rigid flat: the half disc of :func:`hertz_2d` (R = 1) pressed
    by ``depth`` onto the :class:`~contact_ufl.contact.obstacles.RigidPlane` ``y = 0`` (the
    block's top made rigid). The block stays in the scene, clamped and unloaded (no pair
    involves it); ``E* = E / (1 - nu^2)`` (Johnson 1985, 4.2, with a rigid flat).
    """
    hertz = hertz_2d(h_contact=h_contact, depth=depth, E=E, nu=nu, comm=comm)
    return HertzScene(_on_rigid_flat(hertz.scene), 1.0, E / (1.0 - nu**2), h_contact)


def block_under_circle(
    n: int = 8,
    depth: float = 0.05,
    radius: float = 0.5,
    E: float = 1.0,
    nu: float = 0.3,
    mu: float = 0.0,
    slide: float = 0.0,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> tuple[Scene, RigidSphere]:
    """A Neo-Hookean block ``[-0.5, 0.5] x [0, 0.5]`` (``2n x n`` squares cut into
    triangles) clamped at its bottom (facet tag 1), its top (tag 2, the slave) pressed by a
    rigid circle of ``radius`` that touches it at ``(0, 0.5)`` and moves by ``(slide t,
    -depth t)`` (a :class:`~contact_ufl.contact.obstacles.RigidSphere` with a motion);
    friction coefficient ``mu``, default ``eps_N``. Returns the scene and the obstacle."""
    mesh = dolfinx.mesh.create_rectangle(
        comm,
        [np.array([-0.5, 0.0]), np.array([0.5, 0.5])],
        [2 * n, n],
        dolfinx.mesh.CellType.triangle,
        ghost_mode=dolfinx.mesh.GhostMode.shared_facet,
    )
    cells, facets = geometries.tag_single_body(
        mesh, [lambda x: np.isclose(x[1], 0.0), lambda x: np.isclose(x[1], 0.5)]
    )
    circle = RigidSphere((0.0, 0.5 + radius), radius, motion=lambda t: (slide * t, -depth * t))
    scene = Scene(
        mesh,
        cells,
        facets,
        bodies=[Body(1, NeoHookean(E, nu), "block")],
        contacts=[ContactPair(2, circle, mu=mu)],
        dirichlet=[Dirichlet(1, (0.0, 0.0))],
    )
    return scene, circle


def pushed_block_on_plane(
    mu: float = 0.3,
    pressure: float = 0.01,
    push: float = 0.05,
    nu: float = 0.3,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """:func:`pushed_block` with the lower block's top made rigid: the upper block pressed by
    ``pressure`` onto the :class:`~contact_ufl.contact.obstacles.RigidPlane` ``y = 0`` from
    t = 0 to 1, then its top moved horizontally by ``push (t - 1)`` (stick, then slip). The
    lower block stays, clamped and unloaded (no pair involves it). With ``nu > 0`` the
    pressed block widens on the rigid flat, so its edges slip already while it is pressed;
    with ``nu = 0`` it sticks everywhere until the push nears ``mu`` times the load."""
    return _on_rigid_flat(pushed_block(mu=mu, pressure=pressure, push=push, nu=nu, comm=comm))


def on_meshes_of_their_own(scene: Scene) -> Scene:
    """The one-mesh ``scene`` with each body on a mesh of its own (a submesh of its cells,
    the same geometry and partition): each body then has its own displacement field.

    Supports and loads go to the meshes whose facets they tag; each contact pair names the
    domains of its two surfaces (integer tags need them in a scene of several meshes).
    """
    data = MeshData(scene.mesh, scene.cell_tags, scene.facet_tags, dict(scene.groups))
    parts = geometries.split_by_cells(data, [b.tag for b in scene.bodies])
    comm = scene.mesh.comm

    def holds(part: MeshData, tag: int) -> bool:
        return comm.allreduce(len(part.facet_tags.find(tag)), MPI.SUM) > 0

    domains = [
        Domain(
            part.mesh,
            part.cell_tags,
            part.facet_tags,
            [body],
            [d for d in scene.dirichlet if holds(part, d.tag)],
            [ld for ld in scene.loads if holds(part, ld.tag)],
            groups=part.groups,
            name=body.name or f"body {body.tag}",
        )
        for part, body in zip(parts, scene.bodies, strict=True)
    ]

    def domain_of(tag) -> int | None:
        if not isinstance(tag, int | np.integer):
            return None
        (k,) = [k for k, part in enumerate(parts) if holds(part, tag)]
        return k

    contacts = [
        dataclasses.replace(p, slave_domain=domain_of(p.slave), master_domain=domain_of(p.master))
        for p in scene.contacts
    ]
    return Scene(domains=domains, contacts=contacts)


def inflated_sphere(
    n: int = 32,
    law=None,
    pressure: float = 1.0,
    R: float = 1.0,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """Free inflation of a spherical membrane: the octant ``x, y, z >= 0`` of the sphere of
    radius ``R`` (``n`` triangles along each quarter arc), held normally on its three
    symmetry planes, under a follower pressure ``pressure * t``.

    The default law is :class:`~contact_ufl.membranes.MembraneNeoHookean` with ``mu = 1``,
    ``t0 = 0.01``: its pressure maximum is ``2 mu t0 / R (7^(-1/6) - 7^(-7/6))`` at the
    stretch ``7^(1/6)`` (:func:`~contact_ufl.verification.analytic.sphere_inflation_neo_hookean`).
    """
    from contact_ufl.loads import FollowerPressure
    from contact_ufl.membranes import MembraneNeoHookean
    from contact_ufl.verification import membrane_meshes

    law = law or MembraneNeoHookean(1.0, 0.01)
    mesh = membrane_meshes.sphere_octant(comm, R, n)
    planes = {"x0": (0, 0.0), "y0": (1, 0.0), "z0": (2, 0.0)}
    data = membrane_meshes.with_tags(mesh, planes)
    domain = Domain.from_mesh_data(
        data,
        bodies=[Body("membrane", law)],
        dirichlet=[Dirichlet(name, 0.0, component=axis) for name, (axis, _) in planes.items()],
        loads=[FollowerPressure("membrane", lambda t: pressure * t)],
        name="sphere",
    )
    return Scene(domains=[domain])


def squeezed_ring(
    depth: float = 0.8,
    radii: tuple[float, float] = (0.75, 1.0),
    cells: tuple[int, int] = (4, 40),
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """A ring squeezed between two plates until its hole closes on itself (self-contact).

    The half ring ``r`` in ``radii``, ``x >= 0`` (``cells``: quadrilaterals across and
    along; ``u_x = 0`` on the cut ``x = 0``, tag 1; Neo-Hookean, ``E = 1``, ``nu = 0.3``),
    squeezed between the rigid plates ``y = +-r_o`` moved towards each other by ``depth``
    each at ``t = 1`` (frictionless pairs of the outer surface, tag 3): the hole flattens
    until its upper and lower arcs meet across ``y = 0``, a self-contact of the inner
    surface (tag 2).
    """
    ri, ro = radii
    mesh = dolfinx.mesh.create_rectangle(
        comm,
        [[0.0, 0.0], [1.0, 1.0]],
        list(cells),
        dolfinx.mesh.CellType.quadrilateral,
        ghost_mode=dolfinx.mesh.GhostMode.shared_facet,
    )
    s, t = mesh.geometry.x[:, 0].copy(), mesh.geometry.x[:, 1].copy()
    r, theta = ri + s * (ro - ri), np.pi * (t - 0.5)
    mesh.geometry.x[:, 0], mesh.geometry.x[:, 1] = r * np.cos(theta), r * np.sin(theta)
    radius = lambda x: np.hypot(x[0], x[1])  # noqa: E731
    cell_tags, facet_tags = geometries.tag_single_body(
        mesh,
        [
            lambda x: np.isclose(x[0], 0.0),
            lambda x: np.isclose(radius(x), ri),
            lambda x: np.isclose(radius(x), ro),
        ],
    )
    top = RigidPlane((0.0, ro), (0.0, -1.0), motion=lambda t: (0.0, -depth * t))
    bottom = RigidPlane((0.0, -ro), (0.0, 1.0), motion=lambda t: (0.0, depth * t))
    return Scene(
        mesh,
        cell_tags,
        facet_tags,
        [Body(1, NeoHookean(1.0, 0.3))],
        contacts=[ContactPair(3, top), ContactPair(3, bottom), ContactPair(2, 2)],
        dirichlet=[Dirichlet(1, 0.0, component=0)],
    )


def surface_as_membrane(
    scene: Scene, facet_tag: int, body_tag: int, law, direction, name: str = "membrane"
) -> Domain:
    """A membrane (string) on a mesh of its own made of the facets ``facet_tag`` of the
    one-mesh ``scene`` (a surface of a solid taken alone), its cells tagged ``body_tag``
    (also its contact surface) and its boundary (edges; the end points of a string) tagged 1
    (group ``"<name>_boundary"``), with the material ``law`` and its normal along
    ``direction`` (:class:`~contact_ufl.scene.Domain`)."""
    mesh = scene.mesh
    tdim = mesh.topology.dim
    facets = scene.facet_tags.find(facet_tag)
    sub = dolfinx.mesh.create_submesh(mesh, tdim - 1, facets)[0]
    imap = sub.topology.index_map(tdim - 1)
    cells = np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32)
    cell_tags = dolfinx.mesh.meshtags(sub, tdim - 1, cells, np.full_like(cells, body_tag))
    sub.topology.create_entities(tdim - 2)
    sub.topology.create_connectivity(tdim - 2, tdim - 1)
    boundary = dolfinx.mesh.exterior_facet_indices(sub.topology)
    facet_tags = dolfinx.mesh.meshtags(sub, tdim - 2, boundary, np.ones_like(boundary))
    return Domain(
        sub,
        cell_tags,
        facet_tags,
        [Body(body_tag, law, name)],
        groups={name: (tdim - 1, body_tag), f"{name}_boundary": (tdim - 2, 1)},
        name=name,
        direction=direction,
    )


def with_membrane(scene: Scene, side: str, law, direction) -> Scene:
    """The two-body one-mesh ``scene`` (one contact pair) with one body replaced by a
    membrane made of its contact surface (:func:`surface_as_membrane`): ``side`` is
    ``"master"`` or ``"slave"`` (the other body keeps a mesh of its own), or ``"both"``."""
    split = on_meshes_of_their_own(scene)
    (pair,) = split.contacts
    domains, changes = list(split.domains), {}
    for role in ("slave", "master") if side == "both" else (side,):
        k = getattr(pair, f"{role}_domain")
        body_tag = split.domains[k].bodies[0].tag
        domains[k] = surface_as_membrane(scene, getattr(pair, role), body_tag, law, direction)
        changes[role] = body_tag
    return Scene(domains=domains, contacts=[dataclasses.replace(pair, **changes)])


def membrane_sandwich(dim: int = 2, pressure: float = 0.01, law=None) -> Scene:
    """A membrane (string) between the two blocks of the contact patch test (:func:`patch`):
    the upper block presses on the membrane (a master, two-sided), the membrane on the lower
    block (a slave), under the uniform pressure on top. The blocks are held normally on all
    their sides (confined compression: no lateral displacement) and the membrane's boundary
    in its plane. Exact solution: homogeneous, with the multipliers of both pairs equal to
    ``pressure`` (the membrane stays flat, unstretched, and carries no tension).
    """
    from contact_ufl.membranes import MembraneNeoHookean

    law = law or MembraneNeoHookean(1.0, 0.01)
    # the rules of the solid patch tests (tests/test_patch.py)
    degree, subdivisions = (3, 8) if dim == 2 else (2, 4)
    scene = patch(dim, pressure, quadrature_degree=degree, subdivisions=subdivisions)
    split = on_meshes_of_their_own(scene)
    far = {0: "right"} if dim == 2 else {0: "x1", 1: "y1"}
    upper, lower = (
        dataclasses.replace(
            d,
            dirichlet=[
                *d.dirichlet,
                *(Dirichlet(f"{d.name}_{face}", 0.0, component=k) for k, face in far.items()),
            ],
        )
        for d in split.domains
    )
    (pair,) = split.contacts
    up = np.eye(dim)[dim - 1]
    membrane = surface_as_membrane(scene, pair.master, 100, law, up)
    in_plane = [Dirichlet("membrane_boundary", 0.0, component=k) for k in range(dim - 1)]
    membrane = dataclasses.replace(membrane, dirichlet=in_plane)
    on_membrane = dataclasses.replace(pair, master=100, master_domain=2)
    membrane_on_lower = dataclasses.replace(pair, slave=100, slave_domain=2, master_domain=1)
    return Scene(domains=[upper, lower, membrane], contacts=[on_membrane, membrane_on_lower])


# -- membranes for contact: the plates-and-tube problem and the drumhead ------------------------


@dataclass(frozen=True)
class PlatesSchedule:
    """Pseudo-time schedule of the plates-and-tube problem: inflate, then close the plates.

    For ``0 <= t <= t_inflate`` the follower pressure grows linearly to ``pressure`` with the
    plates at ``y = +-r_start`` (above the free radius: no contact); for ``t_inflate <= t <=
    1`` the pressure is held and the plates move linearly to ``y = +-r_end``. The pressure is
    the control (not the enclosed volume); frictionless contact makes the end state that of
    :func:`~contact_ufl.verification.analytic.tube_between_plates` at ``r_end``, whatever the
    path, and so every converged step after first contact (at ``r = r_free``).

    Attributes
    ----------
    pressure, r_start, r_end, t_inflate
        As above (``r_end < r_start``, ``0 < t_inflate < 1``).
    """

    pressure: float
    r_start: float
    r_end: float
    t_inflate: float = 0.25

    def __post_init__(self) -> None:
        if not 0.0 < self.t_inflate < 1.0:
            raise ValueError(f"t_inflate must lie in (0, 1), got {self.t_inflate}")
        if not 0.0 < self.r_end < self.r_start:
            raise ValueError(f"need 0 < r_end < r_start, got {self.r_end}, {self.r_start}")

    def p(self, t: float) -> float:
        """The pressure at pseudo-time ``t``."""
        return self.pressure * min(t / self.t_inflate, 1.0)

    def half_separation(self, t: float) -> float:
        """The plates' distance ``r`` from the axis at pseudo-time ``t``."""
        s = min(max((t - self.t_inflate) / (1.0 - self.t_inflate), 0.0), 1.0)
        return self.r_start + s * (self.r_end - self.r_start)

    def plate(self, dim: int, side: float = 1.0) -> RigidPlane:
        """The plate ``y = side * r(t)`` (``side`` +1 upper, -1 lower) in ``dim`` dimensions,
        its normal towards the tube."""
        e_y = np.eye(dim)[1]
        r0 = self.r_start

        def motion(t: float) -> tuple[float, ...]:
            return tuple(side * (self.half_separation(t) - r0) * e_y)

        return RigidPlane(tuple(side * r0 * e_y), tuple(-side * e_y), motion)


def tube_for_plates(
    schedule: PlatesSchedule,
    dim: int = 2,
    n: int = 32,
    law=None,
    R0: float = 1.0,
    quarters: int = 1,
    length: float = 0.1,
    n_axial: int = 1,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Domain:
    """The tube of the plates-and-tube problem as a membrane domain (no contact pair yet).

    ``dim`` 2: the string ring of :func:`~contact_ufl.verification.membrane_meshes.string_ring`
    (``quarters`` 1, 2 or 4, ``n`` intervals per quarter); ``dim`` 3: the quarter tube of
    :func:`~contact_ufl.verification.membrane_meshes.tube_quarter` (``n`` cells around,
    ``n_axial`` along ``length``, quadrilaterals), held at axial stretch 1 (``u_z = 0`` on its
    ends ``"z0"``, ``"z1"``). Supports ``u_x = 0`` on ``"x0"`` and ``u_y = 0`` on ``"y0"``
    (symmetry; see ``string_ring``); the follower pressure ``schedule.p(t)`` on the cells
    ``"tube"``, along the default outward ``n0``. The default law is
    :class:`~contact_ufl.membranes.MembraneNeoHookean` with ``mu = 1``, ``t0 = 0.01``.

    The upper plate is ``schedule.plate(dim)`` (and the lower ``schedule.plate(dim, -1)`` for
    a whole ring); the contact surface is the cells ``"tube"``. On a quarter the plate force
    is half the closed form's ``p w`` (the contact zone ``0 <= x <= w/2``), in 3D times
    ``length``.
    """
    from contact_ufl.loads import FollowerPressure
    from contact_ufl.membranes import MembraneNeoHookean
    from contact_ufl.verification import membrane_meshes

    law = law or MembraneNeoHookean(1.0, 0.01)
    dirichlet = [Dirichlet("x0", 0.0, component=0), Dirichlet("y0", 0.0, component=1)]
    if dim == 2:
        data = membrane_meshes.string_ring(comm, R0, n, quarters)
    elif dim == 3:
        data = membrane_meshes.tube_quarter(comm, R0, n, length, n_axial)
        dirichlet += [Dirichlet(end, 0.0, component=2) for end in ("z0", "z1")]
    else:
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    return Domain.from_mesh_data(
        data,
        bodies=[Body("tube", law)],
        dirichlet=dirichlet,
        loads=[FollowerPressure("tube", schedule.p)],
        name="tube",
    )


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


# -- membranes in contact with solids and obstacles: verification scenes ----------------------


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


def ironing_plane_strain(
    mu: float = 0.3,
    thickness: float | None = 0.1,
    h_punch: float = 0.05,
    h_block: float = 0.2,
    depth: float = 1.0,
    slide: float = 10.0,
    master_normal: str = "smoothed",
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> Scene:
    """The 2D shallow ironing of :func:`ironing` (the same geometry, materials, loading,
    ``eps_N`` and ``mu``) on a quadrilateral plane mesh, solved in 2D (``thickness=None``)
    or on that mesh extruded through ``thickness`` by one layer of hexahedra
    (:func:`~contact_ufl.verification.geometries.ironing_extruded`) with u_z = 0 on both
    faces z = 0 and z = thickness (``"plane_faces"``): plane strain solved by the 3D
    machinery (closest points on bilinear quadrilaterals, the node-fan smoothed normal,
    Coulomb friction with a 3D ``lambda_T``). Its solution does not vary along z, and its
    forces per unit thickness are those of the 2D scene on the same plane mesh, but for
    what the two machineries do differently: the 2D smoothed normal averages the unit
    normals of the two segments at a node with equal weights, the 3D one weights the
    facets by their area (here the segments' lengths); with ``master_normal="facet"`` there
    is no such difference.

    The punch's top is pressed down by ``depth`` from t = 0 to 1, then moved by ``slide``
    along the block from t = 1 to 2 (z held); the slave is the punch's arc and sides, the
    master the block's top.
    """
    sm = geometries.ironing_extruded(
        thickness=thickness, h_punch=h_punch, h_block=h_block, comm=comm
    )
    dim = 2 if thickness is None else 3
    dirichlet = [
        Dirichlet("block_bottom", (0.0,) * dim),
        Dirichlet("punch_top", _punch_path(depth, slide, dim)),
    ]
    if thickness is not None:
        dirichlet.append(Dirichlet("plane_faces", 0.0, component=2))
    return _ironing_scene(sm, mu, h_block, master_normal, dirichlet)
