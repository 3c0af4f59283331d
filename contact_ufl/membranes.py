"""Membranes and strings: the oriented reference normal, kinematics, laws and follower pressure.

A *membrane* is a surface mesh in 3D (triangles or quadrilaterals: topological dimension 2,
geometric dimension 3); a *string* is a curve mesh in 2D (intervals). Both carry a
displacement field ``u`` with ``gdim`` components. Their mechanics are written once in UFL:

- On such a manifold mesh ``ufl.grad(u)`` is a ``gdim x gdim`` tangential tensor (built with
  the pseudo-inverse of the Jacobian), so ``F = I + grad u`` maps the reference normal ``n0``
  to itself, ``F n0 = n0``. The tangent projector ``P = I - n0 n0`` is built from ``n0``
  (``grad`` of the spatial coordinate is the identity, not ``P``).
- The membrane right Cauchy-Green tensor in the tangent plane is ``C_s = P F^T F P``; for two
  reference tangents ``X1, X2``, ``X1 . C_s X2 = (F X1) . (F X2)``.
- The current area vector per unit reference area is ``a = cof(F) n0``: with an orthonormal
  reference tangent basis ``t1, t2`` (``t1 x t2 = n0``), ``cof(F) (t1 x t2) = F t1 x F t2 =
  g1 x g2``. Its length is the area stretch ``J_s`` and ``a / J_s`` the current unit normal,
  on the side of ``n0``. For a string in 2D, ``cof(F) = R F R^T`` with ``R`` the rotation by
  90 degrees, so ``a`` is the current tangent ``F t0`` rotated: the current normal times the
  length stretch, again on the side of ``n0``.

A string is the cross-section of a long membrane held at axial stretch 1 (plane strain, like
the package's 2D solids): its energy is per unit reference length *and unit depth*, its
``thickness`` the cross-section area per unit depth, and its laws are the membrane laws with
the out-of-plane stretch 1. The in-plane invariant ``I1 = tr C_s + (3 - gdim)`` and the area
stretch ``J_s`` serve both cases.

The orientation of ``n0`` is not the vertex order of the cells (``ufl.CellNormal`` follows it,
and meshes come with any order): :func:`cell_orientation` makes a sign per cell so that
neighbouring cells agree and each connected component points to a chosen outward side.

A membrane has no bending and no compressive stiffness: at ``u = 0`` a flat membrane has no
stiffness normal to itself. A solve starts from a curved reference (a tube, a sphere), a
pre-stress, or an inflation first, with load stepping; where the membrane goes slack
(compressed) the tangent becomes singular and Newton fails or wrinkles are smeared.

Forms, on the membrane mesh's own ``dx`` (``quadrature_degree`` 2 is exact for P1 on flat
triangles, where everything but ``v`` is constant per cell; 4 for P2)::

    n0 = reference_normal(mesh)                  # or orientation * vertex_order_normal(mesh)
    energy = law.strain_energy(u, n0) * dx
    residual = ufl.derivative(energy, u, v) - pressure_virtual_work(u, v, n0, p) * dx
    jacobian = ufl.derivative(residual, u, du)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from contact_ufl import jit
from contact_ufl.errors import ContactInputError, collective_check
from contact_ufl.loads import deformation_gradient
from contact_ufl.materials import lame_parameters

Expr = ufl.core.expr.Expr

#: cycle of the local vertices around a cell, in the sense of its vertex-order normal
_CYCLES = {"triangle": (0, 1, 2), "quadrilateral": (0, 1, 3, 2)}


# -- the reference normal ----------------------------------------------------------------------


def check_manifold(mesh: dolfinx.mesh.Mesh) -> None:
    """Raise on every rank unless ``mesh`` is a membrane (tdim 2 in 3D) or a string (tdim 1 in
    2D)."""
    tdim, gdim = mesh.topology.dim, mesh.geometry.dim
    cell = mesh.topology.cell_name()
    ok = (tdim, gdim) in ((2, 3), (1, 2)) and (tdim == 1 or cell in _CYCLES)
    collective_check(
        mesh.comm,
        ok,
        "a membrane mesh must have triangles or quadrilaterals in 3D and a string mesh "
        f"intervals in 2D, got {cell} cells (dimension {tdim}) in {gdim}D",
    )


def vertex_order_normal(mesh: dolfinx.mesh.Mesh) -> Expr:
    """The unit normal of each cell in the sense of its vertex order (UFL, pointwise).

    ``J[:, 0] x J[:, 1]`` normalised on a surface in 3D, ``(J[1, 0], -J[0, 0])`` normalised on
    a curve in 2D (``J`` the Jacobian of the cell map). Built from the Jacobian rather than
    ``ufl.CellNormal``, whose lowering multiplies by a cell orientation that the form compiler
    does not provide.
    """
    J = ufl.Jacobian(mesh)
    if mesh.topology.dim == 2:
        N = ufl.cross(J[:, 0], J[:, 1])
    else:
        N = ufl.as_vector((J[1, 0], -J[0, 0]))
    return N / ufl.sqrt(ufl.dot(N, N))


def _cell_integrals(mesh: dolfinx.mesh.Mesh) -> np.ndarray:
    """Per owned cell: area, ``int x``, ``int N`` and ``int N . x`` with ``N`` the vertex-order
    normal; shape ``(num_owned_cells, 2 + 2 gdim)``."""
    gdim = mesh.geometry.dim
    x = ufl.SpatialCoordinate(mesh)
    N = vertex_order_normal(mesh)
    xs, Ns = [x[i] for i in range(gdim)], [N[i] for i in range(gdim)]
    columns = ufl.as_vector([1.0, *xs, *Ns, ufl.dot(N, x)])
    W = dolfinx.fem.functionspace(mesh, ("DG", 0, (2 + 2 * gdim,)))
    dx = ufl.Measure("dx", mesh, metadata={"quadrature_degree": 2})
    form = jit.form(ufl.dot(columns, ufl.TestFunction(W)) * dx)
    b = dolfinx.fem.assemble_vector(form)
    b.scatter_reverse(dolfinx.la.InsertMode.add)
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    dofs = W.dofmap.list[:owned, 0]
    return b.array.reshape(-1, 2 + 2 * gdim)[dofs]


def _facet_keys(mesh: dolfinx.mesh.Mesh) -> tuple[np.ndarray, np.ndarray]:
    """The facets of the owned cells as global keys, and the sense each cell gives them.

    On a surface the facets are the edges, traversed along the cycle of the cell's vertices:
    key ``(min, max)`` of the global node numbers, sense ``+1`` from the smaller to the larger.
    On a curve the facets are the end points: sense ``-1`` at the first, ``+1`` at the second.
    Two cells agree across a facet when they give it opposite senses. Returns ``keys``
    ``(num_owned_cells, num_facets, 2)`` and ``senses`` ``(num_owned_cells, num_facets)``.
    """
    tdim = mesh.topology.dim
    owned = mesh.topology.index_map(tdim).size_local
    nodes = mesh.geometry.dofmaps[0][:owned]
    nodes = mesh.geometry.index_map().local_to_global(nodes.ravel()).reshape(nodes.shape)
    if tdim == 1:
        keys = np.stack([nodes[:, :2], nodes[:, :2]], axis=-1)
        return keys, np.broadcast_to(np.array([-1, 1]), (owned, 2))
    cycle = np.array(_CYCLES[mesh.topology.cell_name()])
    start, end = nodes[:, cycle], nodes[:, np.roll(cycle, -1)]
    keys = np.stack([np.minimum(start, end), np.maximum(start, end)], axis=-1)
    return keys, np.where(start < end, 1, -1)


@dataclass(frozen=True)
class _Surface:
    """The gathered surface on rank 0: facet keys and senses, cell integrals."""

    keys: np.ndarray
    senses: np.ndarray
    integrals: np.ndarray


def _signs_within_components(keys: np.ndarray, senses: np.ndarray):
    """Signs making neighbouring cells agree, and the connected component of each cell.

    The cells are the nodes of a graph whose edges are the shared facets, each marked with
    whether its two cells disagree (same sense). The doubled graph has the nodes ``(cell,
    flipped)`` and joins ``(c1, s)`` to ``(c2, s xor disagree)``: a component is orientable iff
    no cell is joined to its own flip, and a cell's sign is then whether its node is in the
    same doubled component as the unflipped root of its component (scipy connected components,
    no loop over cells). Returns ``(sign, component)``; raises ``ContactInputError`` (on the
    calling rank only) for a non-manifold or non-orientable surface.
    """
    num_cells, num_facets = senses.shape
    flat_keys = keys.reshape(-1, 2)
    _, facet, counts = np.unique(flat_keys, axis=0, return_inverse=True, return_counts=True)
    facet = facet.ravel()
    if counts.size and counts.max() > 2:
        raise ContactInputError(
            f"the membrane is not a manifold: {int((counts > 2).sum())} facets are shared by "
            "more than two cells"
        )
    order = np.argsort(facet, kind="stable")
    shared = np.flatnonzero(counts[facet[order]] == 2)[::2]
    first, second = order[shared], order[shared + 1]
    c1, c2 = first // num_facets, second // num_facets
    disagree = (senses.ravel()[first] == senses.ravel()[second]).astype(np.int64)
    n = num_cells
    rows = np.concatenate([c1, c1 + n])
    cols = np.concatenate([c2 + n * disagree, c2 + n * (1 - disagree)])
    doubled = coo_matrix((np.ones(rows.size), (rows, cols)), shape=(2 * n, 2 * n))
    _, label = connected_components(doubled, directed=False)
    base = coo_matrix((np.ones(c1.size), (c1, c2)), shape=(n, n))
    _, component = connected_components(base, directed=False)
    if np.any(label[:n] == label[n:]):
        raise ContactInputError(
            "the membrane cannot be oriented consistently (a non-orientable surface such as "
            "a Moebius strip): no choice of normal agrees across all shared edges"
        )
    _, root = np.unique(component, return_index=True)
    sign = np.where(label[:n] == label[root[component]], 1.0, -1.0)
    return sign, component


def _orient(
    surface: _Surface, outward: Sequence[float] | None, direction: Sequence[float] | None
) -> np.ndarray:
    """The sign of every gathered cell (rank 0): consistent, then outward per component."""
    sign, component = _signs_within_components(surface.keys, surface.senses)
    return _outward_signs(surface, sign, component, outward, direction)


def _outward_signs(
    surface: _Surface,
    sign: np.ndarray,
    component: np.ndarray,
    outward: Sequence[float] | None,
    direction: Sequence[float] | None,
) -> np.ndarray:
    """Flip whole components so that each points to its outward side.

    The side is the sign of ``m = sum_c s_c int_c N . (x - p)`` (away from the point ``p``:
    ``outward``, or by default the area centroid of the component) or ``sum_c s_c int_c N . d``
    (along ``direction``). For a closed surface and ``p`` inside, ``m`` is 3 (2 for a closed
    curve) times the enclosed volume: positive exactly for the outward normal.
    """
    I = surface.integrals
    gdim = (I.shape[1] - 2) // 2
    area, xint, Nint, Nx = I[:, 0], I[:, 1 : 1 + gdim], I[:, 1 + gdim : 1 + 2 * gdim], I[:, -1]
    ncomp = int(component.max()) + 1 if component.size else 0
    per = np.zeros((ncomp, gdim))
    sN = sign[:, None] * Nint
    np.add.at(per, component, sN)
    if direction is not None:
        m = per @ np.asarray(direction, dtype=float)
        scale = np.bincount(component, area, ncomp) * np.linalg.norm(direction)
    else:
        comp_area = np.bincount(component, area, ncomp)
        centroid = np.zeros((ncomp, gdim))
        np.add.at(centroid, component, xint)
        centroid /= comp_area[:, None]
        p = centroid if outward is None else np.broadcast_to(np.asarray(outward, float), per.shape)
        m = np.bincount(component, sign * Nx, ncomp) - np.einsum("kd,kd->k", per, p)
        extent = np.sqrt(comp_area) if gdim == 3 else comp_area
        scale = comp_area * extent
    ambiguous = np.abs(m) <= 1e-8 * scale
    if np.any(ambiguous):
        raise ContactInputError(
            f"cannot tell the outward side of {int(ambiguous.sum())} membrane component(s) "
            "(flat, or symmetric about the outward point): give `outward` (a point the normal "
            "points away from) or `direction`"
        )
    return sign * np.where(m > 0.0, 1.0, -1.0)[component]


def cell_orientation(
    mesh: dolfinx.mesh.Mesh,
    outward: Sequence[float] | None = None,
    direction: Sequence[float] | None = None,
) -> dolfinx.fem.Function:
    """The sign (+1 or -1) per cell that orients the vertex-order normal consistently.

    Neighbouring cells agree (across a shared edge of a surface the two cells traverse the
    edge in opposite senses; along a curve a shared vertex ends one cell and starts the
    next), whatever the vertex order of the cells, and each connected component points to
    its outward side: away from ``outward`` (a point), along ``direction`` (a vector), or, by
    default, away from the area centroid of the component (the outward normal of a closed
    surface, of a sphere octant or a tube sector).

    Under MPI, the owned cells' facet keys (global node numbers) and a few integrals per cell
    are gathered to rank 0, which orients the whole surface with scipy's connected
    components (no loop over cells) and scatters the signs back: every rank sees the same
    orientation, independent of the partition. This is a set-up step; the surface topology
    is small next to the solid meshes.

    Parameters
    ----------
    mesh
        A membrane (triangles or quadrilaterals in 3D) or string (intervals in 2D) mesh.
    outward
        A point the normal points away from (each component as a whole).
    direction
        A direction the normal points along (area-weighted), e.g. for a flat membrane.

    Returns
    -------
    A DG0 scalar function with values +1 or -1 on all local cells (ghosts included).

    Raises
    ------
    ContactInputError
        On every rank: not a manifold mesh of codimension 1, an edge shared by more than two
        cells, a non-orientable surface (Moebius strip), or an undecidable outward side.
    """
    check_manifold(mesh)
    comm = mesh.comm
    collective_check(
        comm,
        outward is None or direction is None,
        "give either `outward` (a point) or `direction`, not both",
    )
    for name, value in (("outward", outward), ("direction", direction)):
        collective_check(
            comm,
            value is None or np.shape(value) == (mesh.geometry.dim,),
            f"`{name}` must have {mesh.geometry.dim} components, got {value}",
        )
    collective_check(
        comm,
        direction is None or float(np.linalg.norm(direction)) > 0.0,
        "`direction` must not be the zero vector",
    )
    keys, senses = _facet_keys(mesh)
    integrals = _cell_integrals(mesh)
    parts = comm.gather((keys, senses, integrals), root=0)
    signs, message = None, None
    if comm.rank == 0:
        try:
            sign = _orient(
                _Surface(*(np.concatenate(p) for p in zip(*parts, strict=True))), outward, direction
            )
            signs = np.split(sign, np.cumsum([len(p[1]) for p in parts])[:-1])
        except ContactInputError as error:
            message = str(error)
    message = comm.bcast(message, root=0)
    collective_check(comm, message is None, message or "")
    local = comm.scatter(signs, root=0)
    return _dg0_function(mesh, local)


def _dg0_function(mesh: dolfinx.mesh.Mesh, owned_values: np.ndarray) -> dolfinx.fem.Function:
    """A DG0 scalar function with the given values on the owned cells, ghosts updated."""
    S = dolfinx.fem.functionspace(mesh, ("DG", 0))
    s = dolfinx.fem.Function(S, name="orientation")
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    s.x.array[S.dofmap.list[:owned, 0]] = owned_values
    s.x.scatter_forward()
    return s


def reference_normal(
    mesh: dolfinx.mesh.Mesh,
    outward: Sequence[float] | None = None,
    direction: Sequence[float] | None = None,
    orientation: dolfinx.fem.Function | None = None,
) -> Expr:
    """The consistently oriented unit reference normal ``n0`` of a membrane or string (UFL).

    ``n0 = s N`` with ``N`` the vertex-order normal (:func:`vertex_order_normal`, pointwise,
    exact on curved or non-planar cells) and ``s`` the cell signs of :func:`cell_orientation`
    (made here from ``outward`` / ``direction`` unless ``orientation`` is given).
    """
    if orientation is None:
        orientation = cell_orientation(mesh, outward, direction)
    return orientation * vertex_order_normal(mesh)


# -- kinematics --------------------------------------------------------------------------------


def tangent_projector(n0: Expr) -> Expr:
    """``P = I - n0 n0``: the projector onto the reference tangent plane (line)."""
    return ufl.Identity(n0.ufl_shape[0]) - ufl.outer(n0, n0)


def membrane_cauchy_green(u: Expr, n0: Expr) -> Expr:
    """``C_s = P F^T F P``: the right Cauchy-Green tensor in the reference tangent plane."""
    F, P = deformation_gradient(u), tangent_projector(n0)
    return P * F.T * F * P


def membrane_green_lagrange(u: Expr, n0: Expr) -> Expr:
    """``E_s = (C_s - P) / 2``: the Green-Lagrange strain in the reference tangent plane."""
    return 0.5 * (membrane_cauchy_green(u, n0) - tangent_projector(n0))


def area_vector(u: Expr, n0: Expr) -> Expr:
    """``a = cof(F) n0 = g1 x g2``: current area vector per unit reference area (a string:
    the current normal times the length stretch), on the side of ``n0``."""
    return ufl.dot(ufl.cofac(deformation_gradient(u)), n0)


def area_stretch(u: Expr, n0: Expr) -> Expr:
    """``J_s = |cof(F) n0|``: current over reference area (a string: the length stretch)."""
    a = area_vector(u, n0)
    return ufl.sqrt(ufl.dot(a, a))


def current_normal(u: Expr, n0: Expr) -> Expr:
    """``n = cof(F) n0 / J_s``: the current unit normal, on the side of ``n0``."""
    return area_vector(u, n0) / area_stretch(u, n0)


def in_plane_invariant(u: Expr, n0: Expr) -> Expr:
    """``I1 = tr C_s + (3 - gdim)``: the sum of the squared in-plane stretches (a string adds
    its out-of-plane stretch 1)."""
    return ufl.tr(membrane_cauchy_green(u, n0)) + (3 - n0.ufl_shape[0])


# -- laws ----------------------------------------------------------------------------------------


def _check_positive(**values: float) -> None:
    """A :class:`~contact_ufl.errors.ContactInputError` unless every value is positive and
    finite (every rank makes the same law, so every rank raises)."""
    for name, value in values.items():
        if not 0.0 < value < float("inf"):
            raise ContactInputError(f"{name} must be positive and finite, got {name} = {value}")


@dataclass(frozen=True)
class MembraneNeoHookean:
    """Incompressible Neo-Hookean membrane (string) in plane stress.

    ``W = mu/2 (l1^2 + l2^2 + l3^2 - 3)`` per unit volume with the thickness stretch
    ``l3 = 1 / J_s`` (incompressibility, the thickness stress zero by the pressure
    multiplier): per unit reference area ``t0 mu/2 (I1 + J_s^-2 - 3)``. A string has the
    out-of-plane stretch 1.

    Parameters
    ----------
    mu
        Shear modulus.
    thickness
        Reference thickness ``t0`` (a string: cross-section area per unit depth).
    """

    mu: float
    thickness: float

    def __post_init__(self) -> None:
        _check_positive(mu=self.mu, thickness=self.thickness)

    @property
    def E(self) -> float:
        """Young's modulus of the small-strain limit, ``3 mu``."""
        return 3.0 * self.mu

    def thickness_stretch(self, u: Expr, n0: Expr) -> Expr:
        """``l3 = 1 / J_s``."""
        return 1.0 / area_stretch(u, n0)

    def strain_energy(self, u: Expr, n0: Expr) -> Expr:
        """Stored energy per unit reference area (length, for a string)."""
        J_s = area_stretch(u, n0)
        return 0.5 * self.mu * self.thickness * (in_plane_invariant(u, n0) + J_s**-2 - 3.0)


@dataclass(frozen=True)
class _IsotropicMembrane:
    """A membrane (string) law given by Young's modulus ``E`` and Poisson's ratio ``nu``
    (``-1 < nu < 1/2``) of its small-strain limit and its reference thickness ``t0``."""

    E: float
    nu: float
    thickness: float

    def __post_init__(self) -> None:
        _check_positive(E=self.E, thickness=self.thickness)
        lame_parameters(self.E, self.nu)  # the range of nu


@dataclass(frozen=True)
class MembraneSVK(_IsotropicMembrane):
    """Saint Venant-Kirchhoff membrane (string) in plane stress, the thickness condensed.

    With ``psi = lambda/2 (tr E)^2 + mu E:E`` and the transverse shears zero, ``S33 = lambda
    tr E + 2 mu E33 = 0`` gives ``E33 = -nu/(1 - nu) tr E_s``, and per unit reference area

    ``W = t0 E / (2 (1 - nu^2)) ((1 - nu) E_s:E_s + nu (tr E_s)^2)``

    with ``E_s`` the in-plane Green-Lagrange strain (a string: its out-of-plane strain is 0).
    Valid for small strains with large rotations.

    Parameters
    ----------
    E, nu, thickness
        As in :class:`MembraneCompressibleNeoHookean`.
    """

    def thickness_stretch(self, u: Expr, n0: Expr) -> Expr:
        """``l3 = sqrt(1 + 2 E33)``, ``E33 = -nu/(1 - nu) tr E_s``."""
        E33 = -self.nu / (1.0 - self.nu) * ufl.tr(membrane_green_lagrange(u, n0))
        return ufl.sqrt(1.0 + 2.0 * E33)

    def strain_energy(self, u: Expr, n0: Expr) -> Expr:
        """Stored energy per unit reference area (length, for a string)."""
        Es = membrane_green_lagrange(u, n0)
        modulus = self.thickness * self.E / (2.0 * (1.0 - self.nu**2))
        return modulus * ((1.0 - self.nu) * ufl.inner(Es, Es) + self.nu * ufl.tr(Es) ** 2)


@dataclass(frozen=True)
class MembraneCompressibleNeoHookean(_IsotropicMembrane):
    """Compressible Neo-Hookean membrane (string) in plane stress, the thickness condensed.

    ``psi = mu/2 (I1 - 3 - 2 ln J) + lambda/4 (J^2 - 1 - 2 ln J)`` per unit volume (the
    volumetric term for which plane stress has a closed form; the package's solid
    :class:`~contact_ufl.materials.NeoHookean` uses ``lambda/2 (ln J)^2``, the same to second
    order). With ``I1 = I1_s + l3^2`` and ``J = J_s l3``, ``d psi / d l3 = 0`` gives

    ``l3^2 = (2 mu + lambda) / (2 mu + lambda J_s^2)``,

    and the energy per unit reference area is ``t0 psi`` at that ``l3``.

    Parameters
    ----------
    E, nu
        Young's modulus and Poisson's ratio of the small-strain limit (``-1 < nu < 1/2``).
    thickness
        Reference thickness ``t0`` (a string: cross-section area per unit depth).
    """

    def thickness_stretch(self, u: Expr, n0: Expr) -> Expr:
        """``l3 = sqrt((2 mu + lambda) / (2 mu + lambda J_s^2))``."""
        mu, lmbda = lame_parameters(self.E, self.nu)
        J_s = area_stretch(u, n0)
        return ufl.sqrt((2.0 * mu + lmbda) / (2.0 * mu + lmbda * J_s**2))

    def strain_energy(self, u: Expr, n0: Expr) -> Expr:
        """Stored energy per unit reference area (length, for a string)."""
        mu, lmbda = lame_parameters(self.E, self.nu)
        J_s = area_stretch(u, n0)
        l3_sq = (2.0 * mu + lmbda) / (2.0 * mu + lmbda * J_s**2)
        I1 = in_plane_invariant(u, n0) + l3_sq
        J_sq = J_s**2 * l3_sq
        psi = 0.5 * mu * (I1 - 3.0 - ufl.ln(J_sq)) + 0.25 * lmbda * (J_sq - 1.0 - ufl.ln(J_sq))
        return self.thickness * psi


MembraneLaw = MembraneNeoHookean | MembraneSVK | MembraneCompressibleNeoHookean


# -- follower pressure -------------------------------------------------------------------------


def pressure_virtual_work(u: Expr, v: Expr, n0: Expr, p: Expr | float) -> Expr:
    """Virtual work density ``p a . v`` of a follower pressure, per unit reference area.

    ``a = cof(F) n0`` (:func:`area_vector`): the pressure ``p`` (force per unit current area)
    pushes along the current normal on the side of ``n0`` (with an outward ``n0``, ``p > 0``
    inflates). Integrate over the membrane cells, ``pressure_virtual_work(...) * dx``, and
    subtract it from the internal virtual work; ``ufl.derivative`` gives the load stiffness.
    """
    return p * ufl.dot(area_vector(u, n0), v)
