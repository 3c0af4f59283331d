"""Hertz scenes with their analytic data: the half disc (2D, plane strain) and the half ball
(3D, quarter model) pressed on a block; the disc driven by a force or a displacement, and
pressed into an elastoplastic block and lifted off again.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair, RigidPlane
from contact_ufl.loads import DeadTraction, Dirichlet
from contact_ufl.materials import (
    LinearElastic,
    NeoHookean,
)
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.scene import Body, Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.analytic import plane_strain_modulus
from contact_ufl.verification.scenes._common import E_STEEL, _solids


def rotation_2d(angle: float) -> np.ndarray:
    """The 2x2 rotation matrix of ``angle`` (radians)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


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
    step of the disc free to turn says so (:meth:`StepSolver.diagnose
    <contact_ufl.strategies.StepSolver.diagnose>`).
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
