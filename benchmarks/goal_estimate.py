"""Effectivity of the normal contact force's error estimate (:mod:`contact_ufl.goal`).

The estimate of ``problem.normal_force_error()`` (dual-weighted residuals, the dual in the
degree-2 displacement) against the true error of the force ``J = int lambda_N dS_o``, on
meshes refined uniformly (every cell, the disc's new nodes on its circle) from a start:

* ``hertz_2d``: the 2D Hertz scene of ``tests/test_goal.py`` (neo-Hookean, depth 0.02 R in
  2 steps, ``h_contact = 0.02``, ``h_far = 0.2``);
* ``hertz_2d_linear``: the Hertz benchmark's scene (linear elastic, depth 0.005 in one
  step, the default eps, graded to ``h_contact = 0.01`` within 0.1 R).

On each mesh: the P1 solve, its force and the estimate; the P2 solve on the same mesh and
its force (what the estimate predicts to first order). The true force is the limit of the
P2 forces extrapolated from the three meshes (Richardson, their observed ratio of
differences); ``limit_p1`` is that of the P1 forces, and ``effectivity_p1`` the
effectivity against it (the two limits differ by 3e-6 of the force on the neo-Hookean
scene, 2.3e-4 on the linear one). Each record: case, level, unknowns (P1, P2), the
forces, the estimate, its consistency part, ``ratio`` (P2 change over the estimate),
``effectivity`` (estimate over true error) and the wall times of the P1 solve, the
estimate and the P2 solve.

    python benchmarks/goal_estimate.py --json benchmarks/results/goal_estimate.json

One rank.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import resultfile
from adaptive import hertz_scene, onto_circle

import contact_ufl as cu
from contact_ufl import goal, refinement
from contact_ufl.verification import scenes


def _cases(name: str) -> tuple[cu.Scene, int]:
    """The starting scene of ``name`` and its load steps."""
    if name == "hertz_2d":
        return scenes.hertz_2d(h_contact=0.02, h_far=0.2, depth=0.02).scene, 2
    _, scene = hertz_scene(0.01, 0.005, order=1, refine_radius=0.1)
    return scene, 1


def _solve(scene: cu.Scene, degree: int, steps: int) -> tuple[cu.ContactProblem, float]:
    start = time.perf_counter()
    problem = cu.ContactProblem(scene, degree=degree, verbose=False)
    problem.solve(num_steps=steps)
    return problem, time.perf_counter() - start


def _limit(values: list[float]) -> float:
    """Richardson's limit of the last three ``values`` of a sequence of halved meshes, with
    their observed ratio of differences."""
    a, b, c = values[-3:]
    ratio = (b - a) / (c - b)
    return c + (c - b) / (ratio - 1.0)


def run(name: str, levels: int) -> list[dict]:
    """The records of case ``name`` on ``levels + 1`` meshes."""
    scene, steps = _cases(name)
    records = []
    for level in range(levels + 1):
        p1, wall = _solve(scene, 1, steps)
        start = time.perf_counter()
        estimate = p1.normal_force_error()
        estimate_s = time.perf_counter() - start
        p2, wall_p2 = _solve(scene, 2, steps)
        force_p2 = goal.normal_force(p2)
        records.append(
            {
                "case": name,
                "level": level,
                "unknowns": p1.layout.global_size,
                "unknowns_p2": p2.layout.global_size,
                "force": estimate.value,
                "estimate": estimate.error,
                "consistency": estimate.consistency,
                "force_p2": force_p2,
                "ratio": (force_p2 - estimate.value) / estimate.error,
                "wall_s": wall,
                "estimate_s": estimate_s,
                "wall_p2_s": wall_p2,
            }
        )
        print(records[-1], flush=True)
        p1.close()
        p2.close()
        if level < levels:
            tdim = scene.parts[0].mesh.topology.dim
            every = [
                np.arange(d.mesh.topology.index_map(tdim).size_local, dtype=np.int32)
                for d in scene.parts
            ]
            scene = refinement.refine_scene(scene, every, {"cylinder_contact": onto_circle})
    limit = _limit([r["force_p2"] for r in records])
    limit_p1 = _limit([r["force"] for r in records])
    for r in records:
        r["limit"], r["limit_p1"] = limit, limit_p1
        r["true_error"] = limit - r["force"]
        r["effectivity"] = r["estimate"] / r["true_error"]
        r["effectivity_p1"] = r["estimate"] / (limit_p1 - r["force"])
    return records


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--levels", type=int, default=2, help="uniform refinements")
    parser.add_argument("--cases", nargs="+", default=["hertz_2d", "hertz_2d_linear"])
    args = parser.parse_args()
    records = [r for name in args.cases for r in run(name, args.levels)]
    resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
