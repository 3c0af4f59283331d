"""Load stepping: cut-back of diverging steps, a clear error when cut-backs run out."""

import dataclasses
import gc
import time
import weakref

import numpy as np
import pytest
from mpi4py import MPI

from contact_ufl.errors import ConvergenceError
from contact_ufl.loads import Dirichlet
from contact_ufl.newton import FIELD_SPLIT_PETSC_OPTIONS
from contact_ufl.problem import ContactProblem
from contact_ufl.stepping import LoadStepper
from contact_ufl.strategies import default_strategies
from contact_ufl.timings import NewtonTimings
from contact_ufl.verification import scenes

#: the package's field split with linear solves tight enough to compare with MUMPS's
FIELD_SPLIT = FIELD_SPLIT_PETSC_OPTIONS | {"ksp_rtol": 1e-12}
#: the reference of the field split's checks
DIRECT = "the same solve with MUMPS (the default direct solver)"
# The bounds of the comparisons of two solves, relative, with the values measured on 1 and
# 2 ranks. Two load paths or tries converge to the Newton tolerance (snes_rtol 1e-9), two
# runs of the same iterations to round-off (more on two ranks, where MUMPS's parallel
# factorisation is reproducible only to round-off, and through iterative linear solves).
#: another load path (a cut-back): 1.4e-10
TOL_CUTBACK = 3e-10
#: another try after a NaN update (h_contact = 0.05): 5.0e-10
TOL_NAN = 1e-9
#: predicted states instead of cut-backs: 5.8e-9
TOL_PREDICTOR = 1e-8
#: the same iterations on two ranks (MUMPS's parallel round-off, which varies from run to
#: run): 0 to 5.1e-15
TOL_BY_HAND = 1e-13
#: the same iterations with other solver-matrix patterns: 0 to 9.3e-15
TOL_REBUILT = 5e-14
#: the field split (GMRES to ksp_rtol 1e-12 in each Newton step): x 4.2e-15, with friction
#: x 3.4e-14 to 5.6e-14 (from run to run on two ranks) and F 1.6e-15
TOL_SPLIT, TOL_SPLIT_FORCE = 2e-13, 1e-14
#: GAMG on the whole (no contact: fewer Newton steps to damp its 1e-12): 2.8e-12
TOL_GAMG = 1e-11
#: T^T K T against the tangent assembled straight (round-off): 1.0e-17
TOL_CHAIN = 1e-15
#: the scene of :func:`hertz_problem`
HERTZ = "Hertz 2D, Neo-Hookean, h_contact = 0.02, depth 0.01"


def hertz_problem(**options):
    hertz = scenes.hertz_2d(h_contact=0.02, depth=0.01)
    return ContactProblem(hertz.scene, verbose=False, petsc_options=options)


def difference(ours, theirs) -> float:
    """The largest difference of two arrays distributed over the ranks (or of the same
    array on every rank), relative to the largest entry of ``theirs``."""
    comm = MPI.COMM_WORLD
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    scale = comm.allreduce(np.abs(theirs).max(initial=0.0), MPI.MAX)
    assert scale > 0
    return comm.allreduce(np.abs(ours - theirs).max(initial=0.0), MPI.MAX) / scale


@pytest.mark.serial  # the stepper's logic, not the partition's
def test_diverging_step_is_cut_back(verification):
    """Three Newton iterations cannot do the whole load in one step: the step is halved
    (no predicted try, which would add its iterations to the steps after a failed try); the
    force is that of four steps without cut-back (a frictionless hyperelastic problem does
    not depend on the load path; consistency, to the Newton tolerance)."""
    problem = hertz_problem(snes_max_it=3)
    problem.solver.strategies = default_strategies(predictor=None)
    history = problem.solve(num_steps=1)
    assert len(history.cutbacks) >= 1
    assert history.cutbacks[0][0] == pytest.approx(1.0)
    assert problem.t == pytest.approx(1.0)
    assert all(r.newton_iterations <= 3 for r in history.steps)
    reference = hertz_problem()
    reference.solve(num_steps=4)
    error = difference(problem.contact_force()[1], reference.contact_force()[1])
    source = "the same scene in 4 load steps, no cut-back"
    quantity = "relative difference of the contact force F_y (cut back)"
    verification(HERTZ, quantity, error, 0.0, TOL_CUTBACK, source, kind="consistency")
    assert error <= TOL_CUTBACK


def test_cutbacks_run_out_with_a_clear_error():
    problem = hertz_problem()
    problem.solve(num_steps=2, t_end=0.5)
    accepted = list(problem.history.steps)
    problem.solver.snes.setTolerances(max_it=1)  # now no step can converge
    with pytest.raises(ConvergenceError, match=r"load step 3, from t = 0.5 to .* did not converge"):
        problem.solve(num_steps=1, t_end=1.0, max_cutbacks=2)
    assert problem.history.steps[: len(accepted)] == accepted  # nothing accepted is lost
    assert problem.t == pytest.approx(accepted[-1].t)  # state restored to the last accepted


@pytest.mark.serial  # the stepper's logic, not the partition's
def test_solver_and_stepping_made_by_hand(verification):
    """``problem.solve`` is the solver and the load stepping composed: made by hand they give
    the same steps, Newton iterations and forces (to the last bit on one rank; on two, MUMPS's
    parallel factorisation is reproducible only to round-off)."""
    problem = hertz_problem()
    solver = problem.solver
    solver.strategies = default_strategies()
    history = LoadStepper(problem, solver).solve(num_steps=4)
    reference = hertz_problem()
    reference.solve(num_steps=4)
    assert [(r.t, r.newton_iterations) for r in history.steps] == [
        (r.t, r.newton_iterations) for r in reference.history.steps
    ]
    tag = problem.scene.dirichlet[0].tag
    tol = 0.0 if problem.comm.size == 1 else TOL_BY_HAND  # relative, of the force
    scale = np.linalg.norm(reference.contact_force())
    error = max(
        np.abs(np.subtract(ours, theirs)).max() / scale
        for ours, theirs in (
            ([r.residual for r in history.steps], [r.residual for r in reference.history.steps]),
            (problem.contact_force(), reference.contact_force()),
            (problem.reaction(tag), reference.reaction(tag)),
        )
    )
    source = "problem.solve of the same scene"
    quantity = "max difference of residuals, contact force, reaction, over |F|"
    verification(HERTZ, quantity, error, 0.0, tol, source, kind="consistency")
    assert error <= tol


def test_a_dropped_problem_is_freed():
    """The solver holds its callbacks weakly: a problem nobody references is collected, with
    its meshes, spaces and MPI communicators (MPICH has only a few thousand)."""
    problem = ContactProblem(scenes.pushed_block(), verbose=False)
    problem.solve(num_steps=1, t_end=0.5)
    ref = weakref.ref(problem)
    del problem
    gc.collect()
    assert ref() is None


def test_newton_timings_are_filled_and_reset():
    """The solver times its parts: each part that must run has run, the parts inside SNES fit
    in the SNES time, all of it fits in the wall time of the solve; reset zeroes them."""
    problem = hertz_problem()
    solver = problem.solver
    timings = solver.timings
    timings.reset()
    start = time.perf_counter()
    problem.solve(num_steps=2)
    wall = time.perf_counter() - start
    assert timings.iterations == sum(r.newton_iterations for r in problem.history.steps) > 0
    assert timings.jacobians >= timings.iterations
    assert timings.residuals > timings.iterations  # one more than Jacobians per solve
    assert timings.searches > 0
    assert 0 <= timings.new_patterns <= timings.jacobians
    for part in ("search", "residual_assembly", "jacobian_assembly", "ptap", "linear_solve"):
        assert getattr(timings, part) > 0.0, part
    assert timings.callbacks <= timings.newton
    parts = timings.search + timings.residual_assembly + timings.jacobian_assembly
    assert parts + timings.ptap + timings.linear_solve <= wall
    assert timings.newton <= wall
    per_iteration = timings.per_iteration()
    assert per_iteration["total"] == pytest.approx(timings.newton / timings.iterations)
    timings.reset()
    assert timings == NewtonTimings()
    assert timings.linear_solve == 0.0


def test_a_failed_step_says_where_elements_invert():
    """A load far beyond what one Newton step can take, without the line search: the trial
    iterate inverts elements (its residual is not a number); the error names the step, the
    reason and where the elements inverted (the loaded block's cells)."""
    problem = ContactProblem(scenes.patch(pressure=3.0), verbose=False)
    problem.solver.strategies = default_strategies(fallback_line_search=None)
    with pytest.raises(ConvergenceError, match=r"load step 1.*inverted elements in \d+ cells"):
        problem.solve(num_steps=1, max_cutbacks=1)
    (first, second) = problem.history.cutbacks
    assert first.reason == "DIVERGED_FUNCTION_NANORINF" and "inverted" in first.why
    assert np.all(problem.u.x.array == 0.0)  # the start of the step is kept


def test_solver_pattern_holds_the_pairings_met():
    """The solver matrix's pattern is a superset (the facets beside each point's facet):
    the pairing changes within a solve, T^T K T gets new patterns, but the factorisation's
    symbolic analysis is kept (fewer analyses than new patterns), and the solver matrix holds
    every coupling of the current tangent."""
    from petsc4py import PETSc

    problem = hertz_problem()
    operator = problem.operator
    timings = operator.timings
    timings.reset()
    problem.solve(num_steps=2)
    assert timings.new_patterns >= 1
    assert timings.analyses < timings.new_patterns
    J = operator.evaluate_jacobian(operator.x)
    union = J.duplicate(copy=True)
    union.axpy(
        1.0, operator._chained_tangent, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
    )
    assert union.getInfo()["nz_used"] == J.getInfo()["nz_used"]


def test_rebuilt_solver_pattern_gives_the_same_solution(verification):
    """With no slack the solver matrix is rebuilt on the current pairing's superset at every
    step whose union grew; the solution is that of the default solver (round-off)."""
    results = []
    for slack in (0.5, -1.0):
        problem = hertz_problem()
        problem.operator.pattern.slack = slack
        problem.solve(num_steps=2)
        results.append((problem.solver.timings.analyses, problem.solver.x.array.copy()))
    (kept, x_kept), (rebuilt, x_rebuilt) = results
    assert rebuilt > kept  # the negative slack rebuilt the pattern at every step
    error = difference(x_rebuilt, x_kept)
    source = "the solve with the default pattern slack"
    quantity = "max |x - x_default| / max |x_default| (pattern rebuilt every step)"
    verification(HERTZ, quantity, error, 0.0, TOL_REBUILT, source, kind="consistency")
    assert error <= TOL_REBUILT


@pytest.mark.serial  # the stepper's logic, not the partition's
def test_a_failed_first_try_is_tried_again_from_the_predicted_state(verification):
    """Hertz in steps of 0.25, Newton held to 3 iterations after the first step: from the
    converged state the steps to 0.5 and 1.0 need 4 and are cut back without the predicted
    try; from the predicted state (the last step's increment once more) they converge in 3,
    with no cut-back and the same force. With the predicted state first, every step takes
    at most 3."""
    forces, counts = {}, {}
    for predictor in (None, "retry", "first"):
        problem = hertz_problem()
        problem.solver.strategies = default_strategies(predictor=predictor)
        problem.solve(num_steps=1, t_end=0.25)
        problem.solver.snes.setTolerances(max_it=3)
        problem.solve(num_steps=3, t_end=1.0)
        forces[predictor] = problem.contact_force()[1]
        counts[predictor] = [r.newton_iterations for r in problem.history.steps[1:]]
        cutbacks = problem.history.cutbacks
        assert bool(cutbacks) == (predictor is None), predictor
    assert counts["retry"] == [6, 3, 6]  # the failed try's 3 iterations, then 3
    assert max(counts["first"]) <= 3
    errors = [difference(forces[p], forces[None]) for p in ("retry", "first")]
    source = "the same steps without a predicted state (cut back)"
    quantity = "relative difference of F_y (predictor 'retry', 'first')"
    verification(HERTZ, quantity, errors, 0.0, TOL_PREDICTOR, source, kind="consistency")
    assert max(errors) <= TOL_PREDICTOR


@pytest.mark.serial  # the stepper's logic, not the partition's
def test_a_solve_at_its_start_time_predicts_nothing(verification):
    """A converged solve at the time it starts from (``solve_step(problem.t)``: a step of
    length zero) leaves no increment to scale: the next step starts from the converged
    state (it raised ZeroDivisionError with the predicted state first), and makes the
    iterations of the steps without a predicted state (the same force to round-off)."""
    problem = hertz_problem()
    problem.solver.strategies = default_strategies(predictor="first")
    problem.solve(num_steps=1, t_end=0.25)
    problem.begin_step()
    assert problem.solver.solve_step(problem.t)[0]
    problem.solve(num_steps=1, t_end=0.5)
    reference = hertz_problem()
    reference.solver.strategies = default_strategies(predictor=None)
    reference.solve(num_steps=2, t_end=0.5)
    assert problem.t == pytest.approx(0.5)
    error = difference(problem.contact_force()[1], reference.contact_force()[1])
    source = "2 steps to t = 0.5 without a predicted state"
    quantity = "relative difference of F_y at t = 0.5 (after a step of length zero)"
    verification(HERTZ, quantity, error, 0.0, TOL_BY_HAND, source, kind="consistency")
    assert error <= TOL_BY_HAND


def test_an_unknown_predictor_is_refused():
    with pytest.raises(ValueError, match="predictor must be 'retry', 'first' or None"):
        default_strategies(predictor="linear")


@pytest.mark.serial  # 2 ranks: the field split with friction
def test_field_split_solver_gives_the_same_solution(verification):
    """The package's ``FIELD_SPLIT_PETSC_OPTIONS`` (a ``fieldsplit``: the solver gives it
    the splits ``u`` and ``lambda``, also after the resets of a new pattern; GMRES with a
    Schur split, GAMG on the displacements) gives the direct solver's solution."""
    results = []
    for options in ({}, FIELD_SPLIT):
        problem = hertz_problem(**options)
        problem.operator.pattern.slack = -1.0  # a new pattern, and a reset, at the second step
        problem.solver.timings.reset()
        problem.solve(num_steps=2)
        results.append((problem.solver, problem.solver.x.array.copy()))
    (direct, x_direct), (iterative, x_iterative) = results
    pc = iterative.snes.getKSP().getPC()
    assert pc.getType() == "fieldsplit"
    assert iterative.timings.analyses >= 1  # the splits were kept through a reset
    assert iterative.snes.getKSP().getIterationNumber() > 1
    error = difference(x_iterative, x_direct)
    quantity = "max |x - x_MUMPS| / max |x_MUMPS| (field split, ksp_rtol 1e-12)"
    verification(HERTZ, quantity, error, 0.0, TOL_SPLIT, DIRECT, kind="consistency")
    assert error <= TOL_SPLIT


def test_field_split_solver_with_friction_gives_the_same_solution(verification):
    """Frictional contact (mu = 0.3, pressed then shifted into partial slip): the field
    split's ``lambda`` holds the normal and tangential multipliers; its Newton iterations
    and solution are the direct solver's."""
    results = []
    for options in ({}, FIELD_SPLIT):
        hertz = scenes.hertz_2d(h_contact=0.02, depth=0.01, mu=0.3, shift=0.002)
        problem = ContactProblem(hertz.scene, verbose=False, petsc_options=options)
        history = problem.solve(num_steps=4, t_end=2.0)
        iterations = [r.newton_iterations for r in history.steps]
        results.append((iterations, problem.contact_force(), problem.solver.x.array.copy()))
    (its_direct, force_direct, x_direct), (its_split, force_split, x_split) = results
    assert abs(force_direct[0]) > 0.1 * abs(force_direct[1])  # a tangential force
    assert its_split == its_direct
    errors = [difference(force_split, force_direct), difference(x_split, x_direct)]
    case = "Hertz 2D, Neo-Hookean, mu = 0.3, pressed then shifted (partial slip)"
    quantity = "max |F - F_MUMPS| / max |F_MUMPS|, of x likewise (field split)"
    tolerance = f"< {TOL_SPLIT_FORCE:g} (F), < {TOL_SPLIT:g} (x)"
    verification(case, quantity, errors, 0.0, tolerance, DIRECT, kind="consistency")
    assert errors[0] <= TOL_SPLIT_FORCE and errors[1] <= TOL_SPLIT


def test_field_split_options_without_multipliers_take_the_multigrid_on_the_whole(verification):
    """A problem without contact has the displacements only: nothing to split, so the field
    split options give their ``u`` split's GAMG on the whole, with the direct solution."""
    hertz = scenes.hertz_2d(h_contact=0.02, depth=0.01).scene
    arc = Dirichlet(hertz.tags["cylinder_contact"], (0.0, -0.01))
    scene = dataclasses.replace(hertz, contacts=[], dirichlet=[*hertz.dirichlet, arc])
    solutions = []
    for options in ({}, FIELD_SPLIT):
        problem = ContactProblem(scene, verbose=False, petsc_options=options)
        problem.solve(num_steps=1)
        solutions.append(problem.solver.x.array.copy())
    ksp = problem.solver.snes.getKSP()
    assert (ksp.getType(), ksp.getPC().getType()) == ("fgmres", "gamg")
    assert ksp.getIterationNumber() > 1
    direct, iterative = solutions
    error = difference(iterative, direct)
    case = "Hertz 2D scene without contact, the arc moved by (0, -0.01)"
    quantity = "max |x - x_MUMPS| / max |x_MUMPS| (GAMG on the whole)"
    verification(case, quantity, error, 0.0, TOL_GAMG, DIRECT, kind="consistency")
    assert error <= TOL_GAMG


def test_solver_matrix_rebuilt_inside_a_newton_solve(verification):
    """3D (no superset: every new pairing grows the pattern): with no slack, a growth
    inside a Newton solve rebuilds the solver matrix on the current pattern there (the
    SNES's matrix replaced during its Jacobian call); the solution is the default's."""
    results = []
    for slack in (0.5, -1.0):
        problem = ContactProblem(scenes.hertz_3d(h_contact=0.025).scene, verbose=False)
        problem.operator.pattern.slack = slack
        problem.solve(num_steps=2)
        results.append((problem.solver, problem.solver.x.array.copy()))
    (kept, x_kept), (rebuilt, x_rebuilt) = results
    assert kept.newton._retired is None  # the union stayed within the slack
    assert rebuilt.newton._retired is not None  # replaced inside a Newton solve
    assert rebuilt.timings.iterations == kept.timings.iterations
    error = difference(x_rebuilt, x_kept)
    source = "the solve with the default pattern slack"
    quantity = "max |x - x_default| / max |x_default| (matrix rebuilt inside Newton)"
    case = "Hertz 3D, h_contact = 0.025"
    verification(case, quantity, error, 0.0, TOL_REBUILT, source, kind="consistency")
    assert error <= TOL_REBUILT


def test_a_pairing_within_the_solver_pattern_keeps_the_analysis(monkeypatch, verification):
    """3D: a pairing that leaves the last one's operator but whose product adds no nonzero
    to the solver matrix keeps the matrix and its symbolic analysis: fewer analyses than
    when every such pairing grows the matrix, the same iterations and solution, and at every
    Jacobian the solver matrix holds every coupling of the tangent."""
    from petsc4py import PETSc

    def solve(grow_always: bool):
        problem = ContactProblem(scenes.hertz_3d(h_contact=0.02).scene, verbose=False)
        operator = problem.operator
        # Newton from the open state, its many pairings (the first contact's predictor
        # iterate starts from about the final zone and meets fewer)
        problem.solver.strategies = default_strategies(first_contact_level=None)
        if grow_always:
            monkeypatch.setattr(operator.pattern, "within_matrix", lambda keys: False)
        add, missing = operator._add_gathered_blocks, []

        def add_checked(J):
            union = J.duplicate(copy=False)
            union.axpy(
                1.0,
                operator._chained_tangent,
                structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN,
            )
            missing.append(union.getInfo()["nz_used"] - J.getInfo()["nz_used"])
            union.destroy()
            add(J)

        monkeypatch.setattr(operator, "_add_gathered_blocks", add_checked)
        operator.timings.reset()
        problem.solve(num_steps=2)
        return operator.timings, operator.x.array.copy(), missing

    (kept, x_kept, missing), (grown, x_grown, _) = solve(False), solve(True)
    assert kept.analyses < grown.analyses
    assert kept.iterations == grown.iterations
    assert len(missing) >= kept.iterations and not any(missing)
    error = difference(x_kept, x_grown)
    source = "the solve whose every new pairing grows the solver matrix"
    quantity = "max |x - x_grown| / max |x_grown| (analysis kept)"
    case = "Hertz 3D, h_contact = 0.02, Newton from the open state"
    verification(case, quantity, error, 0.0, TOL_REBUILT, source, kind="consistency")
    assert error <= TOL_REBUILT


def test_a_closed_problem_frees_its_solver_and_refuses_to_solve():
    """``with ContactProblem(...) as problem``: on leaving, the solver's PETSc objects are
    destroyed (on more than one rank a dropped problem's objects would wait in memory for a
    collective clean-up that never comes); the fields keep their values, and the results read
    from them; solving, or a result that needs the solver, then raises a clear error."""
    with hertz_problem() as problem:
        problem.solve(num_steps=1)
        solver = problem.solver
        held = [solver.snes, solver.operator.matrix, solver.operator._T, solver.x]
        u, force = problem.u.x.array.copy(), problem.contact_force()
    assert all(obj.handle == 0 for obj in held)
    np.testing.assert_array_equal(problem.u.x.array, u)
    assert len(problem.history.steps) == 1
    with pytest.raises(RuntimeError, match="closed"):
        problem.solve(num_steps=1, t_end=2.0)
    with pytest.raises(RuntimeError, match="closed"):
        problem.contact_residual()
    np.testing.assert_array_equal(problem.contact_force(), force)  # from the fields
    problem.close()  # closing again does nothing


def test_a_non_finite_iterate_is_a_failed_try(verification):
    """A Newton update with a NaN (here put into the second line-search direction) makes a
    trial iterate that is not a number: its residual is NaN, with no search on it, and the
    step goes on (another try, a cut-back) to the same solution. When the search raised on
    it inside the SNES callback, PETSc kept the iterate's vector locked and every later try
    of the step failed: 8 cut-backs, then a ConvergenceError."""
    reference = ContactProblem(scenes.hertz_2d(h_contact=0.05, depth=0.01).scene, verbose=False)
    reference.solve(num_steps=1)
    problem = ContactProblem(scenes.hertz_2d(h_contact=0.05, depth=0.01).scene, verbose=False)
    calls = []

    def poison(x, y):
        calls.append(1)
        if len(calls) == 2:
            y.array[:1] = np.nan  # on every rank that owns a dof
            return True
        return False

    problem.solver.snes.setLineSearchPreCheck(poison)
    problem.solve(num_steps=1)
    assert len(calls) > 2 and problem.t == pytest.approx(1.0)
    error = difference(problem.contact_force(), reference.contact_force())
    case = "Hertz 2D, Neo-Hookean, h_contact = 0.05, depth 0.01"
    source = "the same step without the NaN"
    quantity = "max |F - F_ref| / max |F_ref| (a NaN update, then another try)"
    verification(case, quantity, error, 0.0, TOL_NAN, source, kind="consistency")
    assert error <= TOL_NAN


def test_an_error_in_a_callback_is_raised_and_leaves_the_problem_usable(monkeypatch):
    """An exception inside the residual callback (here from the contact update) is raised
    as itself from the solve, not turned into failed tries; the step is undone (the time
    and unknowns of the last converged step) and the next solve works (the SNES's vectors
    are not left locked)."""
    problem = ContactProblem(scenes.hertz_2d(h_contact=0.05, depth=0.01).scene, verbose=False)
    operator = problem.operator
    update = operator.update_pairing

    def broken(*args, **kwargs):
        raise RuntimeError("a bug in the contact update")

    monkeypatch.setattr(operator, "update_pairing", broken)
    with pytest.raises(RuntimeError, match="a bug in the contact update"):
        problem.solve(num_steps=1)
    assert problem.t == 0.0  # the failed step is undone
    monkeypatch.setattr(operator, "update_pairing", update)
    problem.solve(num_steps=1)
    assert problem.t == 1.0 and len(problem.history.steps) == 1
    assert problem.contact_force()[1] != 0.0 and not problem.history.cutbacks


def test_ctrl_c_in_a_solve_stops_it_and_leaves_the_problem_usable(monkeypatch, verification):
    """SIGINT (Ctrl-C) inside a Newton solve raises ``KeyboardInterrupt`` from the solve (it
    came back through PETSc as a failed linear solve, and the step was cut back eight times
    instead); the steps accepted before are kept, the interrupted step is undone, and
    solving on gives the force of a run never interrupted (consistency)."""
    import os
    import signal

    scene = scenes.hertz_2d(h_contact=0.05, depth=0.01).scene
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=2, t_end=0.5)
    operator, calls = problem.operator, []
    update = operator.update_pairing

    def interrupted(x):
        calls.append(1)
        if len(calls) == 3:  # inside the second Newton iterate of the third step
            os.kill(os.getpid(), signal.SIGINT)
        update(x)

    monkeypatch.setattr(operator, "update_pairing", interrupted)
    with pytest.raises(KeyboardInterrupt):
        problem.solve(num_steps=2, t_end=1.0)
    assert problem.t == 0.5 and len(problem.history.steps) == 2
    assert not problem.history.cutbacks
    monkeypatch.setattr(operator, "update_pairing", update)
    problem.solve(num_steps=2, t_end=1.0)
    reference = ContactProblem(scene, verbose=False)
    reference.solve(num_steps=2, t_end=0.5)
    reference.solve(num_steps=2, t_end=1.0)
    error = difference(problem.contact_force()[1], reference.contact_force()[1])
    case = "Hertz 2D, Neo-Hookean, h_contact = 0.05, depth 0.01"
    source = "the same steps never interrupted"
    quantity = "relative difference of F_y after a Ctrl-C in the third step"
    tol = 0.0 if problem.comm.size == 1 else TOL_BY_HAND
    verification(case, quantity, error, 0.0, tol, source, kind="consistency")
    assert error <= tol


@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_unknown_blocks_assembled_straight_give_the_chain_rule_tangent(mu, verification):
    """The solver matrix holds the tangent's blocks between unknowns assembled straight and
    the gathered blocks' ``T^T K T``: it equals ``T^T K T`` of the whole tangent over the
    fields (the chain rule the solver used before the split), with and without friction."""
    from petsc4py import PETSc

    from contact_ufl import assembly

    problem = ContactProblem(
        scenes.hertz_2d(h_contact=0.02, depth=0.01, mu=mu).scene, verbose=False
    )
    problem.solve(num_steps=1)
    operator = problem.operator
    assert (
        operator._unknown_blocks is not None and operator._gathered_tangent is not None
    )  # the split is in use
    J = operator.evaluate_jacobian(operator.x)
    K = assembly.create_matrix(problem.jacobian_form)
    assembly.assemble_matrix(K, problem.jacobian_form)
    K.assemble()
    whole = K.PtAP(operator._T)
    layout, dirichlet = problem.layout, operator.system.dirichlet
    rows = (layout.rank_offsets[layout.rank] + dirichlet.rows).astype(PETSc.IntType)
    whole.zeroRows(rows, diag=dirichlet.scale)
    whole.axpy(-1.0, J, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    assert J.norm() > 0.0
    error = whole.norm() / J.norm()
    case = f"Hertz 2D, Neo-Hookean, h_contact = 0.02, depth 0.01, mu = {mu}"
    source = "T^T K T of the whole tangent over the fields (the chain rule)"
    quantity = "|T^T K T - J| / |J| (Frobenius)"
    verification(case, quantity, error, 0.0, TOL_CHAIN, source, kind="consistency")
    assert error <= TOL_CHAIN
