"""The result of a closest-point search: :class:`Projection`, and the admissibility rule of
a self-contact search (:class:`SelfContact`).

Linearisation
-------------
The reference coordinates ``xi`` of the closest point move with the slave point ``x`` and the
master nodes ``x_a`` as ``d(xi) = M b``, with

``b_alpha = a_alpha . (dx - sum_a N_a dx_a) + (x - y) . sum_a dN_a/dxi^alpha dx_a``

and ``A_ab = a_a . a_b - (x - y) . d(a_a)/d(xi^b)``. ``M`` (:attr:`Projection.sliding`)
depends on where the closest point lies, classified with the exact clamped reference
coordinates (a coordinate clamped to its bound is on that bound, one that is not clamped is
not):

* strictly inside the facet: ``M = A^-1``;
* on an edge (one bound active, for the triangle ``xi1 = 0``, ``xi2 = 0`` or the hypotenuse
  ``xi1 + xi2 = 1``), ``t`` the edge direction in reference space: ``M = t t^T / (t^T A t)``;
* at a vertex (end point of a segment, two bounds active): ``M = 0``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from contact_ufl.contact.search.kinds import BoolArray, FloatArray, IntArray
from contact_ufl.contact.search.shapes import dot

#: The fields of a :class:`Projection`.
FIELDS = ("facet", "xi", "y", "normal", "gap", "distance", "sliding")

NON_FINITE = "{what} of the closest-point search hold non-finite values (NaN or infinity)"


def non_finite(what: str, values: np.ndarray) -> str | None:
    """The message of :data:`NON_FINITE` for ``what`` (points, or facets' nodes: the rows of
    ``values``) naming how many rows hold a NaN or infinity and the first one, or ``None``
    if every value is finite."""
    bad = ~np.isfinite(values.reshape(len(values), -1)).all(axis=1)
    if not bad.any():
        return None
    first = int(np.argmax(bad))
    return NON_FINITE.format(what=what) + f": {int(bad.sum())} of {len(values)}, first row {first}"


@dataclass
class Projection:
    """Closest points of slave points on a master surface.

    Attributes
    ----------
    facet : ndarray of int64, shape (np,)
        Index into the facets given of the facet holding the closest point, ``-1`` where no
        facet lies within the search radius.
    xi : ndarray, shape (np, fdim)
        Reference coordinates of the closest point on that facet.
    y : ndarray, shape (np, gdim)
        Closest point ``y = sum_a N_a(xi) x_a``.
    normal : ndarray, shape (np, gdim)
        Master unit normal ``nu`` at ``xi``.
    gap : ndarray, shape (np,)
        Proximity ``g = -nu . (x - y)``; ``g > 0`` means penetration.
    distance : ndarray, shape (np,)
        ``|x - y|``.
    sliding : ndarray, shape (np, fdim, fdim)
        Linearisation matrix ``M``: ``d(xi) = M b`` (see the module docstring).

    Notes
    -----
    Where ``facet == -1`` the other fields hold placeholders: ``xi = 0``, ``y = x`` (the slave
    point itself), ``normal = 0``, ``distance = inf``, ``gap = -inf`` (never in contact) and
    ``sliding = 0``.
    """

    facet: IntArray
    xi: FloatArray
    y: FloatArray
    normal: FloatArray
    gap: FloatArray
    distance: FloatArray
    sliding: FloatArray


@dataclass
class SelfContact:
    """Which (point, facet) pairs may pair when a surface is searched against itself.

    A point of a surface is at distance zero from the facet that holds it and close to that
    facet's neighbours: those are excluded by topology, not by a distance, so that no
    tolerance is needed. A pair (point ``p``, facet ``f``) is admissible when

    * ``f`` shares no node with the facet holding ``p`` (node numbers compared exactly), and
    * the normal ``n_f`` at the centre of ``f`` opposes the point's current outward normal
      ``n_p``: ``n_f . n_p < 0`` (a facet behind the point, on the same side of the body,
      faces the same way and is not a contact partner).

    Attributes
    ----------
    point_nodes : ndarray of int64, shape (np, m)
        Node numbers of the facet holding each point (``m`` nodes per slave facet).
    facet_nodes : ndarray of int64, shape (nf, nodes_per_facet)
        Node numbers of each master facet, in the same numbering (global or input indices).
    point_normals : ndarray, shape (np, gdim)
        Current outward unit normal of the surface at each point.
    """

    point_nodes: IntArray
    facet_nodes: IntArray
    point_normals: FloatArray

    def admissible(self, pid: IntArray, fid: IntArray, facet_normal: FloatArray) -> BoolArray:
        """Mask of the admissible pairs (points ``pid``, facets ``fid``, (P,) each), given
        the unit normals ``facet_normal`` (P, gdim) of the facets at their centres."""
        mine, theirs = self.point_nodes[pid], self.facet_nodes[fid]
        share = np.zeros(pid.shape, dtype=bool)
        for i in range(mine.shape[1]):
            for j in range(theirs.shape[1]):
                share |= mine[:, i] == theirs[:, j]
        opposed = dot(self.point_normals[pid], facet_normal) < 0.0
        return ~share & opposed
