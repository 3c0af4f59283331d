"""The compiled back end of the closest-point search: a bounding-volume hierarchy over the
master facets, built, refitted and walked per point in C (``search_kernel.c``, built by
:mod:`.compiled`), with the exact projections and the tie-break of the NumPy back end
(:mod:`.numpy_search`) in the same operations.
"""

from __future__ import annotations

import numpy as np

from contact_ufl.contact.search import compiled
from contact_ufl.contact.search.kinds import COMPILED_KINDS, FloatArray, IntArray, facet_kind
from contact_ufl.contact.search.projection import Projection, SelfContact, non_finite
from contact_ufl.contact.search.shapes import centre_normal, normalise


class Hierarchy:
    """A bounding-volume hierarchy (axis-aligned boxes) over master facets, in C.

    Built once over the facets' centroids (median splits on the longest axis, two to four
    facets a leaf: ``O(n log n)``), its boxes refitted over the current nodes at every search
    whose nodes differ from the last one's (``O(n)``: a pass over the facets writing each
    one's record in the order of the leaves, its nodes, box and chord deviation, then the
    rows from the leaves' boxes; an unchanged master costs one comparison with the nodes of
    the records, a moved one a facet of it): exact however far the nodes moved since the
    build (only slower once they moved far). The walk reads rows of four children (two
    levels of the binary tree) with their boxes in single precision, rounded outwards, and
    the records of the facets it meets.
    """

    def __init__(self, nodes: FloatArray) -> None:
        self.ffi, self.lib = compiled.kernel()
        nf, self.nodes_per_facet, self.gdim = nodes.shape
        self.kind = COMPILED_KINDS[facet_kind(self.nodes_per_facet, self.gdim)]
        centroid = np.ascontiguousarray(nodes.mean(axis=1))
        if not np.isfinite(centroid).all():
            raise ValueError(non_finite("the master nodes", nodes))
        self.perm = np.empty(nf, dtype=np.int64)
        self.a = np.empty(nf + 2, dtype=np.int64)  # leaves of 2 to 4 facets: < nf tree nodes
        self.b = np.empty(nf + 2, dtype=np.int64)
        p = self._pointers
        self.m = int(self.lib.bvh_build(self.gdim, nf, *p(centroid, self.perm, self.a, self.b)))
        # the rows of the walk: 128 bytes a tree node at most, one more, 128 to align them
        self.tree = np.empty((self.m + 2) * 128, dtype=np.uint8)
        #: the facets' records in the order of the leaves (nodes, box, chord deviation)
        self.leaves = np.empty((nf, int(self.lib.bvh_record(self.gdim, self.nodes_per_facet))))
        self.leaf_boxes = np.empty((nf, 2 * self.gdim))  # the refit's scratch: <= nf leaves
        self.is_fitted = False
        #: a bound of the largest node movement since the build (the sum of the largest
        #: movements from one refit to the next)
        self.moved = 0.0
        self.R_max = 0.0
        self.projections = 0

    def _pointers(self, *arrays: np.ndarray) -> list:
        return [_ptr(self, a) for a in arrays]

    def fitted(self, nodes: FloatArray) -> bool:
        """Whether the boxes are those of ``nodes`` (C-contiguous): the nodes of the last
        (successful) refit, to the last bit."""
        p = self._pointers
        return self.is_fitted and bool(
            self.lib.same_nodes(
                self.gdim, self.nodes_per_facet, len(nodes), *p(nodes, self.perm, self.leaves)
            )
        )

    def refit(self, nodes: FloatArray) -> float:
        """The boxes, largest facet radius and leaf-ordered facet records of the current
        ``nodes`` (C-contiguous), with the nodes' largest coordinate change since the last
        refit (against the records' copy), which it returns (meaningless after none); a
        ``ValueError`` if a coordinate is not finite."""
        nf, nodes_per_facet, g = nodes.shape
        p = self._pointers
        change = np.zeros(1)
        self.is_fitted = False
        R_max = float(
            self.lib.bvh_refit(
                g, nodes_per_facet, nf, *p(nodes, self.perm), self.m,
                *p(self.a, self.b, self.tree, self.leaves, self.leaf_boxes, change),
            )
        )  # fmt: skip
        if R_max == -2.0:
            raise ValueError(non_finite("the master nodes", nodes))
        self.R_max = R_max
        self.is_fitted = True
        return float(change[0])

    def order(self, points: FloatArray) -> IntArray:
        """An order of the points along a Z-order (Morton) curve through the cells of a
        ``1024^gdim`` grid over their bounding box, by a radix sort in C: the points of a
        cell, then of its neighbours, come one after the other (they walk the same branches
        of the tree while it is in cache). Stable: equal keys in the given order."""
        order = np.empty(len(points), dtype=np.int64)
        x = np.ascontiguousarray(points)
        if self.lib.morton_order(x.shape[1], len(x), *self._pointers(x, order)) != 0:
            raise MemoryError("the compiled closest-point search ran out of memory")
        return order

    def query(
        self,
        x: FloatArray,
        radius: float,
        out: Projection,
        rule: tuple | None = None,
        index: IntArray | None = None,
    ) -> None:
        """The closest point of each point ``x`` (C-contiguous) written to ``out`` (a
        :class:`Projection` of C-contiguous fields) at its row of ``index`` (its own row
        without): of the facets whose exact distance is within the tie reach of the smallest
        one, the one of the tie-break of :func:`.numpy_search.select` (in C); the placeholders
        where that point is beyond ``radius``, the row left as it is where no facet is within
        it.
        ``rule``: the arrays of a self-contact search (point nodes, point normals, facet
        nodes, facet centre normals)."""
        p = self._pointers
        null = self.ffi.NULL
        rows = null if index is None else _ptr(self, index)
        fields = p(out.facet, out.xi, out.y, out.normal, out.gap, out.distance, out.sliding)
        contact = [0, null, null, 0, null, null]
        if rule is not None:
            pn, pnormal, fn, axis = rule
            contact = [pn.shape[1], *p(pn, pnormal), fn.shape[1], *p(fn, axis)]
        status = self.lib.bvh_query(
            self.kind, self.gdim, self.nodes_per_facet, *p(self.leaves, self.perm), self.m,
            _ptr(self, self.tree), self.R_max, len(x), _ptr(self, x), radius, rows, *fields,
            *contact,
        )  # fmt: skip
        if status == -1:
            raise MemoryError("the compiled closest-point search ran out of memory")
        if status == -3:
            raise RuntimeError(
                f"the compiled closest-point search's tree walk overflowed its stack (a tree "
                f"of {self.m} rows deeper than a balanced one: please report the master)"
            )
        if status < 0:
            raise ValueError(
                f"no compiled search for {self.nodes_per_facet}-node facets in {self.gdim}D"
            )
        #: exact projections made by the last query (the work of its pruning)
        self.projections = int(status)


def _ptr(h: Hierarchy, array: np.ndarray):
    """A cffi pointer to the data of a C-contiguous ``array``."""
    kind = {
        np.dtype(np.float64): "double[]",
        np.dtype(np.int64): "i64[]",
        np.dtype(np.uint8): "unsigned char[]",
    }[array.dtype]
    return h.ffi.from_buffer(kind, array, require_writable=False)


def search_compiled(
    points: FloatArray,
    nodes: FloatArray,
    radius: float,
    tree: Hierarchy,
    ordered: bool,
    self_contact: SelfContact | None,
    out: Projection,
) -> None:
    """Fill ``out`` with the closest points of :func:`.closest.closest_points` (checked input,
    C-contiguous ``nodes``) by the compiled search: a branch-and-bound walk of the
    bounding-volume hierarchy ``tree`` (of ``nodes``) per point (``search_kernel.c``) finds
    its closest facet and those within the tie reach of it (the exact projections of the
    NumPy kernels, in C), breaks the ties as :func:`.numpy_search.select` does and writes the
    closest point. ``ordered`` (a large master): the points are walked in a Z-order of cells
    (:meth:`Hierarchy.order`)."""
    rule = None if self_contact is None else self_contact_arrays(self_contact, nodes)
    order = tree.order(points) if ordered else None
    x = np.ascontiguousarray(points if order is None else points[order])
    if rule is not None and order is not None:
        rule = (rule[0][order], rule[1][order], rule[2], rule[3])
    tree.query(x, radius, out, rule, order)


def self_contact_arrays(rule: SelfContact, nodes: FloatArray) -> tuple[np.ndarray, ...]:
    """The arrays of a compiled self-contact search: point nodes, point normals, facet nodes
    and the facets' unit normals at their centres (as
    :attr:`.numpy_facets.MasterFacets.axis`)."""
    g, nodes_per_facet = nodes.shape[2], nodes.shape[1]
    X = [[np.ascontiguousarray(nodes[:, a, k]) for k in range(g)] for a in range(nodes_per_facet)]
    axis = np.stack(normalise(centre_normal(X, nodes_per_facet, g)), axis=1)
    return tuple(
        np.ascontiguousarray(a, dtype=dtype)
        for a, dtype in (
            (rule.point_nodes, np.int64),
            (rule.point_normals, np.float64),
            (rule.facet_nodes, np.int64),
            (axis, np.float64),
        )
    )
