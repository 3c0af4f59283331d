"""Verification runs shared by tests and benchmarks (solve, then compare with theory)."""

from __future__ import annotations

import numpy as np

from contact_ufl.loads import evaluate
from contact_ufl.problem import ContactProblem
from contact_ufl.results import (
    contact_force_parts,
    contact_samples,
    frictional_dissipation,
    stick_zone_half_width,
    stored_energy,
)
from contact_ufl.verification import scenes
from contact_ufl.verification.analytic import CattaneoMindlin2D, Hertz2D

__all__ = [
    "cattaneo_mindlin_run",
    "energy_balance",
    "history_at",
    "ironing_run",
    "shear_error",
    "steady_ratio",
]


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
    shear = np.linalg.norm(c.friction.tangential_multiplier_at_points(), axis=1)
    shear = np.concatenate(comm.allgather(shear / c.slave.area_ratio(problem.u).ravel()))
    pressed = samples.x[samples.lambda_N > 0, 0]
    centre = 0.5 * (pressed.min() + pressed.max())
    x = samples.x[:, 0] - centre
    near = np.abs(x) < 0.8 * exact.hertz.a
    rms = np.sqrt(np.mean((shear[near] - exact.shear(x[near])) ** 2))
    return float(rms / (exact.mu * exact.hertz.p0))


def ironing_run(
    mu: float,
    h_punch: float = 0.025,
    h_block: float = 0.1,
    press_steps: int = 20,
    slide_steps: int = 200,
    verbose: bool = False,
) -> tuple[dict, ContactProblem]:
    """The 2D shallow ironing problem of :func:`~contact_ufl.verification.scenes.ironing`,
    pressing then sliding; one record per converged step.

    Returns ``{"mu", "history", "cutbacks", ...}`` with history records ``time``, ``Fx``,
    ``Fy`` (the force of the support on the indenter's top, which balances the contact
    force), ``newton_iterations``, ``residual`` (SNES's final residual norm),
    ``snes_reason`` (SNES's converged reason of the accepted solve, by name) and
    ``converged`` (that reason is positive; a step whose Newton solve fails is cut back,
    and the run stops with :class:`ConvergenceError` when the cut-backs run out),
    ``contact_normal`` and ``contact_friction`` (the parts of the
    contact force on the indenter, :func:`contact_force_parts`), ``top_displacement``,
    ``stored_energy`` and ``dissipation`` (of the step), and the problem.
    """
    scene = scenes.ironing(mu=mu, h_punch=h_punch, h_block=h_block)
    problem = ContactProblem(scene, verbose=verbose, petsc_options={"snes_max_it": 40})
    top = scene.tags["punch_top"]
    (driven,) = [d for d in scene.dirichlet if d.tag == top]
    history = []

    def record(problem, step):
        F = problem.reaction(top)
        normal, frictional = contact_force_parts(problem)
        history.append(
            {
                "time": step.t,
                "Fx": float(F[0]),
                "Fy": float(F[1]),
                "newton_iterations": step.newton_iterations,
                "residual": float(step.residual),
                "snes_reason": step.reason,
                "converged": step.reason.startswith("CONVERGED"),
                "contact_normal": normal.tolist(),
                "contact_friction": frictional.tolist(),
                "top_displacement": evaluate(driven.value, step.t).tolist(),
                "stored_energy": stored_energy(problem),
                "dissipation": frictional_dissipation(problem),
            }
        )

    problem.solve(num_steps=press_steps, t_end=1.0, callback=record)
    problem.solve(num_steps=slide_steps, t_end=2.0, callback=record)
    run = {
        "mu": mu,
        "h_punch": h_punch,
        "h_block": h_block,
        "unknowns": problem.layout.global_size,
        "history": history,
        "cutbacks": [
            {"time": c.t, "reason": c.reason, "why": c.why} for c in problem.history.cutbacks
        ],
    }
    return run, problem


def steady_ratio(
    history: list[dict], window: tuple[float, float] = (1.2, 1.7), part: str | None = None
) -> float:
    """Mean of |Fx / Fy| over the records of the steady sliding ``window`` of pseudo-time
    (the indenter away from both ends of the block).

    With ``part="contact_friction"`` or ``"contact_normal"``, the numerator is the sliding
    component of that part of the contact force (:func:`contact_force_parts`) instead of Fx.
    Where both components have the sign of Fx (steady sliding) the two parts add up to
    |Fx / Fy|: the frictional one is close to mu where the indenter slides, the normal one
    is the pressure on the indenter's inclined front (ploughing).
    """
    records = [r for r in history if window[0] <= r["time"] <= window[1]]
    if part is None:
        return float(np.mean([abs(r["Fx"] / r["Fy"]) for r in records]))
    return float(np.mean([abs(r[part][0] / r["Fy"]) for r in records]))


def energy_balance(
    history: list[dict], window: tuple[float, float] = (1.2, 1.7)
) -> tuple[float, float, float]:
    """Energy balance of the records of :func:`ironing_run` over ``window``.

    Returns
    -------
    work, dissipation, stored
        The work of the indenter's support (trapezoidal in its force), the frictional
        dissipation and the change of stored energy over the window: in a quasi-static run
        ``work = dissipation + stored`` up to the time discretisation.
    """
    records = [r for r in history if window[0] <= r["time"] <= window[1]]
    if len(records) < 2:
        raise ValueError(f"fewer than two records in the window {window}")
    work = sum(
        0.5
        * np.dot(
            np.add([a["Fx"], a["Fy"]], [b["Fx"], b["Fy"]]),
            np.subtract(b["top_displacement"], a["top_displacement"]),
        )
        for a, b in zip(records[:-1], records[1:], strict=True)
    )
    dissipation = sum(r["dissipation"] for r in records[1:])
    return work, dissipation, records[-1]["stored_energy"] - records[0]["stored_energy"]


def history_at(history: list[dict], t: float, key: str) -> float:
    """|``key``| of the records, interpolated linearly in pseudo-time at ``t``."""
    times = np.array([r["time"] for r in history])
    return float(np.interp(t, times, [abs(r[key]) for r in history]))
