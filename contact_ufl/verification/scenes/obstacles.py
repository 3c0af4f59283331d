"""Solids on rigid obstacles: Hertz and the pushed block on a rigid flat, a block under a
rigid circle, and a ring squeezed between rigid plates until its hole closes on itself
(self-contact).
"""

from __future__ import annotations

import dataclasses

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact import ContactPair, RigidPlane, RigidSphere
from contact_ufl.loads import Dirichlet
from contact_ufl.materials import (
    NeoHookean,
)
from contact_ufl.scene import Body, Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.scenes.hertz import HertzScene, hertz_2d
from contact_ufl.verification.scenes.patches import pushed_block


def _on_rigid_flat(scene: Scene) -> Scene:
    """``scene`` with the master surface of its contact pair made the rigid plane ``y = 0``
    (:class:`~contact_ufl.contact.obstacles.RigidPlane`, normal ``+y``)."""
    pair = dataclasses.replace(scene.contacts[0], master=RigidPlane((0.0, 0.0), (0.0, 1.0)))
    return dataclasses.replace(scene, contacts=[pair])


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
