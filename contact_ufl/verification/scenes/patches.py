"""Contact patch tests: two stacked blocks under a uniform pressure (:func:`patch`), the 3D
one in steel from a gap (:func:`patch_3d_pressed`), and the upper block pushed
tangentially once pressed (:func:`pushed_block`: stick, then slip).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.loads import DeadTraction, Dirichlet
from contact_ufl.materials import (
    NeoHookean,
)
from contact_ufl.scene import Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.scenes._common import E_STEEL, _solids


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
