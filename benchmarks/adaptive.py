"""Speed against error of adaptive refinement, against uniform refinement and hand-graded
meshes: the 2D Hertz problem of ``benchmarks/hertz.py`` (linear elastic, one load step, the
default eps) from a coarse mesh.

Each level of the loop (:func:`contact_ufl.refine_to_tolerance`) writes a record: unknowns,
the estimate and its relative value, the errors of p0 and a (nominal: the multiplier at the
reference positions, as the small-strain Hertz solution compares; *recovered*: of the
pressure recovered from the bulk, :func:`contact_ufl.results.recovered_pressure`), the
pressure L2 error,
Newton iterations, the level's solve-and-estimate time ``wall_s`` and the loop's time so far
``cumulative_s`` (solves, estimates, marking, refinement, the problems' set-up). ``uniform``
records refine every cell at each level instead (``theta = 1``).

    python benchmarks/adaptive.py --json benchmarks/results/adaptive.json [--quick]
        [--degree 2] [--start 0.04] [--max-unknowns 60000]
    python benchmarks/adaptive.py --dim 3 --json ...

``--case cattaneo``: Cattaneo-Mindlin (the 2D scene with mu = 0.3, pressed in 4 steps,
then moved sideways in 4; every mesh replays them): the stick zone's half-width and the
shear traction against Johnson 7.1.

``--goal normal_force``: the loop driven by the estimated error of the normal contact
force (:func:`contact_ufl.goal.normal_force_error`) instead of the energy norm's estimate
(2D Hertz, P1). Every 2D Hertz record has the force and its error against the limit that
``benchmarks/goal_estimate.py`` measured for this scene (``force``, ``force_error``).

``--load-steps N``: Cattaneo-Mindlin pressed in N steps and moved in N (the Newton
iterations of a step against the size of the step).

``--case plastic``: the plastic indentation scene (a stiff half disc pressed by 0.02 into
a perfectly plastic block in 8 steps and lifted off in 8; every mesh replays them): the
imprint's depth, which has no closed form; the estimate and the Newton iterations.

``--dim 3``: the quarter ball on a block of the 3D Hertz benchmark (linear elastic, one
step, depth 0.01, the default eps) from ``h_contact = 0.05``; the errors of
:func:`contact_ufl.verification.runs.hertz_3d_errors` (p0 and a nominal).
"""

import argparse
import dataclasses
import functools
import time
from pathlib import Path

import numpy as np
import resultfile
from hertz import hertz_2d_errors
from mpi4py import MPI

from contact_ufl import ContactProblem, adapt, goal
from contact_ufl.materials import LinearElastic
from contact_ufl.results import contact_samples, lowest_displacement, stick_zone_half_width
from contact_ufl.verification import scenes
from contact_ufl.verification.analytic import CattaneoMindlin2D, Hertz2D, fit_elliptic_profile
from contact_ufl.verification.runs import hertz_3d_errors, shear_error

#: the results files
RESULTS = Path(__file__).parent / "results"

#: the disc of the 2D Hertz scene
CENTRE = np.array([0.0, 1.0, 0.0])


def onto_circle(x: np.ndarray) -> np.ndarray:
    d = x - CENTRE
    return CENTRE + d / np.linalg.norm(d, axis=1)[:, None]


#: the 3D ball: radius 1, centre (0, 0, 1)
CENTRE_3D = np.array([0.0, 0.0, 1.0])


def onto_sphere(x: np.ndarray) -> np.ndarray:
    d = x - CENTRE_3D
    return CENTRE_3D + d / np.linalg.norm(d, axis=1)[:, None]


def hertz_3d_setup(h: float, depth: float):
    """The 3D quarter ball on a block (linear elastic), the default eps; its errors, its
    curved boundary."""
    hertz = scenes.hertz_3d(h_contact=h, depth=depth, h_far=0.25)
    scene = hertz.scene
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=None)

    def errors(problem) -> dict:
        e = hertz_3d_errors(problem, hertz)
        keys = ("p0_error", "a_error", "pressure_l2_error", "p0_error_cauchy", "a")
        return {"p0_error_nominal": e["p0_error"], "a_error_nominal": e["a_error"]} | {
            k: e[k] for k in keys
        }

    return scene, errors, {"sphere_contact": onto_sphere}


def cattaneo_setup(h: float, depth: float, refine_radius: float = 0.3):
    """Cattaneo-Mindlin: the 2D Hertz scene with mu = 0.3 pressed by ``depth`` in 4 steps,
    then moved sideways by 0.0015 in 4; the stick zone's half-width and the shear traction
    against Johnson 7.1 at the last step."""
    mu = 0.3
    hertz = scenes.hertz_2d(
        h_contact=h, depth=depth, mu=mu, shift=0.0015, refine_radius=refine_radius
    )
    scene = hertz.scene

    def errors(problem) -> dict:
        force = problem.history.steps[-1].contact_force
        exact = CattaneoMindlin2D(Hertz2D(force[1], hertz.radius, hertz.E_star), abs(force[0]), mu)
        c = stick_zone_half_width(problem)
        return {
            "stick_zone_error": c / exact.c - 1.0,
            "shear_error": shear_error(problem, exact),
            "Q_over_muP": abs(force[0]) / (mu * force[1]),
        }

    return scene, errors, {"cylinder_contact": onto_circle}


def plastic_setup(h: float, depth: float):
    """The plastic indentation scene (depth 0.02, whatever ``depth``): the imprint's depth,
    the curved boundary."""
    scene = scenes.plastic_indentation(h_contact=h)

    def errors(problem) -> dict:
        return {"imprint": -lowest_displacement(problem, "block_contact")}

    return scene, errors, {"cylinder_contact": onto_circle}


def hertz_2d_setup(h: float, depth: float):
    """The 2D scene, its errors and curved boundary."""
    hertz, scene = hertz_scene(h, depth)
    return scene, lambda problem: hertz_errors(problem, hertz), {"cylinder_contact": onto_circle}


#: the hand-graded meshes (h_contact) by case and degree: Hertz's are those of the Hertz
#: benchmark's graded tables
GRADED = {
    ("hertz", 1): (0.01, 0.0075, 0.005, 0.0035, 0.0025, 0.00175),
    ("hertz", 2): (0.03, 0.025, 0.02, 0.015, 0.01, 0.0075),
    ("cattaneo", 1): (0.01, 0.005, 0.0025, 0.00125),
}


def hertz_scene(h: float, depth: float, order: int = 1, refine_radius: float = 0.3):
    """The benchmark's 2D Hertz scene: linear elastic, the default eps."""
    hertz = scenes.hertz_2d(h_contact=h, depth=depth, order=order, refine_radius=refine_radius)
    scene = hertz.scene
    scene.contacts[0] = dataclasses.replace(scene.contacts[0], eps_N=None)
    scene.bodies = [
        dataclasses.replace(b, material=LinearElastic(b.material.E, b.material.nu))
        for b in scene.bodies
    ]
    return hertz, scene


def force_limit() -> float:
    """The limit of the normal contact force of the 2D Hertz scene under refinement, as
    ``benchmarks/goal_estimate.py`` measured it (its ``hertz_2d_linear`` case: the same
    geometry, material, eps and depth)."""
    records = resultfile.load(RESULTS / "goal_estimate.json")
    (limit,) = {r["limit"] for r in records if r["case"] == "hertz_2d_linear"}
    return limit


def hertz_errors(problem, hertz) -> dict:
    """The errors of :func:`hertz.hertz_2d_errors`, and those of the pressure recovered from
    the bulk (p0 and a of its fitted profile, nominal)."""
    c = problem.contacts[0]
    X = np.concatenate(problem.comm.allgather(c.slave.X.reshape(-1, 2)))
    recovered = contact_samples(problem, recovered=True).lambda_N
    a_recovered, p0_recovered, _ = fit_elliptic_profile(X[:, 0], recovered)
    exact = Hertz2D(problem.contact_force()[1], hertz.radius, hertz.E_star)
    force = goal.normal_force(problem)
    return hertz_2d_errors(problem, hertz) | {
        "p0_error_recovered": p0_recovered / exact.p0 - 1.0,
        "a_error_recovered": a_recovered / exact.a - 1.0,
        "force": force,
        "force_error": force / force_limit() - 1.0,
    }


#: the load steps of each phase of a case's load path (``--load-steps`` changes them)
LOAD_STEPS = {"hertz": 1, "cattaneo": 4, "plastic": 8}


def solve_load_path(problem, case: str) -> None:
    """The load path of ``case``: Hertz in one step; Cattaneo-Mindlin pressed in 4 steps,
    then moved sideways in 4; the plastic indentation pressed in 8 and lifted off in 8."""
    steps = LOAD_STEPS[case]
    if case in ("plastic", "cattaneo"):
        problem.solve(num_steps=steps, t_end=1.0)
        problem.solve(num_steps=steps, t_end=2.0)
    else:
        problem.solve(num_steps=1)


def run_graded(case: str, depth: float, degree: int) -> list[dict]:
    """The hand-graded sweep: each mesh of :data:`GRADED` (the zone of size h within 0.1
    R) built, set up and solved through the load path, from the coarsest."""
    records = []
    begin = time.perf_counter()
    for h in GRADED[case, degree]:
        if case == "cattaneo":
            scene, errors, _ = cattaneo_setup(h, depth, refine_radius=0.1)
        else:
            hertz, scene = hertz_scene(h, depth, order=degree, refine_radius=0.1)
            errors = functools.partial(hertz_errors, hertz=hertz)
        problem = ContactProblem(scene, degree=degree, verbose=False)
        start = time.perf_counter()
        solve_load_path(problem, case)
        wall = time.perf_counter() - start
        steps = problem.history.steps
        records.append(
            {
                "kind": "graded",
                "case": case,
                "dim": 2,
                "degree": degree,
                "h_contact": h,
                "dofs": problem.layout.global_size,
                "newton_iterations": sum(r.newton_iterations for r in steps),
                "newton_per_step": sum(r.newton_iterations for r in steps) / len(steps),
                "newton_max": max(r.newton_iterations for r in steps),
                "load_steps": len(steps),
                "wall_s": wall,
                "cumulative_s": time.perf_counter() - begin,
                "ranks": problem.comm.size,
                **errors(problem),
            }
        )
        r = records[-1]
        if problem.comm.rank == 0:
            print(
                f"graded   {r['dofs']:8d} newton {r['newton_iterations']} "
                f"(max {r['newton_max']} a step) wall {wall:.2f} s "
                f"cumulative {r['cumulative_s']:.2f} s",
                flush=True,
            )
    return records


def _errors_text(record: dict, case: str) -> str:
    """A record's errors as the benchmark prints them."""
    if case == "cattaneo":
        return f"stick zone {record['stick_zone_error']:+.3%} shear {record['shear_error']:.3f} "
    if case == "plastic":
        return f"imprint {record['imprint']:.5f} "
    return (
        f"p0 {record['p0_error_nominal']:+.3%} a {record['a_error_nominal']:+.3%} "
        f"L2 {record['pressure_l2_error']:.3f} "
    )


def run(
    kind: str,
    start_h: float,
    depth: float,
    degree: int,
    max_unknowns: int,
    theta: float,
    dim: int = 2,
    case: str = "hertz",
    goal_name: str | None = None,
) -> list[dict]:
    """The levels of one loop: ``kind`` ``"adaptive"`` (Doerfler, ``theta``) or
    ``"uniform"`` (every cell refined), of ``case`` ``"hertz"``, ``"cattaneo"`` or
    ``"plastic"``."""
    setup = {
        (2, "hertz"): hertz_2d_setup,
        (3, "hertz"): hertz_3d_setup,
        (2, "plastic"): plastic_setup,
    }.get((dim, case), cattaneo_setup)
    scene, errors, boundaries = setup(start_h, depth)

    def solve(problem) -> None:
        solve_load_path(problem, case)

    records = []
    begin = time.perf_counter()

    def record(problem, level) -> None:
        records.append(
            {
                "kind": kind,
                "case": case,
                "dim": dim,
                "degree": degree,
                "start_h": start_h,
                "level": len(records),
                "dofs": level.unknowns,
                "cells": level.cells,
                "estimate": level.estimate,
                "relative_estimate": level.relative,
                "newton_iterations": level.newton_iterations,
                "newton_per_step": level.newton_iterations / len(problem.history.steps),
                "newton_max": max(r.newton_iterations for r in problem.history.steps),
                "load_steps": len(problem.history.steps),
                "start": level.start,
                "wall_s": level.wall,
                "cumulative_s": time.perf_counter() - begin,
                "ranks": problem.comm.size,
                "goal": goal_name or "energy",
                **errors(problem),
            }
        )
        r = records[-1]
        if problem.comm.rank == 0:
            print(
                f"{kind:8s} {r['dofs']:8d} eta {r['relative_estimate']:.3e} "
                + _errors_text(r, case)
                + f"newton {r['newton_iterations']} (max {r['newton_max']} a step) "
                f"wall {r['wall_s']:.2f} s cumulative {r['cumulative_s']:.2f} s",
                flush=True,
            )

    adapt.refine_to_tolerance(
        scene,
        solve,
        tolerance=1e-9,
        max_unknowns=max_unknowns,
        theta=1.0 if kind == "uniform" else theta,
        max_levels=30,
        boundaries=boundaries,
        problem_options={"degree": degree, "verbose": False},
        on_level=record,
        goal=goal_name,
    )
    return records


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--quick", action="store_true", help="to 15,000 unknowns")
    parser.add_argument("--degree", type=int, choices=(1, 2), default=1)
    parser.add_argument("--dim", type=int, choices=(2, 3), default=2)
    parser.add_argument("--case", choices=("hertz", "cattaneo", "plastic"), default="hertz")
    parser.add_argument("--start", type=float, default=None, help="h_contact (0.04, 3D 0.05)")
    parser.add_argument("--depth", type=float, default=None, help="0.005, 3D 0.01")
    parser.add_argument("--theta", type=float, default=0.5)
    parser.add_argument("--max-unknowns", type=int, default=None)
    parser.add_argument("--load-steps", type=int, default=None, help="steps of each phase")
    parser.add_argument("--goal", choices=("normal_force",), default=None)
    args = parser.parse_args()
    if args.load_steps is not None:
        LOAD_STEPS[args.case] = args.load_steps
    budget = args.max_unknowns or (15_000 if args.quick else 120_000)
    start = args.start or (0.04 if args.dim == 2 else 0.05)
    depth = args.depth or (0.005 if args.dim == 2 else 0.01)
    records = []
    for kind in ("adaptive", "uniform"):
        records += run(
            kind, start, depth, args.degree, budget, args.theta, args.dim, args.case, args.goal
        )
    if (args.case, args.degree) in GRADED and args.dim == 2 and not args.quick:
        records += run_graded(args.case, depth, args.degree)
    if MPI.COMM_WORLD.rank == 0:
        resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
