"""Taylor test of the tangent: does the Jacobian differentiate the residual?

For a state z and a direction dz, the remainder ``|R(z + h dz) - R(z) - h J(z) dz|`` of a
consistent tangent falls as ``h^2``; a tangent that misses a term leaves an ``O(h)`` part.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


@dataclass
class TaylorResult:
    """Steps, remainders of order zero (|R(z+h dz) - R(z)|) and one, and the slopes.

    ``active_changed`` also covers stick/slip changes of frictional pairs."""

    h: np.ndarray
    zeroth: np.ndarray
    first: np.ndarray
    facets_changed: bool
    active_changed: bool

    @property
    def slopes(self) -> np.ndarray:
        """Observed orders of the first-order remainder between successive steps."""
        return np.diff(np.log(self.first)) / np.diff(np.log(self.h))


def _signature(problem) -> tuple[list, list]:
    facets = [c.projection.facet.copy() for c in problem.contacts]
    status = [
        c.active().astype(int) + (c.stick() if hasattr(c, "stick") else 0) for c in problem.contacts
    ]
    return facets, status


def _same(a: list, b: list, comm: MPI.Comm) -> bool:
    same = all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    return bool(comm.allreduce(same, MPI.LAND))


def taylor_test(problem, direction: PETSc.Vec, steps: Sequence[float]) -> TaylorResult:
    """Remainders of the residual of ``problem`` at its current state along ``direction``.

    The state is restored afterwards. ``facets_changed``/``active_changed`` report whether
    any slave point changed master facet or contact status over the steps (the remainder
    then has a kink and no order can be expected).
    """
    comm, solver = problem.comm, problem.solver
    z = solver.x.copy()
    solver.forget_state()
    R0 = solver.evaluate_residual(z)
    facets0, active0 = _signature(problem)
    Jdz = R0.duplicate()
    solver.evaluate_jacobian(z).mult(direction, Jdz)
    zeroth, first = [], []
    facets_changed = active_changed = False
    for h in steps:
        zh = z.copy()
        zh.axpy(h, direction)
        Rh = solver.evaluate_residual(zh)
        facets, active = _signature(problem)
        facets_changed |= not _same(facets, facets0, comm)
        active_changed |= not _same(active, active0, comm)
        Rh.axpy(-1.0, R0)
        zeroth.append(Rh.norm())
        Rh.axpy(-h, Jdz)
        first.append(Rh.norm())
    solver.evaluate_residual(z)
    return TaylorResult(
        np.asarray(steps, float), np.array(zeroth), np.array(first), facets_changed, active_changed
    )


def smooth_field(x: np.ndarray, amplitude: float, gdim: int, phase: float = 0.0) -> np.ndarray:
    """A smooth vector field (values ``(gdim, n)``), the same on any number of ranks."""
    return np.vstack(
        [
            amplitude
            * np.sin(2.0 * x[0] + 1.0 + k + phase)
            * np.cos(3.0 * x[1] + k - phase)
            * (1.0 + 0.5 * x[gdim - 1])
            for k in range(gdim)
        ]
    )


def contact_state(
    problem,
    body_tag: int,
    shift: np.ndarray,
    amplitude: float = 0.01,
    multiplier: float = 0.05,
    tangential: float = 0.0,
) -> None:
    """Put ``problem`` in a generic state of contact: every body deformed by a smooth field,
    the body ``body_tag`` also translated by ``shift`` (into the other), smooth positive
    multipliers. Sets the unknowns (not a solution: a point to test the tangent at)."""
    import dolfinx.fem.petsc

    gdim = problem.V.mesh.geometry.dim
    cells = problem.scene.cell_tags.find(body_tag)
    u = problem.u
    u.interpolate(lambda x: smooth_field(x, amplitude, gdim))
    u.interpolate(
        lambda x: smooth_field(x, amplitude, gdim) + np.asarray(shift)[:, None], cells0=cells
    )
    for c in problem.contacts:
        c.lambda_N.interpolate(lambda x: multiplier * (1.0 + 0.2 * np.sin(5.0 * x[0])))
        if hasattr(c, "lambda_T"):
            c.lambda_T.interpolate(
                lambda x: tangential * np.vstack([np.sin(3.0 * x[0] + k) for k in range(gdim)])
            )
    solver = problem.solver
    dolfinx.fem.petsc.assign(problem.unknowns, solver.x)
    solver.forget_state()
    solver.evaluate_residual(solver.x)


def sliding_direction(
    problem, body_tag: int, slide: np.ndarray, amplitude: float = 0.02, multiplier: float = 0.01
) -> PETSc.Vec:
    """A direction dz that slides body ``body_tag`` by ``slide`` over the other, deforms both
    bodies (rotating the master normals) and changes the multipliers; rank independent."""
    import dolfinx.fem.petsc

    gdim = problem.V.mesh.geometry.dim
    cells = problem.scene.cell_tags.find(body_tag)
    fields = []
    du = dolfinx.fem.Function(problem.V)
    du.interpolate(lambda x: smooth_field(x, amplitude, gdim, phase=0.7))
    du.interpolate(
        lambda x: smooth_field(x, amplitude, gdim, phase=0.7) + np.asarray(slide)[:, None],
        cells0=cells,
    )
    fields.append(du)
    for c in problem.contacts:
        dl = dolfinx.fem.Function(c.L)
        dl.interpolate(lambda x: multiplier * np.cos(4.0 * x[0] + 0.3))
        fields.append(dl)
    dz = problem.solver.x.duplicate()
    dolfinx.fem.petsc.assign(fields, dz)
    return dz


#: Generic contact states of :func:`contact_ufl.scenes.curved_pair`: the translation of the
#: upper body into the lower, the sliding of the test direction, the largest step h.
CURVED_STATES = {
    2: dict(shift=(0.03, -0.04), slide=(0.05, 0.0), h0=1e-3),
    3: dict(shift=(0.03, 0.02, -0.04), slide=(0.05, 0.03, 0.0), h0=1e-4),
}


def curved_case(dim: int, num_steps: int = 4, mu: float = 0.0, master_normal: str = "facet"):
    """The Taylor test case on curved surfaces: problem at its state, direction, steps.

    With ``mu > 0`` the state has a slip history: the step is committed half-way along the
    translation, and the tangential multipliers are smooth and non-zero (a small ``mu``
    puts the contact points in slip, a large one in stick). Over the steps no slave point
    changes master facet, contact status or stick/slip status. ``master_normal`` is that
    of :class:`~contact_ufl.contact.ContactPair`.
    """
    import dataclasses

    from contact_ufl.problem import ContactProblem
    from contact_ufl.scenes import curved_pair

    scene = curved_pair(dim)
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], mu=mu, master_normal=master_normal)
    problem = ContactProblem(scene, verbose=False)
    solver = problem.solver  # made at the reference state, the converged state of step 0
    state = CURVED_STATES[dim]
    tag = scene.bodies[0].tag
    shift = np.array(state["shift"])
    if mu > 0:
        contact_state(problem, tag, 0.5 * shift)
        problem.contacts[0].commit(solver.x)
        problem.contacts[0].begin_step()
    contact_state(problem, tag, shift, tangential=0.01 if mu > 0 else 0.0)
    direction = sliding_direction(problem, tag, np.array(state["slide"]))
    return problem, direction, [state["h0"] * 2.0**-k for k in range(num_steps)]
