"""The closest-point mapping between non-matching surfaces, in Python.

For every slave quadrature point the search finds the closest point on the master surface:
the master facets of all ranks that can be within the search radius of this rank's slave
points are exchanged (a bounding-box filter), put in a rank-independent order (so that ties
between equidistant facets break the same way on any number of ranks), and projected onto
by the vectorised kernels of :mod:`.projection`. Points whose closest point lies on the
boundary of the master surface and off its normal are released (they are beyond the
surface, not on it).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact.facets import on_edges
from contact_ufl.contact.master import MeshMaster, smoothed_normals, smoothed_normals_3d
from contact_ufl.contact.projection import Projection, TreeCache, closest_points
from contact_ufl.contact.slave import SlaveSurface
from contact_ufl.errors import collective_check
from contact_ufl.layout import StackedLayout


@dataclass
class Pairing:
    """The master side found for every owned slave point.

    Attributes
    ----------
    points
        Current slave points ``(np, gdim)``.
    projection
        Closest points (facet index ``-1`` where none).
    nodes
        Current positions of the gathered master nodes of each point's facet,
        ``(np, nx, gdim)`` (zero where unpaired).
    columns
        Stacked index of the displacement unknown each of those coordinates gathers,
        ``(np, nx, gdim)`` (``-1`` where unpaired).
    flags
        (smoothed normal, 2D) whether the neighbours before / after the segment exist,
        ``(np, 2)``; else ``None``.
    """

    points: np.ndarray
    projection: Projection
    nodes: np.ndarray
    columns: np.ndarray
    flags: np.ndarray | None

    @property
    def paired(self) -> np.ndarray:
        """Mask of the points that have a master facet."""
        return self.projection.facet >= 0


class ClosestPointSearch:
    """Closest points of the slave points of a pair on its meshed master surface.

    Parameters
    ----------
    slave, master
        The two sides of the pair.
    radius
        Search radius: master facets farther than this from every slave point of a rank are
        not sent to it, and points with no facet within it are unpaired.
    touching
        A length of round-off: a point this close to the master surface counts as on it.
    """

    def __init__(self, slave: SlaveSurface, master: MeshMaster, radius: float, touching: float):
        self.slave, self.master = slave, master
        self.radius, self.touching = radius, touching
        self.comm = slave.V.mesh.comm
        self.gdim = slave.V.mesh.geometry.dim
        #: seconds spent in :meth:`pair` so far
        self.time = 0.0
        #: KD-trees of the master facets, reused from one search to the next
        self.trees = TreeCache()

    def exchange(self, master_nodes: np.ndarray, points: np.ndarray, payload=None):
        """Master facets of all ranks near this rank's ``points`` (bounding-box filter).

        Returns the received facet nodes and their ``payload`` rows.
        """
        comm = self.comm
        box = self.slave.bounding_box(points, comm)
        boxes = comm.allgather(box)
        n = len(master_nodes)
        payload = np.zeros((n, 0)) if payload is None else payload
        if n:
            lo, hi = master_nodes.min(axis=1), master_nodes.max(axis=1)
        sends = []
        for b in boxes:
            if n == 0:
                sends.append((master_nodes, payload))
                continue
            near = np.all((lo <= b[1] + self.radius) & (hi >= b[0] - self.radius), axis=1)
            sends.append((master_nodes[near], payload[near]))
        received = comm.alltoall(sends) if comm.size > 1 else sends
        nodes = np.concatenate([r[0] for r in received]).reshape(-1, *master_nodes.shape[1:])
        data = np.concatenate([r[1] for r in received]).reshape(len(nodes), *payload.shape[1:])
        return nodes, data

    def check_facing(self, description: str) -> None:
        """Raise (on every rank) if no slave point faces the master surface in the reference
        configuration; ``description`` names the pair in the message."""
        x = self.slave.X.reshape(-1, self.gdim)
        nodes, _ = self.exchange(self.master.X_nodes, x)
        proj = closest_points(x, nodes, np.inf)
        # a slave point faces the master when it lies on the outer side of the master facet
        # and the two outward normals oppose each other
        normals = np.repeat(self.slave.normals, self.slave.num_points, axis=0)
        outside = np.einsum("pd,pd->p", proj.normal, x - proj.y) >= -1e-8 * (1 + proj.distance)
        opposed = np.einsum("pd,pd->p", proj.normal, normals) < 0.0
        if self.master.two_sided:  # a membrane master: either side may face the point
            outside = opposed = True
        elif self.slave.membrane:  # a membrane slave: either of its sides may face
            opposed = True
        facing = np.count_nonzero((proj.facet >= 0) & outside & opposed)
        total = self.comm.allreduce(facing, MPI.SUM)
        collective_check(
            self.comm,
            total > 0,
            f"{description} never faces its master surface: no slave point lies on the outer "
            "side of the master facets (wrong tags or swapped bodies?)",
        )

    def pair(self, u: dolfinx.fem.Function, layout: StackedLayout) -> Pairing:
        """Project the current slave points onto the current master surface (collective).

        Parameters
        ----------
        u
            The displacement of the slave's mesh.
        layout
            Layout of the unknowns (the master's displacement is its block
            ``master.block``).
        """
        start = time.perf_counter()
        gdim, nn, nx = self.gdim, self.master.nn, self.master.nx
        points = self.slave.positions(u).reshape(-1, gdim)
        mine = self.master.candidates(layout)
        ne = mine.boundary.shape[1]
        payload = np.hstack([mine.columns, mine.keys, mine.boundary.astype(np.int64), mine.flags])
        nodes, payload = self.exchange(mine.nodes, points, payload)
        # candidates in a rank-independent order: ties between facets break the same way
        order = np.lexsort(payload[:, nx : nx + nn].T[::-1])
        nodes, payload = nodes[order], payload[order]
        columns = payload[:, :nx]
        boundary = payload[:, nx + nn : nx + nn + ne].astype(bool)
        proj = closest_points(points, nodes[:, :nn], self.radius, self.trees)
        release_beyond_boundary(proj, points, boundary, self.touching)
        paired = proj.facet >= 0
        flags = None
        if self.master.smoothed:
            facet_nodes = nodes[proj.facet[paired]]
            if gdim == 2:
                facet_flags = payload[proj.facet[paired], nx + nn + ne :].astype(bool)
                normal = smoothed_normals(proj.xi[paired], facet_nodes, facet_flags)
                flags = np.zeros((len(points), 2))
                flags[paired] = facet_flags
            else:
                normal = smoothed_normals_3d(proj.xi[paired], facet_nodes, nn)
            proj.normal[paired] = normal
            proj.gap[paired] = -np.einsum("pd,pd->p", normal, points[paired] - proj.y[paired])
        npts = len(points)
        gathered = np.zeros((npts, nx, gdim))
        gathered[paired] = nodes[proj.facet[paired]]
        gather = np.full((npts, nx, gdim), -1, dtype=np.int64)
        gather[paired] = columns[proj.facet[paired]][:, :, None] + np.arange(gdim)
        self.time += time.perf_counter() - start
        return Pairing(points, proj, gathered, gather, flags)


def release_beyond_boundary(
    proj: Projection, points: np.ndarray, boundary: np.ndarray, tolerance: float = 0.0
) -> None:
    """Unpair the points beyond the edge of the master surface (in place).

    A point whose closest point is on an edge (2D: an end point) of the master *surface*
    boundary, and off the normal through it by more than ``tolerance`` (a length: round-off),
    lies beyond the surface: it is not in contact (the last facet is not a half-plane).
    ``boundary``: boundary-edge flags per candidate.
    """
    paired = np.flatnonzero(proj.facet >= 0)
    if len(paired) == 0:
        return
    facet = proj.facet[paired]
    on_edge = on_edges(boundary.shape[1], proj.xi[paired])  # as many edges as nodes
    at_boundary = (on_edge & boundary[facet]).any(axis=1)
    d = points[paired] - proj.y[paired]
    normal_part = np.einsum("pd,pd->p", d, proj.normal[paired])
    off_normal = np.linalg.norm(d - normal_part[:, None] * proj.normal[paired], axis=1)
    beyond = (
        at_boundary & (off_normal > 1e-6 * np.linalg.norm(d, axis=1)) & (off_normal > tolerance)
    )
    released = paired[beyond]
    proj.facet[released] = -1
    proj.gap[released] = -np.inf
