"""Newton iterations with the facet and the smoothed master normal on curved 3D masters.

The curved pairs of :func:`~contact_ufl.verification.scenes.curved_pair` (tetrahedra: a half
cylinder on a cylindrical top; hexahedra: the warped boxes, a saddle) with the lower body's
bottom held and the upper body's top pressed down and slid over the master surface.

    python benchmarks/smoothed_normal_3d.py --json benchmarks/results/smoothed_normal_3d.json
"""

import argparse
import dataclasses
import time

import resultfile
from mpi4py import MPI

from contact_ufl.errors import ConvergenceError
from contact_ufl.loads import Dirichlet
from contact_ufl.problem import ContactProblem
from contact_ufl.verification.scenes import curved_pair

#: the motion of the upper body's top at pseudo-time t = 1: pressed down, slid along x and y
TOP_MOTION = (0.15, 0.1, -0.06)


def run(cell: str, master_normal: str, num_steps: int) -> dict:
    scene = curved_pair(3, cell=cell)
    pair = dataclasses.replace(scene.contacts[0], master_normal=master_normal)
    supports = [
        Dirichlet(scene.tags["lower_bottom"], (0.0, 0.0, 0.0)),
        Dirichlet(scene.tags["upper_top"], lambda t: tuple(t * c for c in TOP_MOTION)),
    ]
    scene = dataclasses.replace(scene, contacts=[pair], dirichlet=supports)
    problem = ContactProblem(scene, verbose=False)
    start = time.perf_counter()
    try:
        problem.solve(num_steps=num_steps)
        status = "completed"
    except ConvergenceError:
        status = "stopped"
    history = problem.history
    records = history.steps
    return {
        "cell": cell,
        "master_normal": master_normal,
        "status": status,
        "t_reached": problem.t,
        "nodes_per_point": problem.contacts[0].kinematics.nx,
        "newton_per_step": [r.newton_iterations for r in records],
        "newton_total": sum(r.newton_iterations for r in records),
        "cutbacks": len(history.cutbacks),
        "active_points": problem.active_points(),
        "wall_s": time.perf_counter() - start,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--steps", type=int, default=5)
    args = parser.parse_args()
    records = [
        run(cell, normal, args.steps)
        for cell in ("tetrahedron", "hexahedron")
        for normal in ("facet", "smoothed")
    ]
    if MPI.COMM_WORLD.rank == 0:
        for r in records:
            print(
                f"{r['cell']:12} {r['master_normal']:8} nx={r['nodes_per_point']:3d} "
                f"{r['status']} t={r['t_reached']:.4g} "
                f"newton={r['newton_per_step']} total={r['newton_total']} "
                f"cutbacks={r['cutbacks']} "
                f"active={r['active_points']} wall={r['wall_s']:.1f}s"
            )
        resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
