"""Membranes: the free inflation of a sphere, a solid's contact surface made a membrane
(:func:`with_membrane`; the membrane between the blocks of the patch test), and the tube
inflated between rigid plates (:class:`PlatesSchedule`, :func:`tube_for_plates`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import RigidPlane
from contact_ufl.loads import Dirichlet
from contact_ufl.scene import Body, Domain, Scene
from contact_ufl.verification.scenes.pairs import on_meshes_of_their_own
from contact_ufl.verification.scenes.patches import patch


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
