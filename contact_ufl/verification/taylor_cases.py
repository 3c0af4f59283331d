"""Generic contact states on curved surfaces, for the Taylor test of the tangent.

:func:`curved_case` puts the curved pair of :func:`~contact_ufl.verification.scenes.curved_pair`
in a state of contact (both bodies deformed, one pushed into the other, smooth multipliers)
and gives a direction that slides it: the remainders of
:func:`contact_ufl.taylor.taylor_test` along it must fall as ``h^2``.
"""

from __future__ import annotations

import dataclasses

import dolfinx.fem
import dolfinx.fem.petsc
import numpy as np
from petsc4py import PETSc

from contact_ufl.problem import ContactProblem
from contact_ufl.verification.scenes import curved_pair

__all__ = ["CURVED_STATES", "contact_state", "curved_case", "sliding_direction", "smooth_field"]


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
    gdim = problem.V.mesh.geometry.dim
    cells = problem.scene.cell_tags.find(body_tag)
    u = problem.u
    u.interpolate(lambda x: smooth_field(x, amplitude, gdim))
    u.interpolate(
        lambda x: smooth_field(x, amplitude, gdim) + np.asarray(shift)[:, None], cells0=cells
    )
    for c in problem.contacts:
        c.lambda_N.interpolate(lambda x: multiplier * (1.0 + 0.2 * np.sin(5.0 * x[0])))
        if c.friction:
            c.friction.lambda_T.interpolate(
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
        dl = dolfinx.fem.Function(c.normal.L)
        dl.interpolate(lambda x: multiplier * np.cos(4.0 * x[0] + 0.3))
        fields.append(dl)
    dz = problem.solver.x.duplicate()
    dolfinx.fem.petsc.assign(fields, dz)
    return dz


#: Generic contact states of :func:`~contact_ufl.verification.scenes.curved_pair`: the translation
#: of the upper body into the lower, the sliding of the test direction, the largest step h.
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
