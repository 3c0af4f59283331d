"""The facet kinds of a master surface: one table (:data:`FACET_KINDS`) of what each kind is.

The master facets are given as ``nodes``, an array ``(nf, nodes_per_facet, gdim)`` of current
node positions, already oriented by the caller. The kind follows from ``(nodes_per_facet,
gdim)`` (:func:`facet_kind`); its shape functions are those of the Lagrange element of the
table (a basix cell type and degree), its nodes those of the element's degrees of freedom in
the order of :attr:`FacetKind.basix_order`:

* segment, 2 nodes in 2D: ``N = [1 - xi, xi]``, ``xi`` in ``[0, 1]``, ``a1 = x1 - x0``,
  normal ``nu = (a1[1], -a1[0]) / |a1|``;
* triangle, 3 nodes in 3D: ``N = [1 - xi1 - xi2, xi1, xi2]``, ``a1 = x1 - x0``, ``a2 = x2 -
  x0``, ``nu = a1 x a2 / |a1 x a2|``;
* quadrilateral, 4 nodes in 3D, bilinear in the basix vertex order: ``N = [(1-s)(1-t),
  s(1-t), (1-s)t, st]``, ``(s, t)`` in ``[0, 1]^2``, ``a1 = dy/ds``, ``a2 = dy/dt``, ``nu = a1
  x a2 / |a1 x a2|`` (not constant on a warped quadrilateral);
* quadratic segment, 3 nodes in 2D (``"segment3"``): the two ends, then the midpoint node;
  quadratic triangle, 6 nodes in 3D (``"triangle6"``): the vertices, then the midpoint
  nodes of the edges 01, 12, 02; quadratic quadrilateral, 9 nodes in 3D
  (``"quadrilateral9"``): the basix vertices, the midpoint nodes of the edges 01, 13, 23,
  02, then the centre node. Quadratic Lagrange shape functions
  (:func:`.shapes.quadratic_shape_functions`), the normal as above from the tangents at
  ``xi``: the facets of a degree-2 displacement (curved once deformed, or from the start on
  a degree-2 geometry), projected by the kernels of :mod:`.curved`.

With these conventions the proximity ``g = -nu . (x - y)`` is positive when the slave point
``x`` lies behind the master surface (penetration) and negative when it is in front of it.

The implementations of the shape functions and normals -- UFL
(:func:`contact_ufl.contact.kinematics.master_shape_functions`), NumPy (:mod:`.shapes`) and
C (``search_kernel.c``) -- are each compared with basix's tabulation of the table's element
(``tests/test_facet_kinds.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]


@dataclass(frozen=True)
class FacetKind:
    """One facet kind of a master surface.

    Attributes
    ----------
    name
        The kind's name in the search (``"segment"``, ``"triangle6"``, ...).
    gdim
        The geometric dimension of its surfaces.
    nodes_per_facet
        Its nodes.
    cell, degree
        The basix cell type (by name) and Lagrange degree of the element whose basis
        functions are its shape functions.
    basix_order
        ``basix_order[a]`` is the basix degree of freedom of the facet's node ``a``.
    compiled
        Its kind number in ``search_kernel.c``.
    """

    name: str
    gdim: int
    nodes_per_facet: int
    cell: str
    degree: int
    basix_order: tuple[int, ...]
    compiled: int

    @property
    def fdim(self) -> int:
        """The facet's reference dimension."""
        return self.gdim - 1


#: The facet kinds. basix numbers the edges of a triangle (1, 2), (0, 2), (0, 1) and of a
#: quadrilateral (0, 1), (0, 2), (1, 3), (2, 3), and puts an edge's degree of freedom after
#: the vertices' in that order: the midpoint nodes of the quadratic kinds are permuted.
FACET_KINDS = (
    FacetKind("segment", 2, 2, "interval", 1, (0, 1), 0),
    FacetKind("triangle", 3, 3, "triangle", 1, (0, 1, 2), 1),
    FacetKind("quadrilateral", 3, 4, "quadrilateral", 1, (0, 1, 2, 3), 2),
    FacetKind("segment3", 2, 3, "interval", 2, (0, 1, 2), 3),
    FacetKind("triangle6", 3, 6, "triangle", 2, (0, 1, 2, 5, 3, 4), 4),
    FacetKind("quadrilateral9", 3, 9, "quadrilateral", 2, (0, 1, 2, 3, 4, 6, 7, 5, 8), 5),
)

#: The facet kind of each ``(nodes_per_facet, gdim)``.
KINDS = {(kind.nodes_per_facet, kind.gdim): kind for kind in FACET_KINDS}

#: The quadratic (curved) kinds, projected by the kernels of :mod:`.curved`.
QUADRATIC = tuple(kind.name for kind in FACET_KINDS if kind.degree == 2)

#: The kind numbers of the compiled search (``search_kernel.c``).
COMPILED_KINDS = {kind.name: kind.compiled for kind in FACET_KINDS}

#: Straight edges of each 2D facet kind in reference space: (start node, end node, xi at
#: start, xi at end). Along an edge ``xi = xi_start + u (xi_end - xi_start)``, ``y = x_start
#: + u (x_end - x_start)``.
EDGES = {
    "triangle": (
        (0, 1, (0.0, 0.0), (1.0, 0.0)),  # xi2 = 0
        (1, 2, (1.0, 0.0), (0.0, 1.0)),  # xi1 + xi2 = 1
        (0, 2, (0.0, 0.0), (0.0, 1.0)),  # xi1 = 0
    ),
    "quadrilateral": (
        (0, 1, (0.0, 0.0), (1.0, 0.0)),  # t = 0
        (1, 3, (1.0, 0.0), (1.0, 1.0)),  # s = 1
        (2, 3, (0.0, 1.0), (1.0, 1.0)),  # t = 1
        (0, 2, (0.0, 0.0), (0.0, 1.0)),  # s = 0
    ),
}
#: the 6-node triangle has the straight triangle's edges in reference space (its nodes
#: there are the vertices; the midpoint nodes are in :data:`.curved.TRIANGLE6_EDGES`)
EDGES["triangle6"] = EDGES["triangle"]
EDGES["quadrilateral9"] = EDGES["quadrilateral"]

#: Edges of a master facet by its (oriented) vertex numbers, by its number of vertices: the
#: end points of a segment, the edges of a triangle and of a bilinear quadrilateral (basix
#: vertex order). A quadratic facet's edges are those of its vertices.
FACET_EDGES = {2: [(0,), (1,)], 3: [(0, 1), (0, 2), (1, 2)], 4: [(0, 1), (0, 2), (1, 3), (2, 3)]}


def facet_kind(nodes_per_facet: int, gdim: int) -> str:
    """Name the facet kind of ``nodes_per_facet`` nodes in dimension ``gdim``.

    Raises
    ------
    ValueError
        For a combination that is not in :data:`FACET_KINDS`.
    """
    try:
        return KINDS[(int(nodes_per_facet), int(gdim))].name
    except KeyError:
        raise ValueError(
            f"unsupported master facet: {nodes_per_facet} nodes in {gdim}D "
            "(segments: 2 nodes in 2D; triangles: 3 nodes, quadrilaterals: 4 nodes in 3D)"
        ) from None


def on_edges(vertices: int, xi: np.ndarray, tol: float = 1e-12) -> np.ndarray:
    """Which edges of :data:`FACET_EDGES` hold the points ``xi`` ``(n, fdim)`` of facets of
    ``vertices`` vertices (a facet's first nodes), ``(n, ne)``."""
    if vertices == 2:
        return np.stack([xi[:, 0] <= tol, xi[:, 0] >= 1 - tol], axis=1)
    s, t = xi[:, 0], xi[:, 1]
    if vertices == 3:
        return np.stack([t <= tol, s <= tol, s + t >= 1 - tol], axis=1)
    return np.stack([t <= tol, s <= tol, s >= 1 - tol, t >= 1 - tol], axis=1)
