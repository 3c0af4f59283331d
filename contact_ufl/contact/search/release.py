"""The release rules of a search: the closest points that are not contact partners are
unpaired (in place) -- beyond the boundary of the master surface, beyond the edge of a
self-contact point's admissible facets, and the master side of a self-contact interface.
"""

from __future__ import annotations

import numpy as np

from contact_ufl.contact.search.kinds import on_edges
from contact_ufl.contact.search.projection import Projection, SelfContact
from contact_ufl.keysets import unique


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
    paired = paired[boundary.any(axis=1)[proj.facet[paired]]]  # on a facet at the boundary
    if len(paired) == 0:
        return
    on_edge = on_edges(boundary.shape[1], proj.xi[paired])  # as many edges as nodes
    paired = paired[(on_edge & boundary[proj.facet[paired]]).any(axis=1)]
    d = points[paired] - proj.y[paired]
    normal_part = np.einsum("pd,pd->p", d, proj.normal[paired])
    off_normal = np.linalg.norm(d - normal_part[:, None] * proj.normal[paired], axis=1)
    beyond = (off_normal > 1e-6 * np.linalg.norm(d, axis=1)) & (off_normal > tolerance)
    released = paired[beyond]
    proj.facet[released] = -1
    proj.gap[released] = -np.inf


def release_master_side(proj: Projection, rule: SelfContact) -> None:
    """Keep one side of every self-contact interface as the slave (in place).

    Two facing parts of a self-contact surface would each find the other: the constraint
    would be imposed twice, by two multipliers whose split is undetermined (a singular
    tangent). A pair (point of facet ``F``, facet ``f``) is kept only if the smallest vertex
    key of ``F`` is below that of ``f`` (the two facets share no vertex, so the keys differ:
    no tie, no tolerance, the same on any number of ranks): of two facing facets, the one of
    lower key is the slave, the other the master. The closest point itself is not changed.
    """
    paired = np.flatnonzero(proj.facet >= 0)
    own = rule.point_nodes[paired].min(axis=1)
    partner = rule.facet_nodes[proj.facet[paired]].min(axis=1)
    released = paired[partner < own]
    proj.facet[released] = -1
    proj.gap[released] = -np.inf


def release_beside_own_facet(
    proj: Projection, points: np.ndarray, rule: SelfContact, tolerance: float = 0.0
) -> None:
    """Unpair the self-contact points beyond the edge of their admissible facets (in place).

    The facets around a point's own facet (those sharing a vertex with it) are excluded from
    its search: the rest of the surface has there an edge, as a surface has at its boundary.
    A point whose closest point is on the boundary of a facet that touches the excluded ones
    (a vertex of the facet is a vertex of an excluded facet), off the facet's normal through
    it by more than ``tolerance`` (round-off), lies beyond that edge: the surface continues
    into the excluded facets there, and the point is not in contact with it (as in
    :func:`release_beyond_boundary`).
    """
    paired = np.flatnonzero(proj.facet >= 0)
    if len(paired) == 0:
        return
    facet = proj.facet[paired]
    vertices = rule.facet_nodes.shape[1]
    on_boundary = on_edges(vertices, proj.xi[paired]).any(axis=1)
    d = points[paired] - proj.y[paired]
    normal_part = np.einsum("pd,pd->p", d, proj.normal[paired])
    off_normal = np.linalg.norm(d - normal_part[:, None] * proj.normal[paired], axis=1)
    off = on_boundary & (off_normal > 1e-6 * np.linalg.norm(d, axis=1)) & (off_normal > tolerance)
    # vertex pairs of the same facet, over the facets of the search (the excluded facets
    # around a point's facet are among them: they are within a facet's size of the point)
    pairs = unique(
        np.concatenate(
            [
                _pair_codes(rule.facet_nodes[:, i], rule.facet_nodes[:, j])
                for i in range(vertices)
                for j in range(vertices)
                if i != j
            ]
        )
    )
    own, theirs = rule.point_nodes[paired], rule.facet_nodes[facet]
    touches = np.zeros(len(paired), dtype=bool)
    for i in range(theirs.shape[1]):
        for j in range(own.shape[1]):
            code = _pair_codes(theirs[:, i], own[:, j])
            pos = np.minimum(np.searchsorted(pairs, code), len(pairs) - 1)
            touches |= pairs[pos] == code
    released = paired[off & touches]
    proj.facet[released] = -1
    proj.gap[released] = -np.inf


def _pair_codes(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """One integer per ordered pair of vertex keys (keys below 2^31)."""
    return a.astype(np.int64) * (1 << 31) + b.astype(np.int64)
