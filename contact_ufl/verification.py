"""Verification runs shared by tests and benchmarks (solve, then compare with theory)."""

from __future__ import annotations

import numpy as np

from contact_ufl import scenes
from contact_ufl.analytic import CattaneoMindlin2D, Hertz2D
from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples, stick_zone_half_width


def cattaneo_mindlin_run(
    h: float, mu: float = 0.3, depth: float = 0.005, shift: float = 0.0015, steps: int = 4
):
    """Hertz loading, then ``steps`` tangential steps; one record per tangential level.

    Returns the records (Q / (mu P), stick-zone half-width measured and exact, its relative
    error, the RMS shear-traction error in |x| < 0.8 a relative to mu p0, Newton
    iterations) and the problem.
    """
    hertz = scenes.hertz_2d(h_contact=h, depth=depth, mu=mu, shift=shift)
    problem = ContactProblem(hertz.scene, verbose=False)
    problem.solve(num_steps=4, t_end=1.0)
    levels = []

    def record(problem, step):
        force = step.contact_force
        exact = CattaneoMindlin2D(Hertz2D(force[1], hertz.radius, hertz.E_star), abs(force[0]), mu)
        c = stick_zone_half_width(problem)
        levels.append(
            {
                "t": step.t,
                "Q_over_muP": abs(force[0]) / (mu * force[1]),
                "c": c,
                "c_exact": exact.c,
                "stick_zone_error": c / exact.c - 1.0,
                "shear_error": shear_error(problem, exact),
                "newton_iterations": step.newton_iterations,
            }
        )

    problem.solve(num_steps=steps, t_end=2.0, callback=record)
    return levels, problem


def shear_error(problem, exact: CattaneoMindlin2D, pair: int = 0) -> float:
    """RMS error of the Cauchy shear traction inside |x| < 0.8 a, relative to mu p0."""
    c = problem.contacts[pair]
    comm = problem.comm
    samples = contact_samples(problem, pair)
    shear = np.linalg.norm(c.tangential_multiplier_at_points(), axis=1)
    shear = np.concatenate(comm.allgather(shear / c.slave.area_ratio(problem.u).ravel()))
    pressed = samples.x[samples.lambda_N > 0, 0]
    centre = 0.5 * (pressed.min() + pressed.max())
    x = samples.x[:, 0] - centre
    near = np.abs(x) < 0.8 * exact.hertz.a
    rms = np.sqrt(np.mean((shear[near] - exact.shear(x[near])) ** 2))
    return float(rms / (exact.mu * exact.hertz.p0))
