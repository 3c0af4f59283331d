"""Every facet kind of the search's table (:data:`contact_ufl.contact.search.FACET_KINDS`):
the shape functions, their derivatives and the unit normal of a curved, tilted facet from
each implementation -- UFL (:func:`~contact_ufl.contact.kinematics.master_shape_functions`,
:func:`~contact_ufl.contact.kinematics.facet_normal`), NumPy (the search's
:mod:`~contact_ufl.contact.search.shapes`) and C (``search_kernel.c``, through the closest
points it returns) -- against basix's tabulation of the Lagrange element the table names, an
independent reference, with the table's node permutation."""

from __future__ import annotations

import basix
import dolfinx
import numpy as np
import pytest
import ufl
from mpi4py import MPI

from contact_ufl.contact.kinematics import facet_normal, interpolate, master_shape_functions
from contact_ufl.contact.search import FACET_KINDS, FacetKind, closest_points, shape_functions
from contact_ufl.contact.search.shapes import tangent_vectors, unit_normal

#: The bound of every comparison with basix (values, derivatives, unit normals and ``M`` of
#: size ~1, in double precision: round-off of a few operations; measured <= 5.3e-15, the
#: second derivatives of the 9-node quadrilateral).
TOL = 1e-14
#: The bound of the reference coordinates found for a point off the facet along its normal
#: (measured <= 3.3e-16).
XI_TOL = 1e-15
#: rank-local evaluations: the 2-rank run would repeat them on each rank
pytestmark = pytest.mark.serial

#: Generic interior reference points of each reference cell.
INTERIOR = {
    "interval": [[0.2], [0.5], [0.73]],
    "triangle": [[0.2, 0.3], [1.0 / 3.0, 1.0 / 3.0], [0.6, 0.15]],
    "quadrilateral": [[0.2, 0.3], [0.5, 0.5], [0.8, 0.65]],
}


def element(kind: FacetKind) -> basix.finite_element.FiniteElement:
    """The basix element of the kind (equispaced Lagrange: its nodes are the facet's)."""
    cell = getattr(basix.CellType, kind.cell)
    variant = basix.LagrangeVariant.equispaced
    return basix.create_element(basix.ElementFamily.P, cell, kind.degree, variant)


def source(kind: FacetKind) -> str:
    return f"basix tabulation of the degree-{kind.degree} Lagrange element on the {kind.cell}"


def case(kind: FacetKind) -> str:
    return f"{kind.name} facet ({kind.nodes_per_facet} nodes, {kind.gdim}D), curved and tilted"


def reference_points(kind: FacetKind) -> np.ndarray:
    """Interior points and the element's own nodes (where ``N_a = delta_ab``)."""
    return np.concatenate([np.array(INTERIOR[kind.cell]), element(kind).points])


def facet(kind: FacetKind) -> np.ndarray:
    """The nodes ``(nodes_per_facet, gdim)`` of a non-trivial facet: the reference nodes
    mapped by a smooth nonlinear map and turned (a tilted straight segment or triangle, a
    warped bilinear quadrilateral, curved quadratic facets)."""
    xi = element(kind).points[list(kind.basix_order)]
    if kind.gdim == 2:
        u = xi[:, 0]
        y = np.stack([1.2 * u, 0.25 * u * (1.0 - u)], axis=1)
        c, s = np.cos(0.4), np.sin(0.4)
        return y @ np.array([[c, s], [-s, c]]) + [0.3, -0.1]
    s, t = xi[:, 0], xi[:, 1]
    y = np.stack(
        [1.1 * s + 0.1 * t, 0.9 * t - 0.05 * s, 0.3 * s * (1 - s) + 0.2 * t * t - 0.15 * s * t],
        axis=1,
    )
    turn = np.linalg.qr(np.array([[1.0, 0.3, -0.2], [0.2, 1.0, 0.4], [-0.3, 0.1, 1.0]]))[0]
    return y @ turn.T + [0.1, -0.2, 0.3]


def tabulated(kind: FacetKind, xi: np.ndarray):
    """basix's ``N (P, n)``, ``dN (P, n, fdim)`` and ``d2N (P, n, fdim, fdim)`` at ``xi``, in
    the facet's node order."""
    table = element(kind).tabulate(2, np.asarray(xi, dtype=np.float64))[..., 0]
    table = table[:, :, list(kind.basix_order)]
    fdim = kind.fdim
    unit = np.eye(fdim, dtype=int)
    dN = np.stack([table[basix.index(*unit[a])] for a in range(fdim)], axis=2)
    d2N = np.empty((*dN.shape, fdim))
    for a in range(fdim):
        for b in range(fdim):
            d2N[:, :, a, b] = table[basix.index(*(unit[a] + unit[b]))]
    return table[0], dN, d2N


def reference_normal(dN: np.ndarray, X: np.ndarray) -> np.ndarray:
    """The unit normal of the facet ``X`` from basix's derivatives (``(a1[1], -a1[0])`` in
    2D, ``a1 x a2`` in 3D, normalised)."""
    a = np.einsum("pna,ng->pag", dN, X)
    if a.shape[1] == 1:
        n = np.stack([a[:, 0, 1], -a[:, 0, 0]], axis=1)
    else:
        n = np.cross(a[:, 0], a[:, 1])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def ufl_values(kind: FacetKind, xi: np.ndarray, X: np.ndarray):
    """The UFL shape functions, their derivatives and the facet normal of the kinematics at
    each point ``xi``, evaluated by a compiled :class:`dolfinx.fem.Expression` (the facet's
    nodes and ``xi`` as constants)."""
    mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_SELF, 1)
    point = dolfinx.fem.Constant(mesh, np.zeros(kind.fdim))
    nodes = dolfinx.fem.Constant(mesh, X)
    N, dN = master_shape_functions(kind.nodes_per_facet, point)
    columns = [[dN[a][alpha] for a in range(kind.nodes_per_facet)] for alpha in range(kind.fdim)]
    tangents = [interpolate(column, nodes, kind.gdim) for column in columns]
    normal = facet_normal(tangents, 1.0)
    values = [*N, *(d for row in dN for d in row), *(normal[i] for i in range(kind.gdim))]
    expression = dolfinx.fem.Expression(ufl.as_vector(values), np.array([[0.5]]))
    out = []
    for row in xi:
        point.value[:] = row
        out.append(expression.eval(mesh, np.array([0], dtype=np.int32)).ravel())
    out = np.array(out)
    n, fdim = kind.nodes_per_facet, kind.fdim
    return out[:, :n], out[:, n : n + n * fdim].reshape(-1, n, fdim), out[:, n + n * fdim :]


@pytest.mark.parametrize("kind", FACET_KINDS, ids=[kind.name for kind in FACET_KINDS])
def test_numpy_shape_functions_are_basix(kind, verification):
    """Verification: the search's NumPy shape functions, first and second derivatives and
    unit normal are basix's, at interior points and at the element's nodes."""
    xi = reference_points(kind)
    X = facet(kind)
    N, dN, d2N = shape_functions(kind.nodes_per_facet, kind.gdim, xi)
    N_ref, dN_ref, d2N_ref = tabulated(kind, xi)
    normal = unit_normal(tangent_vectors(dN, np.broadcast_to(X, (len(xi), *X.shape))))
    errors = [
        np.abs(N - N_ref).max(),
        np.abs(dN - dN_ref).max(),
        np.abs(d2N - d2N_ref).max(),
        np.abs(normal - reference_normal(dN_ref, X)).max(),
    ]
    quantity = "max |N|, |dN|, |d2N|, |unit normal| differences (NumPy)"
    verification(case(kind), quantity, errors, 0.0, TOL, source(kind))
    assert max(errors) <= TOL


@pytest.mark.parametrize("kind", FACET_KINDS, ids=[kind.name for kind in FACET_KINDS])
def test_ufl_shape_functions_are_basix(kind, verification):
    """Verification: the kinematics' UFL shape functions, their derivatives and the facet
    normal, compiled and evaluated, are basix's."""
    xi = reference_points(kind)
    X = facet(kind)
    N, dN, normal = ufl_values(kind, xi, X)
    N_ref, dN_ref, _ = tabulated(kind, xi)
    errors = [
        np.abs(N - N_ref).max(),
        np.abs(dN - dN_ref).max(),
        np.abs(normal - reference_normal(dN_ref, X)).max(),
    ]
    quantity = "max |N|, |dN|, |unit normal| differences (UFL)"
    verification(case(kind), quantity, errors, 0.0, TOL, source(kind))
    assert max(errors) <= TOL


@pytest.mark.parametrize("backend", ["compiled", "numpy"])
@pytest.mark.parametrize("kind", FACET_KINDS, ids=[kind.name for kind in FACET_KINDS])
def test_search_closest_points_are_basix(kind, backend, verification):
    """Verification: points off the facet along its normal at interior points ``xi*``
    project back onto ``xi*``, and the search's closest point, unit normal and linearisation
    ``M = A^-1`` (``A_ab = a_a . a_b - (x - y) . y_,ab``) at the ``xi`` it returns are
    basix's: the C kernel's shape functions and their first and second derivatives (its
    only exposed use), and those of the NumPy search."""
    X = facet(kind)
    xi_star = np.array(INTERIOR[kind.cell])
    N_ref, dN_ref, _ = tabulated(kind, xi_star)
    y_star = N_ref @ X
    offsets = np.array([0.01, -0.01])  # in front of and behind the facet
    x = y_star[None] + offsets[:, None, None] * reference_normal(dN_ref, X)[None]
    x = x.reshape(-1, kind.gdim)
    proj = closest_points(x, X[None], np.inf, backend=backend)
    assert np.all(proj.facet == 0)
    N, dN, d2N = tabulated(kind, proj.xi)
    y = N @ X
    a = np.einsum("pna,ng->pag", dN, X)
    curvature = np.einsum("pnab,ng->pabg", d2N, X)
    A = np.einsum("pag,pbg->pab", a, a) - np.einsum("pg,pabg->pab", x - y, curvature)
    M = np.linalg.inv(A)
    xi_error = np.abs(proj.xi - np.tile(xi_star, (len(offsets), 1))).max()
    errors = [
        np.abs(proj.y - y).max(),
        np.abs(proj.normal - reference_normal(dN, X)).max(),
        (np.abs(proj.sliding - M).max(axis=(1, 2)) / np.abs(M).max(axis=(1, 2))).max(),
    ]
    quantity = f"max |y|, |unit normal|, |M| / max |M| differences at the xi found ({backend})"
    verification(case(kind), quantity, errors, 0.0, TOL, source(kind))
    quantity = f"max |xi - xi*| of points 0.01 off the facet along its normal at xi* ({backend})"
    reference = "the closest point of a point off the surface along its normal"
    verification(case(kind), quantity, xi_error, 0.0, XI_TOL, reference)
    assert max(errors) <= TOL
    assert xi_error <= XI_TOL
