"""The shape functions of every facet kind (:mod:`.kinds`) in NumPy, and the tangents and unit
normals they give: vectorised over points, ``y(xi) = sum_a N_a(xi) x_a``, ``a_alpha =
dy/dxi^alpha``, the normal ``(a1[1], -a1[0]) / |a1|`` (2D) or ``a1 x a2 / |a1 x a2|`` (3D).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from contact_ufl.contact.search.kinds import QUADRATIC, FloatArray, facet_kind

#: The 1D index (0: start, 1: end, 2: middle) of the nodes of a 9-node quadrilateral in s and t.
_Q9 = ((0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (1, 2), (2, 1), (0, 2), (2, 2))


def shape_functions(
    nodes_per_facet: int, gdim: int, xi: npt.ArrayLike
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Shape functions of a master facet and their first and second derivatives.

    Parameters
    ----------
    nodes_per_facet : int
        Number of nodes of the facet (:data:`.kinds.FACET_KINDS`).
    gdim : int
        Geometric dimension (2 for segments, 3 otherwise).
    xi : array_like, shape (np, fdim)
        Reference coordinates, ``fdim = gdim - 1``.

    Returns
    -------
    N : ndarray, shape (np, nodes_per_facet)
        Shape functions.
    dN : ndarray, shape (np, nodes_per_facet, fdim)
        ``dN[p, a, alpha] = dN_a / dxi^alpha``.
    d2N : ndarray, shape (np, nodes_per_facet, fdim, fdim)
        ``d2N[p, a, alpha, beta] = d2N_a / dxi^alpha dxi^beta``.
    """
    kind = facet_kind(nodes_per_facet, gdim)
    fdim = gdim - 1
    xi = np.asarray(xi, dtype=np.float64).reshape(-1, fdim)
    if kind in QUADRATIC:
        return quadratic_shape_functions(kind, xi)
    npts = xi.shape[0]
    dN = np.zeros((npts, nodes_per_facet, fdim))
    d2N = np.zeros((npts, nodes_per_facet, fdim, fdim))
    if kind == "segment":
        u = xi[:, 0]
        N = np.stack([1.0 - u, u], axis=1)
        dN[:, :, 0] = [-1.0, 1.0]
    elif kind == "triangle":
        N = np.stack([1.0 - xi[:, 0] - xi[:, 1], xi[:, 0], xi[:, 1]], axis=1)
        dN[:] = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]
    else:
        s, t = xi[:, 0], xi[:, 1]
        N = np.stack([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t], axis=1)
        dN[:, :, 0] = np.stack([t - 1.0, 1.0 - t, -t, t], axis=1)
        dN[:, :, 1] = np.stack([s - 1.0, -s, 1.0 - s, s], axis=1)
        d2N[:, :, 0, 1] = d2N[:, :, 1, 0] = [1.0, -1.0, -1.0, 1.0]
    return N, dN, d2N


def quadratic_shape_functions(
    kind: str, xi: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Shape functions of a quadratic facet and their first and second derivatives.

    ``kind``: ``"segment3"`` (nodes: the two ends, then the midpoint; ``xi`` in ``[0, 1]``)
    or ``"triangle6"`` (the vertices, then the midpoints of the edges 01, 12 and 02; with the
    barycentric ``L = (1 - xi1 - xi2, xi1, xi2)``: ``N_i = L_i (2 L_i - 1)``,
    ``N_ij = 4 L_i L_j``) or ``"quadrilateral9"`` (the tensor product of the 1D functions;
    node order of :data:`.curved.QUADRILATERAL9_EDGES`). Shapes as :func:`shape_functions`.
    """
    npts = xi.shape[0]
    if kind == "quadrilateral9":
        return _quadrilateral9(xi)
    if kind == "segment3":
        u = xi[:, 0]
        N = np.stack([(1 - u) * (1 - 2 * u), u * (2 * u - 1), 4 * u * (1 - u)], axis=1)
        dN = np.stack([4 * u - 3, 4 * u - 1, 4 - 8 * u], axis=1)[:, :, None]
        d2N = np.broadcast_to(np.array([4.0, 4.0, -8.0])[:, None, None], (npts, 3, 1, 1))
        return N, dN, d2N.copy()
    L = np.stack([1.0 - xi[:, 0] - xi[:, 1], xi[:, 0], xi[:, 1]], axis=1)
    dL = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])  # dL_i / dxi^alpha
    pairs = ((0, 1), (1, 2), (0, 2))
    N = np.empty((npts, 6))
    dN = np.empty((npts, 6, 2))
    d2N = np.empty((npts, 6, 2, 2))
    for i in range(3):
        N[:, i] = L[:, i] * (2 * L[:, i] - 1)
        dN[:, i] = (4 * L[:, i] - 1)[:, None] * dL[i]
        d2N[:, i] = 4 * np.outer(dL[i], dL[i])
    for k, (i, j) in enumerate(pairs):
        N[:, 3 + k] = 4 * L[:, i] * L[:, j]
        dN[:, 3 + k] = 4 * (L[:, j, None] * dL[i] + L[:, i, None] * dL[j])
        d2N[:, 3 + k] = 4 * (np.outer(dL[i], dL[j]) + np.outer(dL[j], dL[i]))
    return N, dN, d2N


def _line(u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """1D quadratic Lagrange functions (start, end, middle) at ``u`` and their derivatives,
    ``(3, n)`` each."""
    one = np.ones_like(u)
    values = np.stack([(1 - u) * (1 - 2 * u), u * (2 * u - 1), 4 * u * (1 - u)])
    dl = np.stack([4 * u - 3, 4 * u - 1, 4 - 8 * u])
    d2l = np.stack([4 * one, 4 * one, -8 * one])
    return values, dl, d2l


def _quadrilateral9(xi: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Tensor-product quadratic functions of the 9-node quadrilateral (node order of
    :data:`.curved.QUADRILATERAL9_EDGES`)."""
    (ls, dls, d2ls), (lt, dlt, d2lt) = _line(xi[:, 0]), _line(xi[:, 1])
    i, j = np.array(_Q9).T
    N = (ls[i] * lt[j]).T
    dN = np.stack([(dls[i] * lt[j]).T, (ls[i] * dlt[j]).T], axis=2)
    st = (dls[i] * dlt[j]).T
    d2N = np.stack(
        [np.stack([(d2ls[i] * lt[j]).T, st], 2), np.stack([st, (ls[i] * d2lt[j]).T], 2)], 2
    )
    return N, dN, d2N


def dot(a: FloatArray, b: FloatArray) -> FloatArray:
    """Dot products over the last axis."""
    return np.einsum("...i,...i->...", a, b)


def normalise(v: list[FloatArray]) -> list[FloatArray]:
    """Unit vectors from the coordinate columns ``v``; zero where ``v`` is zero."""
    length = np.sqrt(sum(vk * vk for vk in v))
    scale = np.divide(1.0, length, out=np.zeros_like(length), where=length > 0)
    return [vk * scale for vk in v]


def tangent_vectors(dN: FloatArray, X: FloatArray) -> FloatArray:
    """Tangent vectors ``a[p, alpha] = sum_n dN[p, n, alpha] X[p, n]`` (P, fdim, gdim) from
    the shape function derivatives (P, nodes, fdim) and the nodes (P, nodes, gdim)."""
    a = dN[:, 0, :, None] * X[:, 0, None, :]
    for n in range(1, X.shape[1]):
        a += dN[:, n, :, None] * X[:, n, None, :]
    return a


def unit_normal(a: FloatArray) -> FloatArray:
    """Unit normal from the tangent vectors ``a`` (P, fdim, gdim); zero if degenerate."""
    if a.shape[1] == 1:
        n = np.stack([a[:, 0, 1], -a[:, 0, 0]], axis=1)
    else:
        n = np.cross(a[:, 0], a[:, 1])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def centre_normal(X: list[list[FloatArray]], nodes_per_facet: int, g: int) -> list[FloatArray]:
    """Columns of the normal ``a1 x a2`` (2D: ``(a1[1], -a1[0])``) at the centre of each
    facet of ``nodes_per_facet`` nodes in dimension ``g``, from the coordinate columns
    ``X[a][k]`` of its nodes."""
    centre = 1.0 / 3.0 if facet_kind(nodes_per_facet, g) == "triangle6" else 0.5
    _, dN, _ = shape_functions(nodes_per_facet, g, np.full((1, g - 1), centre))
    a = [
        [
            sum(dN[0, n, alpha] * X[n][k] for n in range(nodes_per_facet) if dN[0, n, alpha] != 0)
            for k in range(g)
        ]
        for alpha in range(g - 1)
    ]
    if g == 2:
        return [a[0][1], -a[0][0]]
    a1, a2 = a
    return [
        a1[1] * a2[2] - a1[2] * a2[1],
        a1[2] * a2[0] - a1[0] * a2[2],
        a1[0] * a2[1] - a1[1] * a2[0],
    ]
