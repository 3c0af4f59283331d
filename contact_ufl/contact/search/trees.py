"""The search trees of a master surface, kept from one search to the next while it has barely
moved: the KD-trees of facet centroids by size class (the NumPy back end) and the
bounding-volume hierarchies (the compiled back end, :class:`.hierarchy.Hierarchy`).
"""

from __future__ import annotations

import itertools
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from contact_ufl.contact.search.hierarchy import Hierarchy
from contact_ufl.contact.search.kinds import FloatArray, IntArray

_TREES = 4  # KD-trees kept for reuse (one per master surface of a distinct shape)


_MOVE = 0.25  # a search tree is reused while no node has moved more than this times R_max


_LEVEL_RADIUS = 2.0  # facets of radius up to this times the median share the first KD-tree


_LEVEL_RATIO = 4.0  # ratio of the largest facet radii of successive KD-tree levels


class TreeCache:
    """Search trees of a master surface, reused while it has barely moved: KD-trees of facet
    centroids (the NumPy search, :meth:`tree`) and bounding-volume hierarchies (the compiled
    search, :meth:`hierarchy`).

    Held by whoever searches the same master surface again and again (a
    :class:`~contact_ufl.contact.search.ClosestPointSearch`) and passed to
    :func:`~contact_ufl.contact.search.closest_points`.

    One entry per shape ``(nf, nodes_per_facet, gdim)`` of the node array and KD-tree level
    or hierarchy (the ``_TREES`` most recent): the nodes the tree was built from (``None``
    for a hierarchy, which keeps the nodes of its last refit) and the tree. A search in parts
    (the normal bins of a self-contact search) keeps the trees of each part in a cache of its
    own (:meth:`part`).
    """

    def __init__(self) -> None:
        self.entries: OrderedDict[tuple, tuple[FloatArray | None, cKDTree | Hierarchy]] = (
            OrderedDict()
        )
        #: the caches of the parts of a search (a self-contact search's normal bins)
        self.parts: dict[object, TreeCache] = {}

    def part(self, key: object) -> TreeCache:
        """The cache of the part ``key`` of a search (made on first use)."""
        return self.parts.setdefault(key, TreeCache())

    def tree(
        self, nodes: FloatArray, centroid: FloatArray, R_max: float, level: int = 0
    ) -> tuple[cKDTree | None, float]:
        """A KD-tree of centroids within ``slack`` of ``centroid`` and that slack.

        The centroid is the mean of the nodes, so it moves at most as far as the farthest
        node: a tree of earlier centroids serves with ``slack`` the largest node movement.
        """
        if len(nodes) == 0:
            return None, 0.0
        key = (*nodes.shape, level)
        entry = self.entries.get(key)
        if entry is not None:
            built, tree = entry
            # largest node movement (bounded by the largest coordinate change times sqrt(gdim))
            move = float(np.max(np.abs(nodes - built))) * np.sqrt(nodes.shape[2])
            if move <= _MOVE * R_max:
                self.entries.move_to_end(key)
                return tree, move
        tree = cKDTree(centroid)
        self._keep(key, nodes, tree)
        return tree, 0.0

    def hierarchy(self, nodes: FloatArray) -> Hierarchy:
        """The bounding-volume hierarchy of the facets ``nodes`` (C-contiguous), refitted
        to them: the one of an earlier call on a master of the same shape while no node has
        moved more than ``_MOVE R_max`` since it was built (a tree of the earlier order stays
        exact once refitted, and stays good while the facets barely moved; not refitted if
        no node moved since the last call), else a new one. The movement since the build is
        bounded by the sum of the largest movements from one refit to the next (the hierarchy
        keeps the nodes of its last refit only), each measured by the refit itself: a tree
        found to have moved too far is refitted once more, then replaced."""
        key = (*nodes.shape, "hierarchy")
        entry = self.entries.get(key)
        if entry is not None:
            tree = entry[1]
            if tree.fitted(nodes):  # the master has not moved since the last search
                self.entries.move_to_end(key)
                return tree
            if tree.is_fitted:
                R_max = tree.R_max
                tree.moved += tree.refit(nodes) * np.sqrt(nodes.shape[2])
                if tree.moved <= _MOVE * R_max:
                    self.entries.move_to_end(key)
                    return tree
        tree = Hierarchy(nodes)
        self._keep(key, None, tree)
        tree.refit(nodes)
        return tree

    def _keep(self, key: tuple, nodes: FloatArray | None, tree: object) -> None:
        """Keep ``tree``, built over ``nodes`` (a copy kept; ``None``: a hierarchy, which
        keeps its own), as the most recent entry."""
        self.entries[key] = (None if nodes is None else nodes.copy(), tree)
        self.entries.move_to_end(key)
        while len(self.entries) > _TREES:
            self.entries.popitem(last=False)


@dataclass
class TreeLevel:
    """The facets of one size class of a master surface and the KD-tree of their centroids.

    Attributes
    ----------
    facets : ndarray of int64 or None
        Indices of the facets of the level (``None``: all the facets, in order).
    n : int
        Number of facets of the level.
    R : float
        Largest facet radius ``R_f`` of the level.
    tree : cKDTree
        KD-tree of the level's centroids (indices local to the level).
    slack : float
        Largest node movement since the tree was built.
    """

    facets: IntArray | None
    n: int
    R: float
    tree: cKDTree
    slack: float

    def facet(self, local: IntArray) -> IntArray:
        """Master facet indices of the level's facets ``local``."""
        return local if self.facets is None else self.facets[local]


def tree_levels(
    nodes: FloatArray, centroid: FloatArray, size: FloatArray, trees: TreeCache
) -> list[TreeLevel]:
    """The facets by size class, each with a KD-tree of its centroids: level ``l`` holds the
    facets of radius ``R_f`` in ``(R0 4^(l-1), R0 4^l]`` (level 0: ``R_f <= R0``), ``R0 =
    2 median(R_f)``. The candidates of a point are the centroids within ``r + R`` of it, with
    ``R`` the largest radius *of the level*: a few large facets do not widen the queries among
    the many small ones. A master of even facet size has one level (all its facets)."""
    if len(nodes) == 0:
        return []
    level = np.zeros(len(nodes), dtype=np.int64)
    base = _LEVEL_RADIUS * float(np.median(size))
    large = size > base
    if base > 0.0 and large.any():
        level[large] = np.ceil(np.log(size[large] / base) / np.log(_LEVEL_RATIO))
    kinds = np.unique(level)
    levels = []
    for k in kinds:
        f = None if kinds.size == 1 else np.flatnonzero(level == k)
        sub = (lambda a: a) if f is None else (lambda a, f=f: a[f])
        R = float(sub(size).max())
        tree, slack = trees.tree(sub(nodes), sub(centroid), R, int(k))
        levels.append(TreeLevel(f, len(sub(size)), R, tree, slack))
    return levels


def ball_candidates(
    level: TreeLevel, x: FloatArray, bound: FloatArray, active: IntArray
) -> tuple[IntArray, IntArray]:
    """All (point, facet) pairs with a centroid of the ``level`` within ``bound`` of the point.

    One ball query of the KD-tree per point, with the point's own bound (widened by the
    slack of a reused tree): no repeated K-nearest queries.
    """
    if active.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    lists = level.tree.query_ball_point(x[active], bound[active] + level.slack, return_sorted=False)
    count = np.fromiter(map(len, lists), dtype=np.int64, count=len(lists))
    fid = np.fromiter(itertools.chain.from_iterable(lists), dtype=np.int64, count=count.sum())
    return np.repeat(active, count), level.facet(fid)
