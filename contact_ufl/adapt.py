"""Adaptive refinement of a scene's meshes to a target accuracy.

One level of the loop: solve, estimate (:mod:`contact_ufl.estimate`, or the error of the
normal contact force, :mod:`contact_ufl.goal`), mark the cells that carry a fraction
``theta`` of the estimate (Doerfler), refine every mesh of the scene there
(:mod:`contact_ufl.refinement`), and solve on the new meshes. A scene without history (no
friction, no plasticity) starts each new mesh from the last solution moved onto it and
brings it to equilibrium at the same load; a scene with history replays its load path on
each mesh. See the user guide, *Adaptive refinement*.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.errors import ContactInputError, ConvergenceError, collective_check
from contact_ufl.estimate import check_estimable
from contact_ufl.goal import check_goal_estimable
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.problem import ContactProblem
from contact_ufl.refinement import (
    Boundary,
    check_boundaries,
    check_refinable,
    interpolate_by_body,
    interpolate_unknowns,
    refine_scene,
    slave_finer_than_master,
)
from contact_ufl.scene import Scene


@dataclass
class Level:
    """One mesh of the adaptive loop and what its solve gave.

    Attributes
    ----------
    unknowns
        Number of unknowns of the problem (all meshes, multipliers).
    cells
        Number of cells of each mesh.
    estimate, relative
        The error estimate and its ratio to the solution's energy norm (with the goal
        ``"normal_force"``: the force's estimated error, its magnitude, and that over the
        force).
    newton_iterations
        Newton iterations of the solve on this mesh (all steps).
    wall
        Wall time of the solve and estimate, seconds (not the refinement).
    start
        ``"load path"``: the solve ran the scene's load path from the reference state;
        ``"moved state"``: it started from the last level's solution moved onto this mesh.
    """

    unknowns: int
    cells: list[int]
    estimate: float
    relative: float
    newton_iterations: int
    wall: float
    start: str


@dataclass
class AdaptiveSolve:
    """The result of :func:`refine_to_tolerance`.

    Attributes
    ----------
    problem
        The problem on the last mesh, solved (its :attr:`estimate` is the last level's).
    estimate
        The error estimate of :attr:`problem` (an :class:`~contact_ufl.estimate.ErrorEstimate`,
        or with a goal a :class:`~contact_ufl.goal.GoalEstimate`).
    levels
        Every mesh the loop solved on, coarsest first.
    reached
        Whether the relative estimate met the tolerance (else the budget or the number of
        levels stopped the loop: :attr:`stopped_by` says which).
    stopped_by
        ``"tolerance"``, ``"budget"`` or ``"levels"``.
    """

    problem: ContactProblem
    estimate: object
    levels: list[Level] = field(default_factory=list)
    reached: bool = False
    stopped_by: str = ""


#: the goals of :func:`refine_to_tolerance` (``None``: the energy norm)
GOALS = (None, "normal_force")


def doerfler_marking(
    indicators: list[dolfinx.fem.Function], theta: float, comm: MPI.Comm
) -> list[np.ndarray]:
    """The fewest cells (largest indicators first) whose indicators sum to at least
    ``theta`` of the total, over all meshes and ranks (Doerfler's bulk criterion).

    Parameters
    ----------
    indicators
        A non-negative value per cell, a DG0 function per mesh: ``eta_K^2`` of the energy
        estimate (:attr:`ErrorEstimate.indicators
        <contact_ufl.estimate.ErrorEstimate.indicators>`), or a goal's ``|eta_K|``
        (:attr:`GoalEstimate.indicators <contact_ufl.goal.GoalEstimate.indicators>`).
    theta
        The fraction, in (0, 1].

    Returns
    -------
    The marked owned cells of each mesh (local indices).
    """
    values = [_cell_values(eta) for eta in indicators]
    local = np.concatenate(values) if values else np.zeros(0)
    gathered = comm.gather(local, root=0)
    threshold = None
    if comm.rank == 0:
        every = np.sort(np.concatenate(gathered))[::-1]
        total = every.sum()
        if total > 0.0:
            k = int(np.searchsorted(np.cumsum(every), theta * total * (1.0 - 1e-12)))
            threshold = float(every[min(k, len(every) - 1)])
    threshold = comm.bcast(threshold, root=0)
    if threshold is None:
        return [np.zeros(0, dtype=np.int32) for _ in values]
    return [np.flatnonzero(v >= threshold).astype(np.int32) for v in values]


def _cell_values(eta: dolfinx.fem.Function) -> np.ndarray:
    """The values of a DG0 function on the owned cells, in cell order."""
    mesh = eta.function_space.mesh
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    dofs = eta.function_space.dofmap.list[:owned, 0]
    return eta.x.array[dofs]


def transfer_state(source: ContactProblem, target: ContactProblem, padding: float = 1e-6) -> None:
    """Set the unknowns of ``target`` (a problem on refined meshes of ``source``'s scene) to
    those of ``source`` moved onto its meshes (pointwise interpolation), and its pseudo-time
    to ``source``'s (collective). ``padding``: the distance, relative to the scene's size,
    within which a point outside the source's cells (a node put onto a curved boundary) is
    still found."""
    size = source.scales()[0]
    for old, new in zip(source.bulks, target.bulks, strict=True):
        interpolate_by_body(new.u, new.domain, old.u, old.domain, padding * size)
    displacements = {id(b.u) for b in source.bulks}
    interpolate_unknowns(source.unknowns, target.unknowns, displacements, padding * size)
    target.set_time(source.t)


def has_history(scene: Scene) -> bool:
    """Whether the state of ``scene`` depends on its load path: friction or plasticity."""
    frictional = any(c.mu > 0.0 for c in scene.contacts)
    plastic = any(isinstance(b.material, J2Plasticity) for d in scene.parts for b in d.bodies)
    return bool(frictional or plastic)


def refine_to_tolerance(
    scene: Scene,
    solve: Callable[[ContactProblem], object],
    tolerance: float,
    max_unknowns: int,
    theta: float = 0.5,
    max_levels: int = 10,
    boundaries: Mapping[int | str, Boundary] | None = None,
    problem_options: Mapping | None = None,
    on_level: Callable[[ContactProblem, Level], None] | None = None,
    goal: str | None = None,
) -> AdaptiveSolve:
    """Solve ``scene``, refine its meshes where the error estimate says, and solve again,
    until the relative estimate (over the solution's energy norm, or over the goal) is at
    most ``tolerance`` or the next mesh would exceed ``max_unknowns`` (collective).

    Parameters
    ----------
    scene
        The scene on its starting meshes (simplices).
    solve
        The load path, ``solve(problem)``: e.g. ``lambda p: p.solve(num_steps=4)``. It runs
        on the first mesh, and on every mesh of a scene with history (friction,
        plasticity); a scene without history starts each later mesh from the last solution
        moved onto it and brings that to equilibrium at the same load (its load path
        replayed if that fails).
    tolerance
        The target of :attr:`ErrorEstimate.relative
        <contact_ufl.estimate.ErrorEstimate.relative>` (with a goal, of
        :attr:`GoalEstimate.relative <contact_ufl.goal.GoalEstimate.relative>`), > 0.
    max_unknowns
        The budget: no mesh with more unknowns is solved on.
    theta
        Doerfler's fraction (:func:`doerfler_marking`), in (0, 1].
    max_levels
        At most this many meshes.
    boundaries
        Curved facet groups and the functions that put points onto them
        (:func:`refine_scene`).
    problem_options
        Keyword arguments of :class:`~contact_ufl.problem.ContactProblem` (``degree``,
        ``petsc_options``, ...).
    on_level
        Called with the problem and its :class:`Level` after each solve (e.g. to write
        pictures of the meshes and indicators).
    goal
        ``None``: the energy norm's estimate drives the loop; ``"normal_force"``: the
        estimated error of the normal contact force of all pairs
        (:func:`~contact_ufl.goal.normal_force_error`; frictionless contact of hyperelastic
        solids, degree 1), its cells' shares marked.

    Returns
    -------
    :class:`AdaptiveSolve`: the problem on the last mesh, its estimate, the levels.
    """
    comm = scene.parts[0].mesh.comm
    options = dict(problem_options or {})
    _check_loop_input(comm, tolerance, max_unknowns, theta, max_levels)
    collective_check(
        comm,
        goal in GOALS,
        f"goal must be one of {', '.join(map(repr, GOALS))}, got {goal!r}",
    )
    check_refinable(scene)
    check_boundaries(scene, boundaries or {})
    check_estimable(scene)
    history = has_history(scene)
    problem = ContactProblem(scene, **options)
    if goal is not None:
        try:
            check_goal_estimable(problem)
        except NotImplementedError:
            problem.close()
            raise
    _check_budget(problem, max_unknowns, first=True)
    levels: list[Level] = []
    previous = None
    while True:
        start = time.perf_counter()
        kind = "load path"
        if previous is None or history:
            solve(problem)
        else:
            problem, kind = _solve_from(previous, problem, solve, options)
            previous.close()
        if goal is None:
            estimate = problem.error_estimate()
            size = estimate.estimate
        else:
            estimate = problem.normal_force_error()
            size = abs(estimate.error)
        level = Level(
            unknowns=problem.layout.global_size,
            cells=[_num_cells(b.V.mesh) for b in problem.bulks],
            estimate=size,
            relative=estimate.relative,
            newton_iterations=sum(r.newton_iterations for r in problem.history.steps),
            wall=time.perf_counter() - start,
            start=kind,
        )
        levels.append(level)
        if on_level is not None:
            on_level(problem, level)
        result = AdaptiveSolve(problem, estimate, levels)
        if level.relative <= tolerance:
            result.reached, result.stopped_by = True, "tolerance"
            return result
        if len(levels) >= max_levels:
            result.stopped_by = "levels"
            return result
        marked = doerfler_marking(estimate.indicators, theta, comm)
        scene = refine_scene(problem.scene, marked, boundaries)
        moved = [b.u for b in problem.bulks]
        sources = [b.domain for b in problem.bulks]
        scene = slave_finer_than_master(scene, moved, boundaries, sources=sources)
        finer = ContactProblem(scene, **options)
        if not _check_budget(finer, max_unknowns):
            finer.close()
            result.stopped_by = "budget"
            return result
        if history:
            problem.close()
        previous, problem = problem, finer


def _solve_from(
    previous: ContactProblem, problem: ContactProblem, solve, options: dict
) -> tuple[ContactProblem, str]:
    """Solve ``problem`` from the state of ``previous`` moved onto it, at its load; where
    that fails, a new problem on the same meshes along the load path. The problem solved
    and which start it took."""
    transfer_state(previous, problem)
    problem.resume_solver()
    try:
        problem.stepper.equilibrate()
        return problem, "moved state"
    except ConvergenceError:
        scene = problem.scene
        problem.close()
    problem = ContactProblem(scene, **options)
    solve(problem)
    return problem, "load path"


def _num_cells(mesh: dolfinx.mesh.Mesh) -> int:
    return mesh.topology.index_map(mesh.topology.dim).size_global


def _check_loop_input(comm, tolerance, max_unknowns, theta, max_levels) -> None:
    def number(value) -> bool:
        return isinstance(value, int | float | np.number) and not isinstance(value, bool)

    collective_check(
        comm,
        number(tolerance) and tolerance > 0.0,
        f"tolerance must be a number > 0 (a relative error estimate), got {tolerance!r}",
    )
    collective_check(
        comm,
        isinstance(max_unknowns, int | np.integer) and max_unknowns > 0,
        f"max_unknowns must be a whole number > 0, got {max_unknowns!r}",
    )
    collective_check(
        comm,
        number(theta) and 0.0 < theta <= 1.0,
        f"theta (Doerfler's fraction) must be in (0, 1], got {theta!r}",
    )
    collective_check(
        comm,
        isinstance(max_levels, int | np.integer) and max_levels >= 1,
        f"max_levels must be a whole number >= 1, got {max_levels!r}",
    )


def _check_budget(problem: ContactProblem, max_unknowns: int, first: bool = False) -> bool:
    """Whether ``problem`` is within the budget; on the starting mesh, an error if not."""
    n = problem.layout.global_size
    if first and n > max_unknowns:
        problem.close()
        raise ContactInputError(
            f"the starting meshes have {n} unknowns, more than max_unknowns = {max_unknowns}: "
            "raise the budget or start from coarser meshes"
        )
    return n <= max_unknowns
