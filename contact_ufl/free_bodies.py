"""Bodies held only by contact: which contact pairs a force-driven start must close first.

A *piece* is a body of a mesh, merged with the bodies that share a node with it. Its
*free modes* are the rigid motions (translations and, about its centroid, rotations) that no
support holds: those whose displacement vanishes at every prescribed component of every
node of the piece, the null space of the matrix of the rigid modes at the prescribed
components. A piece with no support in a Cartesian direction ``i`` translates freely along
``e_i``; a piece held in the direction ``e_x`` only along a line ``y = c`` (the top of the
force-driven Hertz disc without its axis held, see
:func:`contact_ufl.verification.scenes.hertz_2d_driven`) or pinned at one point turns freely
about a point of that line, or about the pin, to first order. Unless a contact point holds
it, a free mode is a null vector of the piece's tangent (the stored energy and dead loads do
not change under it). Where no contact pair on the piece has a point in contact and the
residual has a net load along a free mode (a force, or a moment over the piece's size), the
Newton equation has no solution: the step cannot converge until the contact closes
(:meth:`contact_ufl.newton.NewtonSolver.solve_step` then starts with its closing iterate).

A free mode held by a point in contact starts no closing iterate. A rotation held only by
contact may still be held poorly: a frictionless contact of a curved surface holds it only
through the facets of the discrete surface (the disc turning about its centre slides over
itself), with a tangent near singular. The diagnosis of a failed step then says that the
body is free to turn, and about which point (:meth:`contact_ufl.newton.NewtonSolver.diagnose`);
hold it by a support (:func:`contact_ufl.verification.scenes.hertz_2d_driven` holds the
disc's axis).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl import keysets

if TYPE_CHECKING:
    from contact_ufl.bulk import Bulk
    from contact_ufl.problem import ContactProblem


@dataclass
class Piece:
    """One piece of a mesh.

    Attributes
    ----------
    mesh
        Index of the mesh (the displacement block of the unknowns).
    blocks
        Local dof blocks (nodes) of its cells, owned and ghost.
    free
        The directions with no support on the piece (``gdim`` booleans, the same on every
        rank).
    modes
        Orthonormal coefficients ``(k, m)`` of the ``k`` free modes in the basis of the
        ``m`` rigid modes of :func:`rigid_modes` (translations, then rotations about
        ``centre`` scaled by ``size``); the same on every rank.
    centre, size
        Centroid of the piece's nodes, and their largest distance from it.
    """

    mesh: int
    blocks: np.ndarray
    free: np.ndarray
    modes: np.ndarray
    centre: np.ndarray
    size: float

    @property
    def rotates(self) -> bool:
        """Whether a free mode turns the piece (not a translation only)."""
        gdim = len(self.free)
        return bool(np.abs(self.modes[:, gdim:]).max(initial=0.0) > 1e-8)

    def turning_point(self) -> np.ndarray | None:
        """In 2D, the point about which the piece turns freely (the centre of the free mode
        with no translation along a free direction, or of the one free mode); ``None``
        where no rotation is free or in 3D."""
        if len(self.free) != 2 or not self.rotates:
            return None
        c = self.modes[np.argmax(np.abs(self.modes[:, 2]))].copy()
        c[:2][self.free] = 0.0  # a free translation moves the point along a free direction
        # u = (t_x - w dy, t_y + w dx), d = (x - centre) / size: zero at d = (-t_y, t_x) / w
        t, w = c[:2], c[2] / self.size
        return self.centre + np.array([-t[1], t[0]]) / w


def _indicator(index_map, blocks: np.ndarray) -> np.ndarray:
    """Which local nodes (owned and ghost) any rank's ``blocks`` hold (collective)."""
    marks = dolfinx.la.vector(index_map, 1)
    marks.array[blocks] = 1.0
    marks.scatter_reverse(dolfinx.la.InsertMode.add)
    marks.scatter_forward()
    return marks.array > 0.0


def _merged(index_map, blocks: list[np.ndarray], comm: MPI.Comm) -> list[np.ndarray]:
    """The unions of the node sets ``blocks`` (local nodes of cells) that share a node,
    as the local nodes (owned and ghost) of each union, also where the cells that share
    it lie on different ranks (collective)."""
    held = np.array([_indicator(index_map, b) for b in blocks])
    owned = held[:, : index_map.size_local].astype(int)
    shared = (comm.allreduce(owned @ owned.T, MPI.SUM) > 0) | np.eye(len(blocks), dtype=bool)
    label = np.arange(len(blocks))
    for _ in blocks:  # the smallest label reachable: a few bodies per mesh
        label = np.array([label[row].min() for row in shared])
    return [np.flatnonzero(held[label == m].any(axis=0)) for m in np.unique(label)]


def rigid_modes(x: np.ndarray, centre: np.ndarray, size: float) -> np.ndarray:
    """The rigid modes at the points ``x (n, gdim)``: ``(n, gdim, m)``, the ``gdim``
    translations ``e_i``, then the rotations ``e_j x d`` (3D; in 2D the one ``(-d_y, d_x)``)
    with ``d = (x - centre) / size``."""
    n, gdim = x.shape
    d = (x - centre) / size
    translations = np.broadcast_to(np.eye(gdim), (n, gdim, gdim))
    if gdim == 2:
        rotations = np.stack([-d[:, 1], d[:, 0]], axis=1)[:, :, None]
    else:
        rotations = np.stack([np.cross(np.eye(3)[j], d) for j in range(3)], axis=2)
    return np.concatenate([translations, rotations], axis=2)


def _owned(bulk: Bulk, nodes: np.ndarray) -> np.ndarray:
    return nodes[nodes < bulk.V.dofmap.index_map.size_local]


def _free_modes(bulk: Bulk, nodes: np.ndarray, comm: MPI.Comm) -> tuple:
    """Free modes (orthonormal coefficients), centre and size of the piece of ``nodes``."""
    gdim = bulk.V.mesh.geometry.dim
    x = bulk.V.tabulate_dof_coordinates()[_owned(bulk, nodes), :gdim]
    total = comm.allreduce(np.concatenate([x.sum(axis=0), [len(x)]]), MPI.SUM)
    centre = total[:gdim] / max(total[gdim], 1.0)
    size = comm.allreduce(np.linalg.norm(x - centre, axis=1).max(initial=0.0), MPI.MAX)
    modes = rigid_modes(x, centre, max(size, 1e-300))
    held = bulk.prescribed_components[_owned(bulk, nodes)]
    rows = modes[held]  # (prescribed components, m): each mode's value there
    gram = comm.allreduce(rows.T @ rows, MPI.SUM)
    values, vectors = np.linalg.eigh(gram)
    free = values <= 1e-10 * max(np.trace(gram), 1.0)
    return vectors[:, free].T, centre, size


def pieces(problem: ContactProblem) -> list[Piece]:
    """The pieces of the problem's meshes (collective)."""
    out = []
    for k, bulk in enumerate(problem.bulks):
        dofs = bulk.V.dofmap.list
        blocks = [keysets.unique(dofs[bulk.domain.cell_tags.find(b.tag)]) for b in bulk.bodies]
        for nodes in _merged(bulk.V.dofmap.index_map, blocks, problem.comm):
            held = bulk.prescribed_components[nodes].any(axis=0).astype(int)
            free = problem.comm.allreduce(held, MPI.SUM) == 0
            modes, centre, size = _free_modes(bulk, nodes, problem.comm)
            out.append(Piece(k, nodes, free, modes, centre, size))
    return out


def _on_piece(bulk: Bulk, tag: int, piece: Piece, comm: MPI.Comm) -> bool:
    """Whether the contact surface ``tag`` of ``bulk`` (facets; a membrane's cells) has a
    node on ``piece`` (collective)."""
    if bulk.membrane:
        nodes = bulk.V.dofmap.list[bulk.domain.cell_tags.find(tag)].ravel()
    else:
        nodes = bulk.facet_dofs(tag)
    here = bool(np.isin(nodes, piece.blocks).any())
    return comm.allreduce(here, MPI.LOR)


def pairs_on(problem: ContactProblem, piece: Piece) -> list[int]:
    """Indices of the contact pairs with a side (slave or master surface) on ``piece``."""
    out = []
    for index, c in enumerate(problem.contacts):
        pair = c.pair
        sides = [(pair.slave_domain, pair.slave)]
        if not pair.on_obstacle:
            sides.append((pair.master_domain, pair.master))
        bulks = problem.bulks
        if any(
            (domain or 0) == piece.mesh and _on_piece(bulks[piece.mesh], tag, piece, problem.comm)
            for domain, tag in sides
        ):
            out.append(index)
    return out


def net_free_load(problem: ContactProblem, residual: np.ndarray, piece: Piece) -> float:
    """The norm of the out-of-balance load of the residual ``residual`` (owned part) along
    the piece's free modes: forces, and moments about its centre over its size (a force;
    collective)."""
    bulk = problem.bulks[piece.mesh]
    r = residual[problem.block_rows(piece.mesh)].reshape(-1, problem.gdim)
    owned = _owned(bulk, piece.blocks)
    x = bulk.V.tabulate_dof_coordinates()[owned, : problem.gdim]
    modes = rigid_modes(x, piece.centre, max(piece.size, 1e-300))
    load = problem.comm.allreduce(np.einsum("ni,nim->m", r[owned], modes), MPI.SUM)
    return float(np.linalg.norm(piece.modes @ load))
