"""A residual error estimate of a converged contact solve: per-cell indicators and their sum.

The estimate bounds the error in the energy norm ``||e||_E = (int Grad e : C : Grad e)^1/2``
of the linearised elasticity at the reference configuration, by the residuals of the
discrete solution (Verfuerth's residual estimator, with the contact terms of Hild and
Lleras, and of Wohlmuth for mortar multipliers); every term is scaled by the body's Young's
modulus ``E`` to an energy and weighted by :data:`WEIGHTS`:

* ``bulk``: ``h_K^2 / E ||Div P + B||^2_K`` (zero inside a P1 cell),
* ``jump``: ``h_F / E ||[[P N]]||^2_F`` over the facets between cells (half to each),
* ``boundary``: ``h_F / E ||P N - T||^2_F`` on loaded and free facets (``T`` the load's
  nominal traction, 0 on free ones; the free components of a partly supported facet),
* ``traction``: ``h_F / E ||P N - t_c||^2_F`` on the slave facets, ``t_c`` the contact
  traction of the multipliers (property (c) of the formulation),
* ``penetration``: ``E / h_F ||<g>||^2_F``, the overlap of the surfaces (the gap ``g`` of
  the laws is positive where they overlap),
* ``complementarity``: ``int t_N <-g> dS``, contact pressure across an open gap,
* ``cone``: ``h_F / E ||<|t_T| - mu t_N>||^2_F``, friction outside the Coulomb cone.

The master side's contact facets carry no boundary term (the traction there is the slave's,
transported by the projection); their cells' jumps see its stress. Solids only; see the
user guide, *Error estimates*.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import basix
import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contact_ufl import jit
from contact_ufl.loads import BodyForce, DeadForce, DeadTraction, FollowerForce, FollowerPressure

#: the terms of the estimate, in the order reported
TERMS = ("bulk", "jump", "boundary", "traction", "penetration", "complementarity", "cone")

#: the factor on each term's ``eta^2``: one on the bulk's residuals, one on the contact's,
#: calibrated against the true error of the patch test, 2D Hertz and Cattaneo-Mindlin (the
#: benchmark report, *Effectivity of the error estimate*)
WEIGHTS = {
    **dict.fromkeys(("bulk", "jump", "boundary"), 0.25),
    **dict.fromkeys(("traction", "penetration", "complementarity", "cone"), 0.5),
}


@dataclass
class ErrorEstimate:
    """Indicators and the estimate of the error of a converged state.

    Attributes
    ----------
    indicators
        ``eta_K^2`` of each cell, a DG0 function per mesh (all terms; a facet's share to
        the cells beside it).
    parts
        ``sum_K eta_K^2`` of each term (:data:`TERMS`), over all meshes and ranks.
    energy
        The energy norm of the solution, ``(2 W)^1/2`` with ``W`` the stored energy.
    """

    indicators: list[dolfinx.fem.Function]
    parts: dict[str, float] = field(default_factory=dict)
    energy: float = 0.0

    @property
    def estimate(self) -> float:
        """``eta = (sum of all parts)^1/2``, an estimate of the energy norm of the error."""
        return float(np.sqrt(sum(self.parts.values())))

    @property
    def relative(self) -> float:
        """``eta`` over the energy norm of the solution."""
        return self.estimate / self.energy if self.energy > 0 else float("inf")


def stress_field(bulk) -> dolfinx.fem.Function:
    """The first Piola stress of each body in a discontinuous tensor space of the
    displacement's degree minus one, body by body: interpolated (exact for P1 on affine
    cells), or, for an elastoplastic body, whose stress is known at the points of its
    history, projected cell by cell (L2) from those points."""
    mesh = bulk.V.mesh
    gdim = mesh.geometry.dim
    degree = max(bulk.V.ufl_element().degree - 1, 0)
    space = dolfinx.fem.functionspace(mesh, ("DG", degree, (gdim, gdim)))
    P = dolfinx.fem.Function(space, name="first_piola")
    points = space.element.interpolation_points
    for body in bulk.bodies:
        cells = bulk.domain.cell_tags.find(body.tag)
        history = bulk.histories.get(body.tag)
        if history is None:
            P.interpolate(dolfinx.fem.Expression(bulk.first_piola(body), points), cells0=cells)
        else:
            _project_from_points(P, history.first_piola(), history.quadrature_degree, cells)
    P.x.scatter_forward()
    return P


def _project_from_points(
    target: dolfinx.fem.Function, expr: ufl.core.expr.Expr, degree: int, cells: np.ndarray
) -> None:
    """``target`` (discontinuous Lagrange) on ``cells``: the cell-wise L2 projection of
    ``expr`` known at the points of the quadrature rule of ``degree`` (that rule's
    weights times ``|det J|``)."""
    space = target.function_space
    mesh = space.mesh
    cells = np.asarray(cells, dtype=np.int32)
    if len(cells) == 0:
        return
    points, weights = basix.make_quadrature(mesh.basix_cell(), degree)
    scalar = space.ufl_element().sub_elements[0].basix_element  # the space's own
    phi = scalar.tabulate(0, points)[0, :, :, 0]  # (points, dofs)
    values = jit.expression(expr, points).eval(mesh, cells).reshape(len(cells), len(weights), -1)
    detJ = jit.expression(abs(ufl.JacobianDeterminant(mesh)), points).eval(mesh, cells)
    w = weights[None, :] * detJ.reshape(len(cells), len(weights))  # (cells, points)
    mass = np.einsum("cq,qa,qb->cab", w, phi, phi)
    rhs = np.einsum("cq,qa,cqk->cak", w, phi, values)
    coefficients = np.linalg.solve(mass, rhs)  # (cells, dofs, components)
    bs = space.dofmap.index_map_bs
    dofs = space.dofmap.list[cells]
    target.x.array.reshape(-1, bs)[dofs] = coefficients


def _modulus(bulk) -> dolfinx.fem.Function:
    """Young's modulus of each cell's body (DG0)."""
    mesh = bulk.V.mesh
    E = dolfinx.fem.Function(dolfinx.fem.functionspace(mesh, ("DG", 0)))
    for body in bulk.bodies:
        E.x.array[bulk.domain.cell_tags.find(body.tag)] = body.material.E
    E.x.scatter_forward()
    return E


def _load_density(load, bulk, constant) -> ufl.core.expr.Expr:
    """The nominal traction (or body force) of ``load`` at the current state."""
    u = bulk.u
    if isinstance(load, FollowerPressure):
        return load.traction(u, constant)
    if isinstance(load, FollowerForce | DeadForce):
        # its integrand against a unit vector, component by component (the force per area)
        gdim = bulk.V.mesh.geometry.dim
        components = []
        for i in range(gdim):
            e = ufl.as_vector([1.0 if j == i else 0.0 for j in range(gdim)])
            (integral,) = load.virtual_work(u, e, bulk.ds, constant).integrals()
            components.append(integral.integrand())
        return ufl.as_vector(components)
    if isinstance(load, DeadTraction | BodyForce):
        return constant
    raise NotImplementedError(f"no error estimate with a load {type(load).__name__}")


def check_estimable(scene) -> None:
    """Refuse, before any work, the bodies whose residuals the estimate does not cover yet:
    membranes (``NotImplementedError`` naming the mesh and the body)."""
    for k, d in enumerate(scene.parts):
        for body in d.bodies:
            if body.membrane:
                raise NotImplementedError(
                    f"{d.name or f'mesh {k}'} has a membrane (tag {body.tag}): the error "
                    "estimate, and so adaptive refinement, covers solids only"
                )


def error_estimate(problem) -> ErrorEstimate:
    """The indicators and error estimate of the converged state of ``problem`` (collective).

    Raises
    ------
    NotImplementedError
        A membrane (its residuals are not written yet).
    """
    comm = problem.comm
    check_estimable(problem.scene)
    indicators, parts = [], dict.fromkeys(TERMS, 0.0)
    for bulk in problem.bulks:
        contacts = [c for c in problem.contacts if problem.bulk_of(c) is bulk]
        tags = {c.slave.tag for c in contacts}
        tags |= {
            c.master.tag
            for c in problem.contacts
            if not c.pair.on_obstacle and problem.bulk_of(c, "master") is bulk
        }
        P, E = stress_field(bulk), _modulus(bulk)  # once a mesh, for all its terms
        forms = {name: [form] for name, form in _bulk_forms(bulk, P, E, tags).items()}
        for c in contacts:
            for name, form in _contact_forms(bulk, P, E, c).items():
                forms.setdefault(name, []).append(form)
        eta = dolfinx.fem.Function(dolfinx.fem.functionspace(bulk.V.mesh, ("DG", 0)))
        owned = eta.function_space.dofmap.index_map.size_local
        for name, term in forms.items():
            for form in term:
                vector = dolfinx.fem.assemble_vector(form)
                vector.scatter_reverse(dolfinx.la.InsertMode.add)
                values = WEIGHTS[name] * vector.array[:owned]
                eta.x.array[:owned] += values
                parts[name] += comm.allreduce(float(values.sum()), MPI.SUM)
        eta.x.scatter_forward()
        eta.name = "error_indicator"
        indicators.append(eta)
    # an elastoplastic body's elastic part (problem.stored_energy refuses plastic scenes)
    stored = sum(bulk.stored_energy() for bulk in problem.bulks)
    energy = float(np.sqrt(max(2.0 * stored, 0.0)))
    return ErrorEstimate(indicators, parts, energy)


#: the marker of the exterior facets in no group (free)
UNTAGGED = 2**30


def _exterior_facets(bulk) -> ufl.Measure:
    """The exterior facets of the mesh, each marked by its group's tag or :data:`UNTAGGED`."""
    mesh = bulk.V.mesh
    fdim = mesh.topology.dim - 1
    mesh.topology.create_connectivity(fdim, fdim + 1)
    facets = dolfinx.mesh.exterior_facet_indices(mesh.topology)
    tags = bulk.domain.facet_tags
    values = np.full(len(facets), UNTAGGED, dtype=np.int32)
    order = np.argsort(tags.indices)
    at = np.searchsorted(tags.indices, facets, sorter=order).clip(max=max(len(order) - 1, 0))
    found = len(order) > 0 and tags.indices[order[at]] == facets
    values = np.where(found, tags.values[order[at]] if len(order) else values, values)
    marked = dolfinx.mesh.meshtags(mesh, fdim, facets.astype(np.int32), values.astype(np.int32))
    return ufl.Measure("ds", domain=mesh, subdomain_data=marked)


def _bulk_forms(bulk, P, E, contact_tags: set[int]) -> dict[str, dolfinx.fem.Form]:
    """The bulk, jump and boundary terms of one mesh, each a form linear in a DG0 test
    function (its vector: the cells' shares). ``P``, ``E``: the stress and modulus fields
    (:func:`stress_field`, :func:`_modulus`); ``contact_tags``: the facet groups of the
    contact surfaces on this mesh (no boundary term)."""
    mesh = bulk.V.mesh
    comm = mesh.comm
    gdim = mesh.geometry.dim
    w = ufl.TestFunction(dolfinx.fem.functionspace(mesh, ("DG", 0)))
    h = ufl.CellDiameter(mesh)
    N = ufl.FacetNormal(mesh)
    dx, ds = bulk.dx, _exterior_facets(bulk)
    bulk_term = 0
    body_forces = [(load, c) for load, c in bulk.load_constants if isinstance(load, BodyForce)]
    for body in bulk.bodies:
        r = ufl.div(P)
        for load, constant in body_forces:
            if load.tag in (body.tag, None):
                r = r + _load_density(load, bulk, constant)
        bulk_term += h**2 / E * ufl.dot(r, r) * w * dx(body.tag)
    forms = {"bulk": bulk_term}
    jump = ufl.jump(P, N)
    forms["jump"] = ufl.avg(h) / ufl.avg(E) * ufl.dot(jump, jump) * ufl.avg(w) * ufl.dS
    # the exterior facets: loaded, supported (their free components), contact (none), free
    traction = ufl.dot(P, N)
    boundary, done = 0, set(contact_tags)
    for load, constant in bulk.load_constants:
        if not isinstance(load, BodyForce):
            r = traction - _load_density(load, bulk, constant)
            boundary += h / E * ufl.dot(r, r) * w * ds(load.tag)
            done.add(load.tag)
    supported: dict[int, set[int]] = {}
    for d in bulk.domain.dirichlet:
        axes = range(gdim) if d.component is None else [d.component]
        supported.setdefault(d.tag, set()).update(axes)
    for tag, axes in supported.items():
        free = [i for i in range(gdim) if i not in axes]
        if free and tag not in done:
            boundary += h / E * sum(traction[i] ** 2 for i in free) * w * ds(tag)
        done.add(tag)
    groups = set(comm.allreduce(set(bulk.domain.facet_tags.values.tolist()), MPI.BOR))
    free_tags = tuple(sorted((groups | {UNTAGGED}) - done))
    boundary += h / E * ufl.dot(traction, traction) * w * ds(free_tags)
    forms["boundary"] = boundary
    return {name: jit.form(form) for name, form in forms.items() if _linear(form)}


def _contact_forms(bulk, P, E, c) -> dict[str, dolfinx.fem.Form]:
    """The contact terms of the slave surface of pair ``c`` (on its slave's mesh, of stress
    and modulus fields ``P``, ``E``)."""
    mesh = bulk.V.mesh
    w = ufl.TestFunction(dolfinx.fem.functionspace(mesh, ("DG", 0)))
    h = ufl.CellDiameter(mesh)
    N = ufl.FacetNormal(mesh)
    ds = c.ds
    r = ufl.dot(P, N) - c.traction()
    # the laws' gap is positive where the surfaces overlap (t_N = <lambda_N + eps_N g>)
    overlap = ufl.max_value(c.gap, 0.0)
    open_gap = ufl.max_value(-c.gap, 0.0)
    mask = c.kinematics.mask
    forms = {
        "traction": h / E * ufl.dot(r, r) * w * ds,
        "penetration": E / h * mask * overlap**2 * w * ds,
        "complementarity": mask * c.t_N * open_gap * w * ds,
    }
    if c.friction:
        t_T = -c.friction.traction()
        excess = ufl.max_value(ufl.sqrt(ufl.dot(t_T, t_T)) - c.friction.mu * c.t_N, 0.0)
        forms["cone"] = h / E * excess**2 * w * ds
    maps = [c.slave.entity_map]
    return {name: jit.form(form, entity_maps=maps) for name, form in forms.items() if _linear(form)}


def _linear(form) -> bool:
    """Whether ``form`` is a linear form (not one UFL simplified to zero: ``Div P`` of a
    cellwise constant stress)."""
    return isinstance(form, ufl.Form) and len(form.arguments()) == 1 and not form.empty()
