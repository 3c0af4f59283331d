"""Ready-made scenes of the verification problems, shared by tests, demos and benchmarks.

Each function meshes its geometry (:mod:`contact_ufl.verification.geometries`) and returns a
:class:`~contact_ufl.scene.Scene` with the bodies, supports, loads and contact pair, plus the
data needed to compare with the analytic solution.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair, RigidPlane, RigidSphere
from contact_ufl.loads import DeadTraction, Dirichlet, FollowerForce
from contact_ufl.materials import LinearElastic, NeoHookean
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.scene import Body, Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.analytic import plane_strain_modulus


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
    """
    E_flat = E if E_flat is None else E_flat
    sm = geometries.hertz_2d(h_contact=h_contact, h_far=h_far, gap=gap, comm=comm)
    tags = sm.tags
    R = rotation_2d(rotation)
    sm.mesh.geometry.x[:, :2] = sm.mesh.geometry.x[:, :2] @ R.T
    scene = Scene(
        sm.mesh,
        sm.cell_tags,
        sm.facet_tags,
        bodies=[
            Body(tags["cylinder"], NeoHookean(E, nu), "cylinder"),
            Body(tags["block"], NeoHookean(E_flat, nu_flat), "block"),
        ],
        contacts=[
            ContactPair(
                tags["cylinder_contact"],
                tags["block_contact"],
                eps_N=eps_factor * E / h_contact,
                mu=mu,
                quadrature_degree=quadrature_degree,
            )
        ],
        dirichlet=[
            Dirichlet(tags["block_bottom"], (0.0, 0.0)),
            Dirichlet(
                tags["cylinder_top"],
                lambda t: R @ (shift * max(t - 1.0, 0.0), -depth * min(t, 1.0)),
            ),
        ],
        tags=tags,
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
    quadrature_degree: int | None = 2,
    quadrature_subdivisions: int = 1,
    h_edge: float | None = None,
    edge_width: float | None = None,
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
        ball's: 1.3 gave p0 2.3% high where 1.0 gives 1.9%).
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
        Quadrature rule of the contact integrals (see :class:`ContactPair`). Degree 2 (three
        points per slave facet) gave the errors of the pair's default degree 3 (six points)
        to 0.1%, with half the points to search.
    """
    if flat not in ("elastic", "rigid"):
        raise ValueError(f"flat must be 'elastic' or 'rigid', not {flat!r}")
    rigid = flat == "rigid"
    E_flat = E if E_flat is None else E_flat
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
    tags = sm.tags
    material = NeoHookean(E, nu)
    traction = np.zeros(dim)
    traction[-1] = -pressure
    supports = [Dirichlet(tags["lower_bottom"], 0.0, component=dim - 1)]
    supports += [
        Dirichlet(tags[name], 0.0, component=k) for k, names in sides.items() for name in names
    ]
    return Scene(
        sm.mesh,
        sm.cell_tags,
        sm.facet_tags,
        bodies=[Body(tags["upper"], material, "upper"), Body(tags["lower"], material, "lower")],
        contacts=[
            ContactPair(
                tags["upper_contact"],
                tags["lower_contact"],
                eps_N=10.0 * E,
                mu=mu,
                quadrature_degree=quadrature_degree,
                quadrature_subdivisions=subdivisions,
            )
        ],
        dirichlet=supports,
        loads=[DeadTraction(tags["upper_top"], lambda t: traction * t)],
        tags=tags,
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
    """
    if driven_by not in ("force", "displacement"):
        raise ValueError(f"driven_by must be 'force' or 'displacement', not {driven_by!r}")
    mesh = geometries.hertz_2d(h_contact=h_contact, h_far=0.2, gap=gap, comm=comm)
    steel = NeoHookean(E_STEEL, 0.3)
    supports = [Dirichlet("block_bottom", (0.0, 0.0))]
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
    dim: int, comm: MPI.Comm = MPI.COMM_WORLD, E: float = 1.0, nu: float = 0.3, eps_N: float = 10.0
) -> Scene:
    """Two bodies with curved contact surfaces and no supports (for Taylor tests).

    ``dim = 2``: a half disc above a block with a circular top; ``dim = 3``: a half cylinder
    above a block with a cylindrical top of crossed axis.
    """
    if dim == 2:
        sm = geometries.curved_2d(h_contact=0.05, h_far=0.3, comm=comm)
        names = ("cylinder", "block", "cylinder_contact", "block_contact")
    else:
        sm = geometries.cylinders_3d(h_contact=0.15, h_far=0.4, comm=comm)
        names = ("upper", "lower", "upper_contact", "lower_contact")
    tags = sm.tags
    return Scene(
        sm.mesh,
        sm.cell_tags,
        sm.facet_tags,
        bodies=[
            Body(tags[names[0]], NeoHookean(E, nu), "upper"),
            Body(tags[names[1]], NeoHookean(E, nu), "lower"),
        ],
        contacts=[ContactPair(tags[names[2]], tags[names[3]], eps_N=eps_N)],
        tags=tags,
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
    tags = sm.tags
    E_block, E_punch, nu = 6.896e8, 6.896e9, 0.32
    return Scene(
        sm.mesh,
        sm.cell_tags,
        sm.facet_tags,
        bodies=[
            Body(tags["punch"], NeoHookean(E_punch, nu), "punch"),
            Body(tags["block"], NeoHookean(E_block, nu), "block"),
        ],
        contacts=[
            ContactPair(
                tags["punch_contact"],
                tags["block_contact"],
                eps_N=E_block / h_block,
                mu=mu,
                search_radius=1.0,
                master_normal=master_normal,
            )
        ],
        dirichlet=[
            Dirichlet(tags["block_bottom"], (0.0, 0.0)),
            Dirichlet(
                tags["punch_top"], lambda t: (slide * max(t - 1.0, 0.0), -depth * min(t, 1.0))
            ),
        ],
        tags=tags,
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
    tags = sm.tags
    material = NeoHookean(E, nu)
    EI = E * geometry.width * geometry.height**3 / 12.0
    P_end = load * EI / geometry.length**2
    h = geometry.height / divisions
    scene = Scene(
        sm.mesh,
        sm.cell_tags,
        sm.facet_tags,
        bodies=[Body(tags["upper"], material, "upper"), Body(tags["lower"], material, "lower")],
        contacts=[
            ContactPair(
                tags["upper_contact"],
                tags["lower_contact"],
                eps_N=eps_factor * E / h,
                mu=mu,
                search_radius=geometry.gap + geometry.height,
                quadrature_degree=3,
                quadrature_rule="lobatto",
            )
        ],
        dirichlet=[
            Dirichlet(tags["upper_clamp"], (0.0, 0.0, 0.0)),
            Dirichlet(tags["lower_clamp"], (0.0, 0.0, 0.0)),
        ],
        loads=[FollowerForce(tags["upper_tip"], lambda t: P_end * t, (0.0, 0.0, -1.0))],
        tags=tags,
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
    scene = hertz.scene
    pair = dataclasses.replace(scene.contacts[0], master=RigidPlane((0.0, 0.0), (0.0, 1.0)))
    scene = dataclasses.replace(scene, contacts=[pair])
    return HertzScene(scene, 1.0, E / (1.0 - nu**2), h_contact)


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
    scene = pushed_block(mu=mu, pressure=pressure, push=push, nu=nu, comm=comm)
    pair = dataclasses.replace(scene.contacts[0], master=RigidPlane((0.0, 0.0), (0.0, 1.0)))
    return dataclasses.replace(scene, contacts=[pair])
