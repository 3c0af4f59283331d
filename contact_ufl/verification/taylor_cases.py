"""Generic contact states on curved surfaces, for the Taylor test of the tangent.

:func:`curved_case` puts the curved pair of :func:`~contact_ufl.verification.scenes.curved_pair`
in a state of contact (both bodies deformed, one pushed into the other, smooth multipliers)
and gives a direction that slides it: the remainders of
:func:`contact_ufl.taylor.taylor_test` along it must fall as ``h^2``.
"""

from __future__ import annotations

import dataclasses
import warnings

import dolfinx.fem
import dolfinx.fem.petsc
import numpy as np
from petsc4py import PETSc

from contact_ufl.contact.obstacles import RigidCylinder, RigidObstacle, RigidSphere
from contact_ufl.errors import NonUniqueSolutionWarning
from contact_ufl.membranes import MembraneNeoHookean
from contact_ufl.problem import ContactProblem
from contact_ufl.verification.scenes.membranes import with_membrane
from contact_ufl.verification.scenes.pairs import curved_pair, on_meshes_of_their_own

__all__ = [
    "CURVED_STATES",
    "contact_state",
    "curved_case",
    "obstacle_case",
    "sliding_direction",
    "smooth_field",
]


def taylor_problem(scene, degree: int = 1) -> ContactProblem:
    """The problem of a Taylor case: its states are set by hand, never solved, so a body
    held by nothing (the scenes have no supports) is no concern here."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NonUniqueSolutionWarning)
        return ContactProblem(scene, degree=degree, verbose=False)


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
    gdim = problem.gdim
    for bulk in problem.bulks:
        _deform(bulk, body_tag, amplitude, shift, gdim, bulk.u)
    for c in problem.contacts:
        c.lambda_N.interpolate(lambda x: multiplier * (1.0 + 0.2 * np.sin(5.0 * x[0])))
        if c.friction:
            c.friction.lambda_T.interpolate(
                lambda x: tangential * np.vstack([np.sin(3.0 * x[0] + k) for k in range(gdim)])
            )
    operator = problem.operator
    dolfinx.fem.petsc.assign(problem.unknowns, operator.x)
    operator.forget_state()
    operator.evaluate_residual(operator.x)


def sliding_direction(
    problem, body_tag: int, slide: np.ndarray, amplitude: float = 0.02, multiplier: float = 0.01
) -> PETSc.Vec:
    """A direction dz that slides body ``body_tag`` by ``slide`` over the other, deforms both
    bodies (rotating the master normals) and changes the multipliers; rank independent."""
    fields = []
    for bulk in problem.bulks:
        du = dolfinx.fem.Function(bulk.V)
        _deform(bulk, body_tag, amplitude, slide, problem.gdim, du, phase=0.7)
        fields.append(du)
    for c in problem.contacts:
        dl = dolfinx.fem.Function(c.normal.L)
        dl.interpolate(lambda x: multiplier * np.cos(4.0 * x[0] + 0.3))
        fields.append(dl)
    dz = problem.operator.x.duplicate()
    dolfinx.fem.petsc.assign(fields, dz)
    return dz


def _deform(bulk, body_tag: int, amplitude: float, shift, gdim: int, u, phase: float = 0.0):
    """``u`` = the smooth field over the mesh of ``bulk``, plus ``shift`` on the cells of
    the body ``body_tag`` if that body is on this mesh."""
    u.interpolate(lambda x: smooth_field(x, amplitude, gdim, phase))
    if any(b.tag == body_tag for b in bulk.bodies):
        cells = bulk.domain.cell_tags.find(body_tag)
        u.interpolate(
            lambda x: smooth_field(x, amplitude, gdim, phase) + np.asarray(shift)[:, None],
            cells0=cells,
        )


#: Generic contact states of :func:`~contact_ufl.verification.scenes.curved_pair`: the translation
#: of the upper body into the lower, the sliding of the test direction, the largest step h.
CURVED_STATES = {
    2: dict(shift=(0.03, -0.04), slide=(0.05, 0.0), h0=1e-3),
    3: dict(shift=(0.03, 0.02, -0.04), slide=(0.05, 0.03, 0.0), h0=1e-4),
}


def curved_case(
    dim: int,
    num_steps: int = 4,
    mu: float = 0.0,
    master_normal: str = "facet",
    own_meshes: bool = False,
    membrane: str | None = None,
    direction: float = 1.0,
    cell: str = "tetrahedron",
    degree: int = 1,
    order: int = 1,
    multiplier_degree: int | str = 1,
):
    """The Taylor test case on curved surfaces: problem at its state, direction, steps.

    With ``mu > 0`` the state has a slip history: the step is committed half-way along the
    translation, and the tangential multipliers are smooth and non-zero (a small ``mu``
    puts the contact points in slip, a large one in stick). Over the steps no slave point
    changes master facet, contact status or stick/slip status. ``master_normal`` is that
    of :class:`~contact_ufl.contact.ContactPair`. With ``own_meshes`` each body is on a
    mesh of its own (:func:`~contact_ufl.verification.scenes.on_meshes_of_their_own`). With
    ``membrane="master"`` (``"slave"``) the lower (upper) body is replaced by a Neo-Hookean
    membrane made of its contact surface (:func:`~contact_ufl.verification.scenes.with_membrane`),
    its normal up (``direction = 1``) or down (``-1``); ``cell`` (3D) that of
    :func:`~contact_ufl.verification.scenes.curved_pair`. ``degree``: that of the
    displacement; ``order``: that of the geometry (2: curved cells); ``multiplier_degree``:
    that of the pair (``"iso"``: P1-iso-P2).
    """
    scene = curved_pair(dim, cell=cell, order=order)
    scene.contacts[0] = dataclasses.replace(
        scene.contacts[0],
        mu=mu,
        master_normal=master_normal,
        multiplier_degree=multiplier_degree,
    )
    if own_meshes:
        scene = on_meshes_of_their_own(scene)
    if membrane:
        up = direction * np.eye(dim)[dim - 1]
        scene = with_membrane(scene, membrane, MembraneNeoHookean(1.0, 0.05), up)
    problem = taylor_problem(scene, degree=degree)
    operator = problem.operator  # made at the reference state, the converged state of step 0
    state = CURVED_STATES[dim]
    tag = problem.bulks[0].bodies[0].tag
    shift = np.array(state["shift"])
    if mu > 0:
        contact_state(problem, tag, 0.5 * shift)
        problem.contacts[0].commit(operator.x)
        problem.contacts[0].begin_step()
    contact_state(problem, tag, shift, tangential=0.01 if mu > 0 else 0.0)
    direction = sliding_direction(problem, tag, np.array(state["slide"]))
    return problem, direction, [state["h0"] * 2.0**-k for k in range(num_steps)]


def rotation(angles: np.ndarray) -> np.ndarray:
    """The rotation matrix ``exp(W)`` of the rotation vector ``angles`` (3D; in 2D the
    angle ``angles[0]`` about the normal of the plane)."""
    if len(angles) == 1:
        c, s = np.cos(angles[0]), np.sin(angles[0])
        return np.array([[c, -s], [s, c]])
    theta = np.linalg.norm(angles)
    if theta == 0.0:
        return np.eye(3)
    k = np.asarray(angles) / theta
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(theta) * K + (1.0 - np.cos(theta)) * K @ K


def moving_obstacle(dim: int, shape: str = "cylinder") -> RigidObstacle:
    """The rigid obstacle of :func:`obstacle_case`: the lower body's top of
    :func:`~contact_ufl.verification.scenes.curved_pair` made rigid (2D: the circle of
    radius 3 touching the disc at the origin; 3D: the cylinder of radius 3 with axis along
    x, or with ``shape="sphere"`` the ball of radius 3 touching the half cylinder at the
    origin), translated by ``(0.02, -0.01) t`` (3D ``(0.02, 0.01, -0.008) t``) and rotated
    about its centre (axis) by ``0.3 t`` (3D the rotation vector ``(0.1, 0, 0.2) t``)."""
    if dim == 2:

        def motion(t: float):
            return np.array([0.02, -0.01]) * t, rotation(np.array([0.3 * t]))

        return RigidSphere((0.0, -3.0), 3.0, motion=motion)

    def motion3(t: float):
        return np.array([0.02, 0.01, -0.008]) * t, rotation(np.array([0.1, 0.0, 0.2]) * t)

    if shape == "sphere":
        return RigidSphere((0.0, 0.0, -3.0), 3.0, motion=motion3)
    return RigidCylinder((0.0, 0.0, -3.0), (1.0, 0.0, 0.0), 3.0, motion=motion3)


def obstacle_case(dim: int, num_steps: int = 4, mu: float = 0.0, shape: str = "cylinder"):
    """The Taylor test case of a slave on a moved and rotated rigid obstacle
    (:func:`moving_obstacle`): the upper body of
    :func:`~contact_ufl.verification.scenes.curved_pair` pressed onto it and slid over it.

    The state is at pseudo-time 1; with ``mu > 0`` the slip history was committed at
    pseudo-time 0.5 half-way along the translation, so the slip reference has moved with
    the obstacle since (a small ``mu`` puts the contact points in slip). ``shape``: that of
    the 3D obstacle (:func:`moving_obstacle`). Returns the problem at its state, the
    direction and the steps, as :func:`curved_case`.
    """
    scene = curved_pair(dim)
    obstacle = moving_obstacle(dim, shape)
    # every slave point within the search radius: no point changes pairing over the steps
    scene.contacts[0] = dataclasses.replace(
        scene.contacts[0], master=obstacle, mu=mu, search_radius=2.0
    )
    problem = taylor_problem(scene)
    operator = problem.operator
    state = CURVED_STATES[dim]
    tag = scene.bodies[0].tag
    shift = np.array(state["shift"])
    if mu > 0:
        problem.set_time(0.5)
        contact_state(problem, tag, 0.5 * shift)
        problem.contacts[0].commit(operator.x)
        problem.contacts[0].begin_step()
    problem.set_time(1.0)
    contact_state(problem, tag, shift, tangential=0.01 if mu > 0 else 0.0)
    direction = sliding_direction(problem, tag, np.array(state["slide"]))
    return problem, direction, [state["h0"] * 2.0**-k for k in range(num_steps)]


def membrane_pressure_case(dim: int, num_steps: int = 4):
    """The Taylor test case of a membrane under a follower pressure (no contact): the sphere
    octant of :func:`~contact_ufl.verification.scenes.inflated_sphere` (3D) or the quarter
    string ring of :func:`~contact_ufl.verification.scenes.tube_for_plates` (2D), deformed by
    a smooth field, at its full pressure; the direction another smooth field. Returns the
    problem at its state, the direction and the steps, as :func:`curved_case`."""
    from contact_ufl.scene import Scene
    from contact_ufl.verification.scenes.membranes import (
        PlatesSchedule,
        inflated_sphere,
        tube_for_plates,
    )

    if dim == 3:
        scene = inflated_sphere(n=8, pressure=0.01)
    else:
        schedule = PlatesSchedule(0.005, 2.0, 1.5)
        scene = Scene(domains=[tube_for_plates(schedule, dim=2, n=16)])
    problem = taylor_problem(scene)
    operator = problem.operator
    problem.set_time(1.0)
    (bulk,) = problem.bulks
    bulk.u.interpolate(lambda x: smooth_field(x, 0.05, dim))
    du = dolfinx.fem.Function(bulk.V)
    du.interpolate(lambda x: smooth_field(x, 0.05, dim, phase=0.7))
    dolfinx.fem.petsc.assign(problem.unknowns, operator.x)
    operator.forget_state()
    direction = operator.x.duplicate()
    dolfinx.fem.petsc.assign([du], direction)
    return problem, direction, [1e-2 * 2.0**-k for k in range(num_steps)]
