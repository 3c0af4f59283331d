"""Names of dofs and points that do not depend on the partition: how a checkpoint written on
some number of ranks is read on another.

A Lagrange dof is named by the mesh entity it lies on: the input indices of that entity's
vertices (``geometry.input_global_indices``, the node numbers of the mesh file), sorted. A
value at a quadrature point is named by the point's position in the reference configuration
(two points of one rule on distinct cells never coincide), matched within a round-off.
"""

from __future__ import annotations

import basix
import dolfinx
import numpy as np
import scipy.spatial

from contact_ufl.errors import ContactInputError


def entity_keys(V: dolfinx.fem.FunctionSpace) -> np.ndarray:
    """The key of every local dof block of the Lagrange (or DG, or iso) space ``V``, owned
    and ghost: the sorted input indices of the vertices of the entity the dof lies on,
    padded with ``-1`` to the vertices of a cell, ``(blocks, vertices)``.

    Elements with more than one dof on an entity (degree 3 and higher) have no such name
    (their order on an edge follows its orientation): a ``NotImplementedError``.
    """
    mesh = V.mesh
    element = V.ufl_element().basix_element
    topology = basix.topology(element.cell_type)
    nv = len(topology[0])
    geometry = mesh.geometry
    vertex_keys = geometry.input_global_indices[geometry.dofmaps[0][:, :nv]].astype(np.int64)
    dofs = V.dofmap.list
    imap = V.dofmap.index_map
    keys = np.full((imap.size_local + imap.num_ghosts, nv), -2, dtype=np.int64)
    for dim, entities in enumerate(element.entity_dofs):
        for entity, local in enumerate(entities):
            if len(local) > 1:
                raise NotImplementedError(
                    f"{len(local)} dofs on one entity (degree {element.degree}): "
                    "checkpoints name dofs of degree 1 and 2 only"
                )
            for i in local:
                vertices = topology[dim][entity]
                keys[dofs[:, i], : len(vertices)] = np.sort(vertex_keys[:, vertices], axis=1)
                keys[dofs[:, i], len(vertices) :] = -1
    return keys


def quadrature_positions(V: dolfinx.fem.FunctionSpace) -> np.ndarray:
    """The reference positions of the owned points of the quadrature space ``V``,
    ``(points, 3)``."""
    owned = V.dofmap.index_map.size_local
    return V.tabulate_dof_coordinates()[:owned]


def _rows(keys: np.ndarray) -> np.ndarray:
    """Each row of an int64 array as one comparable item (for sorting and lookup)."""
    keys = np.ascontiguousarray(keys, dtype=np.int64)
    return keys.view(np.dtype((np.void, keys.dtype.itemsize * keys.shape[1]))).ravel()


def find_keys(stored: np.ndarray, wanted: np.ndarray, what: str) -> np.ndarray:
    """Where each row of ``wanted`` is in ``stored`` (rows of entity keys).

    Raises
    ------
    ContactInputError
        Some row is not stored: the checkpoint was written for another mesh or degree.
    """
    if stored.shape[1] != wanted.shape[1]:
        raise ContactInputError(
            f"{what}: the checkpoint holds dofs of cells with {stored.shape[1]} vertices, "
            f"this scene {wanted.shape[1]}: it was written for another mesh"
        )
    rows, want = _rows(stored), _rows(wanted)
    if len(want) == 0:
        return np.zeros(0, dtype=np.int64)
    order = np.argsort(rows, kind="stable")
    rows = rows[order]
    at = np.searchsorted(rows, want).clip(max=max(len(rows) - 1, 0))
    found = rows[at] == want if len(rows) else np.zeros(len(want), dtype=bool)
    if not found.all():
        raise ContactInputError(
            f"{what}: {int((~found).sum())} of this scene's dofs are not in the checkpoint "
            "(it was written for another mesh, degree or contact surface)"
        )
    return order[at]


def find_points(stored: np.ndarray, wanted: np.ndarray, tolerance: float, what: str) -> np.ndarray:
    """Where each point of ``wanted`` is among the ``stored`` points (within ``tolerance``).

    Raises
    ------
    ContactInputError
        A point has no stored point within ``tolerance``.
    """
    if len(wanted) == 0:
        return np.zeros(0, dtype=np.int64)
    if len(stored) == 0:
        raise ContactInputError(f"{what}: the checkpoint holds no points, this scene does")
    distance, at = scipy.spatial.cKDTree(stored).query(wanted)
    far = distance > tolerance
    if far.any():
        raise ContactInputError(
            f"{what}: {int(far.sum())} of this scene's points are farther than {tolerance:.3g} "
            f"from any point of the checkpoint (up to {distance.max():.3g}): it was written "
            "for another mesh or quadrature"
        )
    return at
