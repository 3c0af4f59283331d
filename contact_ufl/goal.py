"""A goal-oriented estimate: the error in the normal contact force, by dual-weighted residuals.

The energy estimate (:mod:`contact_ufl.estimate`) bounds the error over the whole scene; a
user reading a contact force wants the error in that number. For a goal ``J`` (here the
normal force of the multipliers, ``J = int lambda_N dS_o``) the dual-weighted residual
(DWR) of Becker and Rannacher gives it to first order:

    J(u) - J(u_h) ~ -R(u_h)(z),     A^T z = J'

with ``R`` the residual and ``A`` its tangent in a richer space (the displacement of one
degree more on the same meshes, the multipliers and the contact rules unchanged) at the
converged state ``u_h`` moved into it, and ``z`` the dual solution there. The tangent is that
of the converged contact state (the active set fixed), as in Blum and Suttmeier's DWR
estimate for the Signorini problem. The estimate is signed: ``J(u_h) + error`` is, to first
order, the force the richer space would give. Its measured effectivity is in the user
guide, *Error estimates*.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import dolfinx
import dolfinx.fem.petsc as fem_petsc
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl import jit
from contact_ufl.errors import collective_check
from contact_ufl.estimate import check_estimable
from contact_ufl.refinement import interpolate_unknowns


@dataclass
class GoalEstimate:
    """The estimated error in a goal quantity of a converged state.

    Attributes
    ----------
    value
        The goal at the converged state, ``J(u_h)``.
    error
        The estimated error ``J(u) - J(u_h)`` (signed).
    indicators
        The share of each cell in the error, ``|eta_K|`` (a DG0 function per mesh), for
        marking.
    consistency
        The part of ``error`` that is the residual of the richer space tested by the
        degree-1 interpolant of the dual solution: zero where the two discretisations agree
        on degree-1 test functions (with the smoothed master normal of 2D, which the richer
        space replaces by the facet normal, it is the change of normal).
    """

    value: float
    error: float
    indicators: list[dolfinx.fem.Function]
    consistency: float = 0.0

    @property
    def relative(self) -> float:
        """``|error| / |value|``."""
        return abs(self.error) / abs(self.value) if self.value else float("inf")


def normal_force(problem, pair: int | None = None) -> float:
    """``int lambda_N dS_o`` over the slave surface of ``pair`` (all pairs: ``None``), the
    normal contact force the multipliers carry (collective)."""
    contacts = problem.contacts if pair is None else [problem.contacts[pair]]
    local = 0.0
    for c in contacts:
        form = jit.form(c.normal.lambda_N * c.slave.ds, entity_maps=[c.slave.entity_map])
        local += dolfinx.fem.assemble_scalar(form)
    return float(problem.comm.allreduce(local, MPI.SUM))


def check_goal_estimable(problem) -> None:
    """Refuse, on every rank before any work, what the force estimate does not cover:
    membranes, a displacement of degree 2 (its richer space, degree 3, has no contact
    facets), friction and plasticity (their state depends on the load path, which the richer
    space has not seen)."""
    check_estimable(problem.scene)
    comm = problem.comm
    degrees = {b.V.ufl_element().embedded_superdegree for b in problem.bulks}
    collective_check(
        comm,
        degrees == {1},
        f"the contact force's error estimate needs a degree-1 displacement (its richer space "
        f"is of degree 2), got degree {max(degrees)}",
        NotImplementedError,
    )
    frictional = [c.pair.surface("slave") for c in problem.contacts if c.friction]
    collective_check(
        comm,
        not frictional,
        f"the contact force's error estimate covers frictionless contact; the pair(s) of slave "
        f"surface {', '.join(map(str, frictional))} have friction, whose state depends on "
        "the load path",
        NotImplementedError,
    )
    plastic = sorted(tag for b in problem.bulks for tag in b.histories)
    collective_check(
        comm,
        not plastic,
        "the contact force's error estimate covers hyperelastic bodies; the bodies of cell "
        f"tags {plastic} are elastoplastic, whose state depends on the load path",
        NotImplementedError,
    )


def enriched_problem(problem):
    """A problem on the same scene and meshes with a displacement of degree 2 and the
    contact rules of ``problem`` (quadrature, ``eps_N``; the facet master normal, the only
    one of degree 2), its state moved from ``problem``'s (exactly: degree 1 lies in degree
    2) and its pseudo-time set to ``problem``'s (collective)."""
    pairs = [
        dataclasses.replace(
            c.pair,
            quadrature_degree=c.slave.quadrature_degree,
            eps_N=float(c.normal.eps_N.value),
            master_normal="facet",
        )
        for c in problem.contacts
    ]
    scene = dataclasses.replace(problem.scene, contacts=pairs)
    rich = type(problem)(scene, degree=2, verbose=False, petsc_options=problem.petsc_options)
    for old, new in zip(problem.bulks, rich.bulks, strict=True):
        new.u.interpolate(old.u)
    displacements = {id(b.u) for b in problem.bulks}
    # the multipliers: the same slave submesh, made anew
    interpolate_unknowns(problem.unknowns, rich.unknowns, displacements, 1e-6 * problem.scales()[0])
    rich.set_time(problem.t)
    return rich


def normal_force_error(problem, pair: int | None = None) -> GoalEstimate:
    """The estimated error in :func:`normal_force` of the converged state of ``problem``
    (collective): the dual-weighted residual in the displacement of degree 2 (see the
    module's docstring).

    Raises
    ------
    NotImplementedError
        What :func:`check_goal_estimable` refuses.
    """
    check_goal_estimable(problem)
    rich = enriched_problem(problem)
    try:
        operator = rich.operator
        operator.read_unknowns()
        x = operator.x
        rows = operator.system.dirichlet.rows
        residual = operator.evaluate_residual(x)
        residual.array[rows] = 0.0  # the prescribed values' interpolation is not the goal's
        tangent = operator.evaluate_jacobian(x)
        goal = operator.assemble(_force_derivative(rich, pair))
        goal.array[rows] = 0.0
        dual = goal.duplicate()
        ksp = PETSc.KSP().create(rich.comm)
        try:
            ksp.setOperators(tangent)
            ksp.setType("preonly")
            ksp.getPC().setType("lu")
            ksp.getPC().setFactorSolverType("mumps")
            ksp.solveTranspose(goal, dual)
        finally:
            ksp.destroy()
        error = -dual.dot(residual)
        indicators, consistency = _localise(problem, rich, residual, dual)
        for v in (residual, goal, dual):
            v.destroy()
    finally:
        rich.close()
    return GoalEstimate(normal_force(problem, pair), float(error), indicators, consistency)


def _force_derivative(problem, pair: int | None) -> list[list]:
    """The derivative of :func:`normal_force` as a blocked form over ``problem``'s fields:
    ``int lambda_N* dS_o`` in the multiplier block of each pair counted."""
    blocks: list[list] = [[] for _ in problem.fields]
    fields = [id(f) for f in problem.fields]
    contacts = problem.contacts if pair is None else [problem.contacts[pair]]
    for c in contacts:
        lam = c.normal.lambda_N
        test = ufl.TestFunction(lam.function_space)
        form = jit.form(test * c.slave.ds, entity_maps=[c.slave.entity_map])
        blocks[fields.index(id(lam))].append(form)
    return blocks


def _localise(problem, rich, residual: PETSc.Vec, dual: PETSc.Vec):
    """Cell indicators ``|eta_K|`` of the error ``-R(z - I z)``, ``I z`` the degree-1
    interpolant of the dual displacement (whose residual is the consistency part), each dof's
    product shared equally among its cells; and the consistency part ``-R(I z)``."""
    functions = {}
    for name, vector in (("R", residual), ("z", dual)):
        functions[name] = [dolfinx.fem.Function(f.function_space) for f in rich.unknowns]
        fem_petsc.assign(vector, functions[name])
        for f in functions[name]:
            f.x.scatter_forward()
    position = {id(f): k for k, f in enumerate(rich.unknowns)}
    indicators, consistency = [], 0.0
    for coarse, bulk in zip(problem.bulks, rich.bulks, strict=True):
        k = position[id(bulk.u)]
        R, z = functions["R"][k], functions["z"][k]
        V = bulk.V
        degree_one = dolfinx.fem.Function(coarse.V)
        degree_one.interpolate(z)
        interpolant = dolfinx.fem.Function(V)
        interpolant.interpolate(degree_one)
        index_map, bs = V.dofmap.index_map, V.dofmap.index_map_bs
        owned = index_map.size_local * bs
        consistency -= float(np.dot(R.x.array[:owned], interpolant.x.array[:owned]))
        share = dolfinx.fem.Function(V)
        above = z.x.array[:owned] - interpolant.x.array[:owned]  # the dual beyond degree 1
        share.x.array[:owned] = -R.x.array[:owned] * above
        share.x.scatter_forward()
        indicators.append(_cell_shares(share, coarse.V.mesh))
    return indicators, float(problem.comm.allreduce(consistency, MPI.SUM))


def _cell_shares(share: dolfinx.fem.Function, mesh: dolfinx.mesh.Mesh) -> dolfinx.fem.Function:
    """``|sum over a cell's dofs of share_i / (cells of dof i)|`` as a DG0 function."""
    V = share.function_space
    tdim = mesh.topology.dim
    cells = mesh.topology.index_map(tdim).size_local
    dofs = V.dofmap.list[:cells]
    bs = V.dofmap.index_map_bs
    count = dolfinx.la.vector(V.dofmap.index_map, 1)
    np.add.at(count.array, dofs.ravel(), 1.0)
    count.scatter_reverse(dolfinx.la.InsertMode.add)
    count.scatter_forward()
    per_node = share.x.array.reshape(-1, bs).sum(axis=1) / np.maximum(count.array, 1.0)
    eta = dolfinx.fem.Function(dolfinx.fem.functionspace(mesh, ("DG", 0)), name="force_error")
    eta.x.array[eta.function_space.dofmap.list[:cells, 0]] = np.abs(per_node[dofs].sum(axis=1))
    eta.x.scatter_forward()
    return eta
