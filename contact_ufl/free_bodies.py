"""Bodies held only by contact: which contact pairs a force-driven start must close first.

A *piece* is a body of a mesh, merged with the bodies that share a node with it. A piece
with no support in a Cartesian direction ``i`` translates freely along ``e_i`` unless a
contact point holds it: the translation is a null vector of its tangent (the stored energy
and dead loads do not change under it). Where no contact pair on the piece has a point in
contact and the residual has a net force along ``e_i`` on the piece, the Newton equation
has no solution: the step cannot converge until the contact closes
(:meth:`contact_ufl.newton.NewtonSolver.solve_step` then starts with its closing iterate).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import dolfinx
import numpy as np
from mpi4py import MPI

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
    """

    mesh: int
    blocks: np.ndarray
    free: np.ndarray


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


def pieces(problem: ContactProblem) -> list[Piece]:
    """The pieces of the problem's meshes (collective)."""
    out = []
    for k, bulk in enumerate(problem.bulks):
        dofs = bulk.V.dofmap.list
        blocks = [np.unique(dofs[bulk.domain.cell_tags.find(b.tag)].ravel()) for b in bulk.bodies]
        for nodes in _merged(bulk.V.dofmap.index_map, blocks, problem.comm):
            held = bulk.prescribed_components[nodes].any(axis=0).astype(int)
            free = problem.comm.allreduce(held, MPI.SUM) == 0
            out.append(Piece(k, nodes, free))
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


def net_force(problem: ContactProblem, residual: np.ndarray, piece: Piece) -> np.ndarray:
    """The sum over the piece's nodes of the residual of the unknowns ``residual`` (owned
    part): the net out-of-balance force on the piece (collective)."""
    bulk = problem.bulks[piece.mesh]
    r = residual[problem.block_rows(piece.mesh)].reshape(-1, problem.gdim)
    owned = piece.blocks[piece.blocks < bulk.V.dofmap.index_map.size_local]
    return problem.comm.allreduce(r[owned].sum(axis=0), MPI.SUM)
