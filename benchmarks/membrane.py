"""The inflated tube between two rigid plates under refinement (a membrane slave on a rigid
obstacle), against the closed form of
:func:`contact_ufl.verification.analytic.tube_between_plates`.

The quarter model of ``tests/test_membrane_contact.py``: a Neo-Hookean tube (``mu = 1``,
``t0 = 0.01``, ``R0 = 1``) inflated by a follower pressure to half its limit pressure, then
pressed by a frictionless rigid plate from 1.02 to 0.8 times its free radius (10 steps);
in 2D a string ring quarter (``n`` intervals), in 3D a quarter of a long tube at axial
stretch 1 (``n`` quadrilaterals around, ``n // 8`` along its length 0.1).

One JSON record per mesh: ``dim``, ``n``, ``h`` (reference cell size around), ``unknowns``,
``newton_max`` and ``newton_mean`` (Newton iterations per step), ``cutbacks``, the relative
errors ``width_error`` (contact width, see below), ``width_active_error`` (the extent of the
points in contact), ``pressure_error`` (the largest deviation of the current contact pressure
``lambda_N / (da/dA)`` from the inflation pressure over the points in contact within 3/4 of
the flat zone's half width; ``_pressure_error`` of the tests) and ``force_error`` (plate
force against ``p w``), ``wall_s`` (the solve) and ``search_s`` (the closest-point search).

The contact width. The free arc leaves the plate tangentially, so the gap grows only
quadratically away from the edge of the zone, ``g = d^2 / (2 r)`` at a distance ``d``: a
node two cells (``h = 0.014``, ``n = 128``) from the edge is off the plate by 1e-4, no more
than the nodes of the flat zone wiggle about it there (measured 2e-5), so "the first node
off the plate" is ill-defined and a gap threshold picks the edge to within several cells.
The extent of the points in contact (``width_active_error``) is an edge known only to the
spacing of the quadrature points (the pressure jumps from ``p`` to 0 there). Instead, the
width is read off the free arc: a circle (centre and radius fitted by least squares, Kasa's
algebraic fit) through the deformed nodes of the free arc clear of the edge (gap above
``0.02 r``); where that circle meets the plate tangentially, at its centre's ``x``, the
string leaves the plate: ``w / 2 = x_c``. The closed form's free arc is a half circle of
radius ``r`` centred at ``(w/2, 0)``; the fitted radius's error (``arc_radius_error``) is
reported too. The width and force errors agree (measured, to three digits): the vertical
balance of the quarter's upper part gives the plate force ``p (x_c + rho) - T`` for a free arc
of radius ``rho = T / p``, that is ``p x_c``, so the two differ only by how far the free
arc is from a circle.

Newton iterations. After first contact the residual falls by about the same amount at every
iteration, not quadratically: the edge of the contact zone advances by a fraction of a cell
per iteration (the string next to the zone leaves the plate tangentially, so each iterate
activates only the points that its predecessor pushed through), and the iterations per step
grow with the number of cells the edge crosses in a step, about in proportion to ``n`` at a
fixed number of steps (max 6 at n = 16, 21 at n = 512). At ``n = 1024`` with 10 steps the
steps need more than SNES's 25 iterations and are cut back (7 cut-backs); use more steps
(``--steps``) on fine meshes.

    python benchmarks/membrane.py --json benchmarks/results/membrane.json [--quick]
    mpirun -n 2 python benchmarks/membrane.py --json ...
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import resultfile
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.verification import analytic, scenes

MU, T0, R0, LENGTH = 1.0, 0.01, 1.0, 0.1
FULL = {2: [16, 32, 64, 128, 256, 512, 1024], 3: [16, 32, 64, 128]}
QUICK = {2: [16, 32, 64, 128], 3: [16, 32]}
CLEAR = 0.02  # free-arc nodes used by the circle fit: gap above CLEAR r


def solve(dim: int, n: int, steps: int) -> tuple:
    """The quarter tube pressed by the plate: the solved problem, its schedule, the plate
    and the solve's wall time."""
    p = 0.5 * MU * T0 / R0
    free = analytic.tube_free_radius(MU, T0, R0, p)
    schedule = scenes.PlatesSchedule(p, 1.02 * free, 0.8 * free)
    n_axial = max(n // 8, 1)
    tube = scenes.tube_for_plates(schedule, dim=dim, n=n, length=LENGTH, n_axial=n_axial)
    plate = schedule.plate(dim)
    scene = cu.Scene(domains=[tube], contacts=[cu.ContactPair("tube", plate)])
    problem = cu.ContactProblem(scene, verbose=False)
    start = time.perf_counter()
    problem.solve(num_steps=steps)
    return problem, schedule, plate, time.perf_counter() - start


def deformed_nodes(problem: cu.ContactProblem) -> np.ndarray:
    """Current positions ``(x, y)`` of the tube's nodes, all ranks (every rank)."""
    bulk = problem.bulks[0]
    dim = problem.gdim
    owned = bulk.V.dofmap.index_map.size_local
    x = bulk.V.tabulate_dof_coordinates()[:owned, :dim]
    x = x + bulk.u.x.array.reshape(-1, dim)[:owned]
    return np.concatenate(problem.comm.allgather(x[:, :2]))


def circle_fit(x: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre and radius of the circle fitted to the points ``x`` ``(n, 2)`` (Kasa: least
    squares of ``|x|^2 - 2 c.x - (r^2 - |c|^2)``)."""
    A = np.column_stack([2.0 * x, np.ones(len(x))])
    b = np.sum(x**2, axis=1)
    (cx, cy, k), *_ = np.linalg.lstsq(A, b, rcond=None)
    return np.array([cx, cy]), float(np.sqrt(k + cx**2 + cy**2))


def pressure_error(problem: cu.ContactProblem, p: float, width: float) -> float:
    """Largest relative deviation of ``lambda_N / (da/dA)`` from ``p`` over the points in
    contact with ``x < 3/4 w/2``."""
    (c,) = problem.contacts
    x = c.slave.positions(c.u).reshape(-1, problem.gdim)[:, 0]
    pressure = c.multiplier_at_points() / c.slave.area_ratio(c.u).ravel()
    inner = c.active() & (x < 0.75 * width / 2)
    error = np.abs(pressure[inner] / p - 1.0).max(initial=0.0)
    return problem.comm.allreduce(error, MPI.MAX)


def active_extent(problem: cu.ContactProblem) -> float:
    """The largest current ``x`` of the slave points in contact (all ranks)."""
    (c,) = problem.contacts
    x = c.slave.positions(c.u).reshape(-1, problem.gdim)[:, 0][c.active()]
    return problem.comm.allreduce(x.max(initial=-np.inf), MPI.MAX)


def run(dim: int, n: int, steps: int) -> dict:
    """Solve one mesh and measure it against the closed form."""
    problem, schedule, plate, wall = solve(dim, n, steps)
    r, p = schedule.r_end, schedule.pressure
    exact = analytic.tube_between_plates(MU, T0, R0, p, r)
    w = float(exact["width"])
    nodes = deformed_nodes(problem)
    arc = nodes[r - nodes[:, 1] > CLEAR * r]
    centre, radius = circle_fit(arc)
    depth = LENGTH if dim == 3 else 1.0
    force = -problem.obstacle_reaction(plate)[1] / (0.5 * p * w * depth)  # quarter: w / 2
    iterations = np.array([s.newton_iterations for s in problem.history.steps])
    return {
        "dim": dim,
        "n": n,
        "h": float(np.pi / 2 * R0 / n),
        "unknowns": int(problem.layout.global_size),
        "steps": len(iterations),
        "cutbacks": len(problem.history.cutbacks),
        "newton_max": int(iterations.max()),
        "newton_mean": float(iterations.mean()),
        "width_exact": w,
        "width_error": float(2.0 * centre[0] / w - 1.0),
        "width_active_error": float(2.0 * active_extent(problem) / w - 1.0),
        "arc_radius_error": float(radius / r - 1.0),
        "pressure_error": float(pressure_error(problem, p, w)),
        "force_error": float(force - 1.0),
        "wall_s": wall,
        "search_s": float(problem.search_time),
        "ranks": problem.comm.size,
    }


HEADER = (
    f"{'dim':>3} {'n':>4} {'unknowns':>8} {'newton':>10} {'width err':>10} {'active err':>10} "
    f"{'arc r err':>10} {'p err':>9} {'force err':>10} {'wall s':>7} {'search s':>8}"
)


def row(r: dict) -> str:
    newton = f"{r['newton_max']}/{r['newton_mean']:.1f}"
    return (
        f"{r['dim']:3d} {r['n']:4d} {r['unknowns']:8d} {newton:>10} {r['width_error']:+10.2e} "
        f"{r['width_active_error']:+10.2e} {r['arc_radius_error']:+10.2e} "
        f"{r['pressure_error']:9.2e} {r['force_error']:+10.2e} {r['wall_s']:7.2f} "
        f"{r['search_s']:8.3f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--quick", action="store_true", help="coarser meshes (< 1 min)")
    parser.add_argument("--steps", type=int, default=10, help="load steps")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    meshes = QUICK if args.quick else FULL
    if comm.rank == 0:
        print("newton: max/mean Newton iterations per step; errors relative", flush=True)
        print(HEADER, flush=True)
    records = []
    for dim, sizes in meshes.items():
        for n in sizes:
            records.append(run(dim, n, args.steps))
            if comm.rank == 0:
                print(row(records[-1]), flush=True)
    if comm.rank == 0:
        resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
