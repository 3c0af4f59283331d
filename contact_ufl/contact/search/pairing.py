"""The closest-point mapping between non-matching surfaces, in Python.

For every slave quadrature point the search finds the closest point on the master surface:
the master facets of all ranks that can be within the search radius of this rank's slave
points are exchanged (a bounding-box filter), put in a rank-independent order (so that ties
between equidistant facets break the same way on any number of ranks), and projected onto
(:func:`.closest.closest_points`). Points whose closest point lies on the
boundary of the master surface and off its normal are released (they are beyond the
surface, not on it). On a self-contact surface (slave and master the same surface) a point
pairs only with the facets that share no vertex with its own and face it, and of two facing
facets only the one of lower vertex key is the slave (:func:`.release.release_master_side`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.contact.search import compiled
from contact_ufl.contact.search.candidates import Candidates, MasterCandidates
from contact_ufl.contact.search.closest import closest_points, compiled_backend
from contact_ufl.contact.search.normals import smoothed_normals, smoothed_normals_3d
from contact_ufl.contact.search.projection import Projection, SelfContact, non_finite
from contact_ufl.contact.search.release import (
    release_beside_own_facet,
    release_beyond_boundary,
    release_master_side,
)
from contact_ufl.contact.search.trees import TreeCache
from contact_ufl.contact.slave import SlaveSurface
from contact_ufl.errors import collective_check
from contact_ufl.layout import StackedLayout


class MasterSurface(Protocol):
    """What the search needs of a meshed master side
    (:class:`~contact_ufl.contact.master.MeshMaster`)."""

    #: nodes of a facet, of them vertices, and nodes gathered to a slave point (the facet's,
    #: then with the smoothed normal its neighbours')
    nn: int
    nv: int
    nx: int
    #: whether the normal is smoothed; whether either side of the surface may be in contact
    smoothed: bool
    two_sided: bool
    #: reference positions of the facets' nodes ``(nf, nn, gdim)``; sorted vertex input
    #: indices of each facet ``(nf, nv)``
    X_nodes: np.ndarray
    keys: np.ndarray

    def candidates(self, layout: StackedLayout) -> MasterCandidates:
        """This rank's facets at the current displacement (collective)."""
        ...


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
        ``(np, master.nx, gdim)`` (zero where unpaired).
    columns
        Stacked index of the displacement unknown each of those coordinates gathers,
        ``(np, master.nx, gdim)`` (``-1`` where unpaired).
    flags
        (smoothed normal, 2D) whether the neighbours before / after the segment exist,
        ``(np, 2)``; else ``None``.
    neighbourhood
        Stacked index of the first displacement unknown of every node gathered by the
        candidate facets beside each point's facet (sharing a side with it: a node in 2D,
        an edge in 3D; the facet included), ``(np, width)`` (``-1`` padded; ``-1`` where
        unpaired): a pairing that moves a point onto a neighbouring facet gathers within it.
    """

    points: np.ndarray
    projection: Projection
    nodes: np.ndarray
    columns: np.ndarray
    flags: np.ndarray | None
    neighbourhood: np.ndarray | None = None

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
    self_contact
        Whether slave and master are the same surface: a point then pairs only with the
        facets that share no vertex with its own facet and whose normal opposes its current
        normal (:class:`~contact_ufl.contact.search.SelfContact`; no tolerance).
    backend
        The back end of the closest-point search (``"compiled"`` or ``"numpy"``, see
        :func:`~contact_ufl.contact.search.closest_points`); default: the environment
        variable ``CONTACT_UFL_SEARCH`` at each search, else ``"compiled"``.
    """

    def __init__(
        self,
        slave: SlaveSurface,
        master: MasterSurface,
        radius: float,
        touching: float,
        self_contact: bool = False,
        backend: str | None = None,
    ):
        self.slave, self.master = slave, master
        self.radius, self.touching = radius, touching
        self.self_contact = self_contact
        self.backend = backend
        self.comm = slave.V.mesh.comm
        self.gdim = slave.V.mesh.geometry.dim
        #: seconds spent in :meth:`pair` so far
        self.time = 0.0
        #: search trees of the master facets, reused from one search to the next
        self.trees = TreeCache()
        self._candidates: Candidates | None = None
        # the compiled kernel on every rank now: a rank with no slave points never builds
        # it, so a build error would otherwise be raised on the searching ranks only
        if self.comm.allreduce(compiled_backend(backend, master.nn, self.gdim), MPI.LOR):
            compiled.require(self.comm)

    def exchange(self, master_nodes: np.ndarray, points: np.ndarray, payload=None):
        """Master facets of all ranks near this rank's ``points`` (bounding-box filter).

        Returns the received facet nodes and their ``payload`` rows (on one rank the
        arguments themselves: nothing to send, and the search skips the far facets itself).
        Raises a ``ValueError`` on every rank if a rank's points or master nodes are not all
        finite (the search would pair them silently).
        """
        comm = self.comm
        n = len(master_nodes)
        payload = np.zeros((n, 0)) if payload is None else payload
        if comm.size == 1:  # nothing to send: the search skips the far facets itself
            problem = _non_finite(points, master_nodes.reshape(n, -1))
            if problem is not None:
                raise ValueError(f"{problem} (on rank 0)")
            return master_nodes, payload
        box = self.slave.bounding_box(points, comm)
        if n:
            lo, hi = _node_bounds(master_nodes)
        problem = _non_finite(points, np.concatenate([lo, hi], axis=1) if n else None)
        problem = None if problem is None else f"{problem} (on rank {comm.rank})"
        gathered = comm.allgather((box, problem))
        problems = [p for _, p in gathered if p is not None]
        if problems:
            raise ValueError(problems[0])
        sends = []
        for box, _ in gathered:
            if n == 0:
                sends.append((master_nodes, payload))
                continue
            near = _overlapping(lo, hi, box[0] - self.radius, box[1] + self.radius)
            if near.all():
                sends.append((master_nodes, payload))
            else:
                sends.append((master_nodes[near], payload[near]))
        received = comm.alltoall(sends)
        nodes = np.concatenate([r[0] for r in received]).reshape(-1, *master_nodes.shape[1:])
        data = np.concatenate([r[1] for r in received]).reshape(len(nodes), *payload.shape[1:])
        return nodes, data

    def candidates(self, table: np.ndarray) -> Candidates:
        """The fixed data of the received candidate facets (their rows of the master's
        :class:`~contact_ufl.contact.search.MasterCandidates` table) in the search order:
        those of the last search while the same rows are received in the same order (on one
        rank, always), else anew."""
        if self._candidates is None or not np.array_equal(self._candidates.table, table):
            master = self.master
            self._candidates = Candidates.of(table, master.nx, master.nv, master.nn, self.gdim)
        return self._candidates

    def check_facing(self, description: str) -> Projection:
        """Raise (on every rank) if no slave point faces the master surface in the reference
        configuration; ``description`` names the pair in the message.

        Returns the closest points of the reference configuration, paired (``facet >= 0``)
        where a slave point faces the master within the search radius, on either side of it
        (an initial overlap is a positive gap)."""
        x = self.slave.X.reshape(-1, self.gdim)
        keys = self.master.keys.astype(np.int64)
        nodes, keys = self.exchange(self.master.X_nodes, x, keys)
        normals = np.repeat(self.slave.normals, self.slave.num_points, axis=0)
        rule = self._self_contact(keys, normals)
        proj = closest_points(x, nodes, np.inf, self_contact=rule, backend=self.backend)
        # a slave point faces the master when it lies on the outer side of the master facet,
        # or inside it within the search radius (a press fit), and the two outward normals
        # oppose each other
        outside = np.einsum("pd,pd->p", proj.normal, x - proj.y) >= -1e-8 * (1 + proj.distance)
        outside |= proj.distance <= self.radius
        opposed = np.einsum("pd,pd->p", proj.normal, normals) < 0.0
        if self.master.two_sided:  # a membrane master: either side may face the point
            outside = opposed = True
        elif self.slave.membrane:  # a membrane slave: either of its sides may face
            opposed = True
        facing = np.count_nonzero((proj.facet >= 0) & outside & opposed)
        total = self.comm.allreduce(facing, MPI.SUM)
        if self.self_contact:
            message = (
                f"{description} never faces itself: no point of the surface lies in front of "
                "another part of it with opposed normals (a self-contact pair needs a surface "
                "that can fold onto itself: a hole, a slit, a curved face; not a flat face)"
            )
        else:
            message = (
                f"{description} never faces its master surface: no slave point lies on the "
                "outer side of the master facets (wrong tags or swapped bodies?)"
            )
        collective_check(self.comm, total > 0, message)
        near = (proj.facet >= 0) & opposed & (proj.distance <= self.radius)
        proj.facet = np.where(near, proj.facet, -1)
        return proj

    def _self_contact(self, keys: np.ndarray, normals: np.ndarray) -> SelfContact | None:
        """The admissibility rule of a self-contact search (``None`` for other pairs): the
        master facets' vertex ``keys`` and the slave points' outward ``normals``."""
        if not self.self_contact:
            return None
        own = np.repeat(self.slave.vertex_keys, self.slave.num_points, axis=0)
        return SelfContact(own, keys.astype(np.int64), normals)

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
        gdim, nodes_per_facet = self.gdim, self.master.nn
        points = self.slave.positions(u).reshape(-1, gdim)
        mine = self.master.candidates(layout)
        nodes, table = self.exchange(mine.nodes, points, mine.table)
        candidates = self.candidates(table)
        nodes = np.take(nodes, candidates.order, axis=0)
        rule = None
        if self.self_contact:  # the current normals only where the rule needs them
            rule = self._self_contact(candidates.keys, self.slave.current_normals(u))
        proj = closest_points(
            points, nodes[:, :nodes_per_facet], self.radius, self.trees, rule, self.backend
        )
        if rule is not None:
            release_beside_own_facet(proj, points, rule, self.touching)
            release_master_side(proj, rule)
        release_beyond_boundary(proj, points, candidates.boundary, self.touching)
        paired = proj.facet >= 0
        flags = None
        if self.master.smoothed:
            facet_nodes = nodes[proj.facet[paired]]
            if gdim == 2:
                facet_flags = candidates.flags[proj.facet[paired]]
                normal = smoothed_normals(proj.xi[paired], facet_nodes, facet_flags)
                flags = np.zeros((len(points), 2))
                flags[paired] = facet_flags
            else:
                normal = smoothed_normals_3d(proj.xi[paired], facet_nodes, nodes_per_facet)
            proj.normal[paired] = normal
            proj.gap[paired] = -np.einsum("pd,pd->p", normal, points[paired] - proj.y[paired])
        gathered = _at_points(nodes, proj.facet, paired, 0.0)
        gather = _at_points(candidates.gather, proj.facet, paired, -1)
        width = candidates.counts[proj.facet[paired]].max(initial=0)  # the rest of a row: -1
        neighbourhood = _at_points(candidates.fans[:, :width], proj.facet, paired, -1)
        self.time += time.perf_counter() - start
        return Pairing(points, proj, gathered, gather, flags, neighbourhood)


def _at_points(rows: np.ndarray, facet: np.ndarray, paired: np.ndarray, fill) -> np.ndarray:
    """``rows[facet]`` at the ``paired`` points, ``fill`` at the others (``np.take``: several
    times faster than indexing)."""
    if len(rows) == 0:
        return np.full((len(facet), *rows.shape[1:]), fill, dtype=rows.dtype)
    if paired.all():
        return np.take(rows, facet, axis=0)
    out = np.take(rows, np.where(paired, facet, 0), axis=0)
    out[~paired] = fill
    return out


def _overlapping(lo: np.ndarray, hi: np.ndarray, low: np.ndarray, high: np.ndarray):
    """Which boxes ``[lo, hi]`` ``(n, gdim)`` meet the box ``[low, high]``, a coordinate at
    a time."""
    near = (lo[:, 0] <= high[0]) & (hi[:, 0] >= low[0])
    for d in range(1, lo.shape[1]):
        near &= (lo[:, d] <= high[d]) & (hi[:, d] >= low[d])
    return near


def _node_bounds(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The smallest and largest coordinates of each facet's ``nodes`` ``(n, nodes, gdim)``, a
    node at a time (NumPy's reduction over the middle axis is several times slower)."""
    lo, hi = nodes[:, 0].copy(), nodes[:, 0].copy()
    for a in range(1, nodes.shape[1]):
        np.minimum(lo, nodes[:, a], out=lo)
        np.maximum(hi, nodes[:, a], out=hi)
    return lo, hi


def _non_finite(points: np.ndarray, nodes: np.ndarray | None) -> str | None:
    """The message naming what is not finite among a rank's slave ``points`` and its master
    facets' ``nodes`` (a row a facet: its nodes, or the bounds of its nodes, which a NaN or
    infinite node makes non-finite), or ``None``."""
    if not np.isfinite(points).all():
        return non_finite("the slave points", points)
    if nodes is not None and not np.isfinite(nodes).all():
        return non_finite("the master nodes", nodes)
    return None
