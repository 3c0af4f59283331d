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
(:class:`contact_ufl.strategies.FirstTry` then starts with its closing iterate).

A free mode held by a point in contact starts no closing iterate. A rotation held only by
contact may still be held poorly: a frictionless contact of a curved surface holds it only
through the facets of the discrete surface (the disc turning about its centre slides over
itself), with a tangent near singular. The diagnosis of a failed step then says that the
body is free to turn, and about which point (:class:`contact_ufl.diagnosis.StepDiagnosis`);
hold it by a support (:func:`contact_ufl.verification.scenes.hertz_2d_driven` holds the
disc's axis).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl import keysets
from contact_ufl.bulk import Bulk


class ContactProblem(Protocol):
    """What this module asks of a problem: its meshes' bulks, contact pairs and numbering."""

    comm: MPI.Comm
    gdim: int
    bulks: list[Bulk]
    contacts: list

    def block_rows(self, k: int) -> slice: ...


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
    bodies
        Names (or cell tags) of the bodies of the piece.
    """

    mesh: int
    blocks: np.ndarray
    free: np.ndarray
    modes: np.ndarray
    centre: np.ndarray
    size: float
    bodies: tuple[str, ...] = ()

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


def _merged(index_map, blocks: list[np.ndarray], comm: MPI.Comm) -> list[tuple]:
    """The unions of the node sets ``blocks`` (local nodes of cells) that share a node,
    as (the indices of the merged sets, the local nodes (owned and ghost) of the union),
    also where the cells that share it lie on different ranks (collective)."""
    held = np.array([_indicator(index_map, b) for b in blocks])
    owned = held[:, : index_map.size_local].astype(int)
    shared = (comm.allreduce(owned @ owned.T, MPI.SUM) > 0) | np.eye(len(blocks), dtype=bool)
    label = np.arange(len(blocks))
    for _ in blocks:  # the smallest label reachable: a few bodies per mesh
        label = np.array([label[row].min() for row in shared])
    return [
        (np.flatnonzero(label == m), np.flatnonzero(held[label == m].any(axis=0)))
        for m in np.unique(label)
    ]


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
        for members, nodes in _merged(bulk.V.dofmap.index_map, blocks, problem.comm):
            held = bulk.prescribed_components[nodes].any(axis=0).astype(int)
            free = problem.comm.allreduce(held, MPI.SUM) == 0
            modes, centre, size = _free_modes(bulk, nodes, problem.comm)
            names = tuple(_body_name(bulk.bodies[b]) for b in members)
            out.append(Piece(k, nodes, free, modes, centre, size, names))
    return out


def _body_name(body) -> str:
    return repr(body.name) if body.name else f"of cell tag {body.tag}"


def _on_piece(bulk: Bulk, tag: int, piece: Piece, comm: MPI.Comm) -> bool:
    """Whether the contact surface ``tag`` of ``bulk`` (facets; a membrane's cells) has a
    node on ``piece`` (collective)."""
    if bulk.membrane:
        nodes = bulk.V.dofmap.list[bulk.domain.cell_tags.find(tag)].ravel()
    else:
        nodes = bulk.facet_dofs(tag)
    here = bool(np.isin(nodes, piece.blocks).any())
    return comm.allreduce(here, MPI.LOR)


def _sides_on(problem: ContactProblem, piece: Piece, pair) -> tuple[bool, bool]:
    """Whether the slave and the master surface of ``pair`` have a node on ``piece``
    (collective; a rigid obstacle is on no piece)."""
    bulk = problem.bulks[piece.mesh]
    slave = (pair.slave_domain or 0) == piece.mesh and _on_piece(
        bulk, pair.slave, piece, problem.comm
    )
    master = (
        not pair.on_obstacle
        and (pair.master_domain or 0) == piece.mesh
        and _on_piece(bulk, pair.master, piece, problem.comm)
    )
    return slave, master


def pairs_on(problem: ContactProblem, piece: Piece) -> list[int]:
    """Indices of the contact pairs with a side (slave or master surface) on ``piece``."""
    return [k for k, c in enumerate(problem.contacts) if any(_sides_on(problem, piece, c.pair))]


def unheld_modes(
    problem: ContactProblem, piece: Piece, on: list[int], modes: np.ndarray | None = None
) -> np.ndarray:
    """The free ``modes`` of ``piece`` (default: :attr:`Piece.modes`) that its frictionless
    contact pairs ``on`` do not hold, as orthonormal coefficients ``(k, m)`` like
    :attr:`Piece.modes` (collective).

    A frictionless contact pushes only along the master normal, so it holds a rigid mode
    only where the mode moves a point near contact along that normal. Near contact means
    paired in the reference configuration within one slave facet size of the pair's
    closest distance;
    a mode is not held where the mean square of its normal component there is below
    ``1e-6`` (modes of unit size: translations, and rotations over the piece's size). A
    pair with friction may hold every mode (stick), and one with both surfaces on the
    piece (self-contact) holds none: a rigid motion moves both alike.
    """
    comm = problem.comm
    modes = piece.modes if modes is None else modes
    if not len(modes):
        return modes
    gram = np.zeros((len(modes),) * 2)
    points = 0
    for k in on:
        c = problem.contacts[k]
        if c.friction is not None:
            return modes[:0]
        if all(_sides_on(problem, piece, c.pair)):
            continue
        p = c.reference
        paired = p.facet >= 0
        nearest = comm.allreduce(p.distance[paired].min(initial=np.inf), MPI.MIN)
        near = paired & (p.distance <= nearest + c.slave.facet_size)
        at = rigid_modes(p.y[near], piece.centre, max(piece.size, 1e-300))
        values = np.einsum("ni,nim->nm", p.normal[near], at) @ modes.T
        gram += values.T @ values
        points += int(near.sum())
    gram = comm.allreduce(gram, MPI.SUM)
    points = comm.allreduce(points, MPI.SUM)
    if points == 0:
        return modes[:0]  # nothing near contact to judge by: the first step will tell
    values, vectors = np.linalg.eigh(gram / points)
    return vectors[:, values < 1e-6].T @ modes


def describe_mode(piece: Piece, mode: np.ndarray) -> str:
    """A rigid mode in words: ``"translation along x"``, ``"rotation about (0, 1)"``."""
    gdim = len(piece.free)
    t, w = mode[:gdim], mode[gdim:] / max(piece.size, 1e-300)
    if np.linalg.norm(mode[gdim:]) < 1e-6 * np.linalg.norm(mode):
        axis = np.abs(t).argmax()
        if abs(t[axis]) > (1.0 - 1e-6) * np.linalg.norm(t):
            return f"translation along {'xyz'[axis]}"
        return "translation along (" + ", ".join(f"{v:.3g}" for v in t / np.linalg.norm(t)) + ")"
    if gdim == 2:
        point = piece.centre + np.array([-t[1], t[0]]) / w[0]
        return "rotation about (" + ", ".join(f"{v:.3g}" for v in point) + ")"
    return "rotation about the axis (" + ", ".join(f"{v:.3g}" for v in w / np.linalg.norm(w)) + ")"


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
