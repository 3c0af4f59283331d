"""The smoothed master normal at the closest points, in NumPy: the twins of the UFL
:func:`~contact_ufl.contact.kinematics.smoothed_normal` (2D: from the nodes before and after
the segment) and :func:`~contact_ufl.contact.kinematics.smoothed_normal_3d` (3D: from the
fans of the facet's nodes, :func:`~contact_ufl.contact.master.node_fans`).
"""

from __future__ import annotations

import numpy as np

from contact_ufl.contact.search.shapes import shape_functions


def smoothed_normals(xi: np.ndarray, nodes: np.ndarray, flags: np.ndarray) -> np.ndarray:
    """NumPy twin of :func:`contact_ufl.contact.kinematics.smoothed_normal` for paired
    points: ``xi (n, 1)``, ``nodes (n, 4, 2)``, ``flags (n, 2)``; returns unit normals
    ``(n, 2)`` (by coordinate columns: NumPy reduces rows of two numbers slowly)."""
    a, b, before, after = ([nodes[:, k, d] for d in range(2)] for k in range(4))
    segment = [b[d] - a[d] for d in range(2)]
    incoming = [np.where(flags[:, 0], a[d] - before[d], segment[d]) for d in range(2)]
    outgoing = [np.where(flags[:, 1], after[d] - b[d], segment[d]) for d in range(2)]

    def unit_perp(t):
        length = np.sqrt(t[1] * t[1] + t[0] * t[0])
        return [t[1] / length, -t[0] / length]

    s, u = xi[:, 0], 1.0 - xi[:, 0]
    ends = [unit_perp(incoming), unit_perp(segment), unit_perp(outgoing)]
    n = [u * (ends[0][d] + ends[1][d]) + s * (ends[1][d] + ends[2][d]) for d in range(2)]
    length = np.sqrt(n[0] * n[0] + n[1] * n[1])
    return np.stack([n[0] / length, n[1] / length], axis=1)


def fan_normals(nodes: np.ndarray, nodes_per_facet: int) -> np.ndarray:
    """Unit nodal normals of 3D master facets from their carried nodes: ``nodes (n,
    gathered, 3)``, the ``nodes_per_facet`` facet nodes then the fans of
    :func:`~contact_ufl.contact.master.node_fans`; returns ``(n, nodes_per_facet, 3)``.

    The nodal normal of ``a`` is the sum over its fan of the corner normals ``(s_i - a) x
    (s_i+1 - a)``: each the unit normal of a facet around ``a`` weighted by the area of the
    parallelogram its two edges at ``a`` span (twice a triangle's area; a bilinear
    quadrilateral's area when it is a parallelogram), normalised.
    """
    n, slots = len(nodes), (nodes.shape[1] - nodes_per_facet) // nodes_per_facet
    own = nodes[:, :nodes_per_facet]
    fan = nodes[:, nodes_per_facet:].reshape(n, nodes_per_facet, slots, 3) - own[:, :, None]
    normal = np.cross(fan[:, :, :-1], fan[:, :, 1:]).sum(axis=2)
    return normal / np.linalg.norm(normal, axis=2, keepdims=True)


def smoothed_normals_3d(xi: np.ndarray, nodes: np.ndarray, nodes_per_facet: int) -> np.ndarray:
    """NumPy twin of :func:`contact_ufl.contact.kinematics.smoothed_normal_3d` for paired
    points: ``xi (n, 2)``, ``nodes (n, gathered, 3)`` (see :func:`fan_normals`); returns unit
    normals ``(n, 3)``: the normalised interpolation of the nodal normals."""
    N = shape_functions(nodes_per_facet, 3, xi)[0]
    normal = np.einsum("pa,pad->pd", N, fan_normals(nodes, nodes_per_facet))
    return normal / np.linalg.norm(normal, axis=1, keepdims=True)
