"""Verification runs shared by tests and benchmarks (solve, then compare with theory)."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
from mpi4py import MPI

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
from contact_ufl.verification.analytic import (
    CattaneoMindlin2D,
    Hertz2D,
    Hertz3D,
    fit_radial_profile,
)

__all__ = [
    "cattaneo_mindlin_run",
    "coulomb_ratio_3d",
    "energy_balance",
    "hertz_3d_errors",
    "hertz_3d_run",
    "history_at",
    "ironing_3d_run",
    "ironing_plane_strain_run",
    "ironing_run",
    "shear_error",
    "slave_point_weights",
    "steady_ratio",
]


def cattaneo_mindlin_run(
    h: float,
    mu: float = 0.3,
    depth: float = 0.005,
    shift: float = 0.0015,
    steps: int = 4,
    refine_radius: float = 0.3,
    pair: dict | None = None,
):
    """Hertz loading, then ``steps`` tangential steps; one record per tangential level.

    ``h`` is the element size within ``refine_radius`` of the first point of contact (the
    contact half-width is about 0.05 here; see :func:`scenes.hertz_2d`). ``pair``: fields
    of the contact pair to replace (e.g. ``{"eps_N": None, "eps_T": 0.1}``: the default
    ``eps_N``, a given ``eps_T``; by default the scene's ``eps_N = E / h``).

    Returns the records (Q / (mu P), stick-zone half-width measured and exact, its relative
    error, the RMS shear-traction error in |x| < 0.8 a relative to mu p0, Newton
    iterations) and the problem.
    """
    hertz = scenes.hertz_2d(
        h_contact=h, depth=depth, mu=mu, shift=shift, refine_radius=refine_radius
    )
    if pair:
        hertz.scene.contacts[0] = dataclasses.replace(hertz.scene.contacts[0], **pair)
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
    pressed = samples.x[samples.in_contact, 0]  # not lambda_N > 0: open points carry some
    centre = 0.5 * (pressed.min() + pressed.max())
    x = samples.x[:, 0] - centre
    near = np.abs(x) < 0.8 * exact.hertz.a
    rms = np.sqrt(np.mean((shear[near] - exact.shear(x[near])) ** 2))
    return float(rms / (exact.mu * exact.hertz.p0))


def _driven_run(scene, top_name: str, stages, verbose: bool) -> tuple[dict, ContactProblem]:
    """Solve ``scene`` through the load ``stages`` (``(num_steps, t_end)`` each), recording
    per converged step the force of the support ``top_name`` (the driven top of an
    indenter; ``Fx, Fy[, Fz]``), the Newton data, the parts of the contact force, the top's
    prescribed displacement, the stored energy and the step's dissipation."""
    problem = ContactProblem(scene, verbose=verbose, petsc_options={"snes_max_it": 40})
    top = scene.tags[top_name]
    (driven,) = [d for d in scene.dirichlet if d.tag == top]
    history = []

    def record(problem, step):
        F = problem.reaction(top)
        normal, frictional = contact_force_parts(problem)
        history.append(
            {
                "time": step.t,
                **{f"F{axis}": float(f) for axis, f in zip("xyz", F, strict=False)},
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

    for num_steps, t_end in stages:
        problem.solve(num_steps=num_steps, t_end=t_end, callback=record)
    run = {
        "unknowns": problem.layout.global_size,
        "history": history,
        "cutbacks": [
            {"time": c.t, "reason": c.reason, "why": c.why} for c in problem.history.cutbacks
        ],
    }
    return run, problem


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
    stages = [(press_steps, 1.0), (slide_steps, 2.0)]
    run, problem = _driven_run(scene, "punch_top", stages, verbose)
    return {"mu": mu, "h_punch": h_punch, "h_block": h_block, **run}, problem


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


def ironing_3d_run(
    mu: float,
    h_die: float = 0.3,
    h_slab: float = 0.5,
    press_steps: int = 10,
    slide_steps: int = 40,
    slide: float = 4.0,
    t_end: float = 2.0,
    verbose: bool = False,
    **scene_options,
) -> tuple[dict, ContactProblem]:
    """The 3D ironing problem of :func:`~contact_ufl.verification.scenes.ironing_3d`: the
    die pressed 1.4 into the slab (t = 0 to 1), then slid ``slide`` along it (t = 1 to 2),
    the slide stopped at ``t_end`` (in ``slide_steps`` steps); one record per converged step.
    ``scene_options`` go to the scene (``slave``, ``quadrature_degree``, ``master_normal``).

    Returns ``{"mu", "history", "cutbacks", ...}`` with history records ``time``, ``Fx``,
    ``Fy``, ``Fz`` (the force of the support on the die's top, which balances the contact
    force), ``newton_iterations``, ``residual``, ``snes_reason``, ``converged``,
    ``contact_normal`` and ``contact_friction`` (:func:`contact_force_parts`),
    ``top_displacement``, ``stored_energy`` and ``dissipation``, as :func:`ironing_run`;
    and the problem.
    """
    scene = scenes.ironing_3d(mu=mu, h_die=h_die, h_slab=h_slab, slide=slide, **scene_options)
    stages = [(press_steps, 1.0)] + ([(slide_steps, t_end)] if slide_steps > 0 else [])
    run, problem = _driven_run(scene, "die_top", stages, verbose)
    return {"mu": mu, "h_die": h_die, "h_slab": h_slab, **scene_options, **run}, problem


def coulomb_ratio_3d(history: list[dict], window: tuple[float, float] = (1.5, 1.9)) -> float:
    """Mean over the records of ``window`` of the sliding component of the frictional part
    of the contact force over the vertical component of its normal part,
    ``|F_fric,x| / |F_normal,z|`` (:func:`contact_force_parts`), in the 3D ironing.

    On the die's cylinder (axis along y) a point at angle theta from the bottom line has
    the normal ``(-sin theta, 0, cos theta)`` and, sliding along the circumference, the
    frictional traction ``mu t_N (cos theta, 0, sin theta)``: the ratio of the x component
    of the one to the z component of the other is ``mu`` at every sliding point, so the
    ratio of the sums is ``mu`` where the whole contact slides along x (Coulomb's law), less
    where points stick or slip across the slab. The default window is the steady slide:
    on the soft slab (E = 1) the contact sticks in part until the die has moved about 1.8
    (t = 1.45), and the die is 1 from the slab's far end at t = 2."""
    records = [r for r in history if window[0] <= r["time"] <= window[1]]
    if not records:
        raise ValueError(f"no record in the window {window}")
    return float(np.mean([abs(r["contact_friction"][0] / r["contact_normal"][2]) for r in records]))


# -- 3D Hertz -----------------------------------------------------------------------------------


def slave_point_weights(problem, pair: int = 0) -> np.ndarray:
    """Quadrature weights (reference measure) of the slave points of all ranks, in the order
    of :func:`~contact_ufl.results.contact_samples`: each rank's
    :attr:`~contact_ufl.contact.slave.SlaveSurface.point_weights`."""
    return np.concatenate(problem.comm.allgather(problem.contacts[pair].slave.point_weights))


def hertz_3d_errors(problem, hertz: scenes.Hertz3DScene, pair: int = 0) -> dict:
    """Errors of the 3D Hertz quarter model against :class:`Hertz3D` under the computed force.

    The exact solution is that of the full force ``P = 4 F_z``, ``F_z`` the contact force on
    the quarter ball. Hertz's solution is one of linear (small-strain) elasticity, where the
    configurations and the stress measures coincide; the model's bulk
    (:class:`~contact_ufl.materials.LinearElastic`) is Hooke's law for the *first Piola*
    stress, so the pressure compared is the nominal one, the multiplier ``lambda_N`` (force
    per unit reference area), at the reference positions of the slave points, ``r = sqrt(X^2
    + Y^2)``. (The Cauchy pressure at the current positions differs from it by the change of
    the surface's area, of the order of the strain ``p0 / E* ~ a / R``: 2-4% at the centre for
    ``a / R = 0.1``; it is reported as ``p0_error_cauchy``.)

    Returns
    -------
    dict
        ``P``, ``a``, ``p0`` (exact), ``a_over_h``; ``a_error``, ``p0_error``: of the
        L2-nearest profile ``p0 sqrt(1 - r^2 / a^2)``
        (:func:`~contact_ufl.verification.analytic.fit_radial_profile`);
        ``a_moment_error``: of ``a = sqrt(5/2 int p r^2 dA / int p dA)`` (the second moment of
        Hertz's pressure); ``p0_node_error``: of the largest nodal multiplier (at the point of
        first contact); ``a_last_error``: of the radius of the farthest slave point in
        contact; ``pressure_l2_error``: ``||p_h - p||_L2 / ||p||_L2`` over the whole slave
        surface (reference area); ``p0_error_cauchy``: the fit of the Cauchy pressure at the
        current positions.
    """
    c = problem.contacts[pair]
    comm = problem.comm
    samples = contact_samples(problem, pair)
    P = hertz.symmetry_factor * float(problem.contact_force(pair)[2])
    exact = Hertz3D(P, hertz.radius, hertz.E_star)
    X = np.concatenate(comm.allgather(c.slave.X.reshape(-1, c.gdim)))
    r = np.linalg.norm(X[:, :2], axis=1)
    lam = samples.lambda_N
    w = slave_point_weights(problem, pair)
    a, p0 = fit_radial_profile(r, lam, w)
    p = exact.pressure(r)
    a_moment = np.sqrt(2.5 * np.sum(w * lam * r**2) / np.sum(w * lam))
    owned = c.slave.P1.dofmap.index_map.size_local
    node_max = comm.allreduce(
        float(np.max(c.normal.lambda_N.x.array[:owned], initial=-np.inf)), MPI.MAX
    )
    r_current = np.linalg.norm(samples.x[:, :2], axis=1)
    p0_cauchy = fit_radial_profile(r_current, samples.pressure, w)[1]
    return {
        "P": P,
        "a": exact.a,
        "p0": exact.p0,
        "a_over_h": exact.a / hertz.h_contact,
        "a_error": a / exact.a - 1.0,
        "p0_error": p0 / exact.p0 - 1.0,
        "a_moment_error": float(a_moment) / exact.a - 1.0,
        "p0_node_error": node_max / exact.p0 - 1.0,
        "a_last_error": float(r[_in_contact(problem, pair)].max()) / exact.a - 1.0,
        "pressure_l2_error": float(np.sqrt(np.sum(w * (lam - p) ** 2) / np.sum(w * p**2))),
        "p0_error_cauchy": p0_cauchy / exact.p0 - 1.0,
    }


def _in_contact(problem, pair: int = 0) -> np.ndarray:
    """Mask of the slave points of all ranks in contact (order of ``contact_samples``)."""
    return np.concatenate(problem.comm.allgather(problem.contacts[pair].active()))


def hertz_3d_run(
    h_contact: float,
    steps: int = 2,
    degree: int = 1,
    default_eps: bool = False,
    multiplier_degree: int | str = 1,
    petsc_options: dict | None = None,
    **options,
) -> tuple[dict, ContactProblem]:
    """Solve :func:`~contact_ufl.verification.scenes.hertz_3d` (``options`` passed to it;
    its geometry ``order`` by default the displacement's ``degree``) in ``steps`` load
    steps (``default_eps``: with the library's default ``eps_N`` instead of the scene's
    ``E / h``; ``multiplier_degree``: that of the pair; ``petsc_options``: the solver's,
    recorded as ``petsc_options``); return the record of
    :func:`hertz_3d_errors` with ``degree``, ``multiplier_degree``, ``geometry_order``,
    ``dofs``, ``h_contact``, ``slave_points``, ``newton_iterations``, ``newton_per_step``,
    ``wall_s`` (the solve), ``cpu_s`` (its CPU time), ``search_s`` (its closest-point
    search) and ``ranks``, and the problem."""
    options.setdefault("order", degree)
    hertz = scenes.hertz_3d(h_contact=h_contact, **options)
    pair = dataclasses.replace(hertz.scene.contacts[0], multiplier_degree=multiplier_degree)
    if default_eps:
        pair = dataclasses.replace(pair, eps_N=None)
    hertz.scene.contacts[0] = pair
    problem = ContactProblem(hertz.scene, degree=degree, verbose=False, petsc_options=petsc_options)
    start, cpu = time.perf_counter(), time.process_time()
    problem.solve(num_steps=steps)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    newton = sum(s.newton_iterations for s in problem.history.steps)
    record = {
        "petsc_options": dict(petsc_options or {}),
        "degree": degree,
        "multiplier_degree": multiplier_degree,
        "geometry_order": options["order"],
        "dofs": problem.layout.global_size,
        "h_contact": h_contact,
        "slave_points": len(contact_samples(problem).pressure),
        **hertz_3d_errors(problem, hertz),
        "newton_iterations": newton,
        "newton_per_step": newton / len(problem.history.steps),
        "wall_s": wall,
        "cpu_s": cpu,
        "search_s": problem.search_time,
        "ranks": problem.comm.size,
    }
    return record, problem


# -- the 2D ironing extruded (plane strain in 3D) -------------------------------------------------


def ironing_plane_strain_run(
    mu: float,
    thickness: float | None = 0.1,
    h_punch: float = 0.05,
    h_block: float = 0.2,
    press_steps: int = 20,
    slide_steps: int = 100,
    t_end: float = 2.0,
    master_normal: str = "smoothed",
    verbose: bool = False,
) -> tuple[dict, ContactProblem]:
    """The shallow ironing of :func:`~contact_ufl.verification.scenes.ironing_plane_strain`
    on the quadrilateral plane mesh, in 2D (``thickness=None``) or extruded through
    ``thickness`` (3D, u_z = 0 on both faces), pressed in ``press_steps`` then slid to
    ``t_end`` in ``slide_steps`` (to t = 2: the slide's end); one record per converged step,
    as :func:`ironing_run`, with the forces also per unit thickness: ``fx``, ``fy`` (equal to
    ``Fx``, ``Fy`` in 2D; the 3D ones divided by ``thickness``)."""
    scene = scenes.ironing_plane_strain(
        mu=mu, thickness=thickness, h_punch=h_punch, h_block=h_block, master_normal=master_normal
    )
    stages = [(press_steps, 1.0)] + ([(slide_steps, t_end)] if slide_steps > 0 else [])
    run, problem = _driven_run(scene, "punch_top", stages, verbose)
    per_unit = 1.0 if thickness is None else 1.0 / thickness
    for r in run["history"]:
        r["fx"], r["fy"] = r["Fx"] * per_unit, r["Fy"] * per_unit
    options = {"thickness": thickness, "h_punch": h_punch, "h_block": h_block}
    return {"mu": mu, **options, "master_normal": master_normal, **run}, problem
