"""The ironing problems: the 2D shallow ironing (:func:`ironing`; on a quadrilateral mesh,
in 2D or extruded in plane strain, :func:`ironing_plane_strain`) and the 3D die on a slab
(:func:`ironing_3d`).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.gmshio import MeshData
from contact_ufl.loads import Dirichlet
from contact_ufl.materials import (
    NearlyIncompressibleWarning,
    NeoHookean,
)
from contact_ufl.scene import Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.scenes._common import _solids


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
