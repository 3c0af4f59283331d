"""The 2D shallow ironing solved on a 3D mesh in plane strain (issue #13, item 2).

The published large-sliding benchmark with published force histories (the shallow ironing
of Yang, Laursen & Meng 2005; :data:`~contact_ufl.verification.literature.IRONING_FORCES`)
run by the 3D machinery: the plane quadrilateral mesh of the 2D problem extruded through a
thickness by one layer of hexahedra, u_z = 0 on both faces z = 0 and z = thickness, so that
the 3D solution is the plane-strain one
(:func:`contact_ufl.verification.scenes.ironing_plane_strain`): 3D closest points on
bilinear quadrilaterals, the 3D smoothed master normal (node fans), Coulomb friction in 3D.
The same geometry, materials, loading and mu as benchmarks/ironing.py (the punch pressed 1
over t = 0-1, slid 10 over t = 1-2), mu = 0 and mu = 0.3.

For each mu the script solves the problem twice on the same plane mesh, in 2D
(``thickness=None``) and extruded, and prints: the steps, cut-backs and Newton iterations of
each, that every step converged, the wall times; the force history per unit thickness of the
extruded run against the 2D one (the largest difference over the history, relative to the
largest |fy|: the two differ only by the smoothed normal's nodal averaging, equal weights in
2D, facet areas in 3D: with the facet normal they agree to the solver's tolerance as far as
the 2D run gets with it, ``--normal facet`` stopping near t = 1.11 on this mesh); and,
with mu = 0.3, the forces at t = 1 and t = 1.5 and |fx/fy| in steady sliding against every
published source and their spread (``IRONING_FORCES``, ``IRONING_LITERATURE``). Writes JSON:
a list of runs, each with ``mu``, ``thickness`` (``null``: the 2D run), ``history``
(records ``time``, ``Fx``, ``Fy`` [, ``Fz``], ``fx``, ``fy`` per unit thickness,
``newton_iterations``, ``converged``, ...), ``cutbacks``, ``wall_s``; the JSON is written
after every mu. (The fx columns printed for the extruded run are interpolated at the 2D
run's times where a cut-back made their steps differ.)

    python benchmarks/ironing_plane_strain.py --quick \
        --json benchmarks/results/ironing_plane_strain_quick.json
"""

import argparse
import time

import numpy as np
import resultfile
from mpi4py import MPI

from contact_ufl.verification.literature import IRONING_FORCES, IRONING_LITERATURE
from contact_ufl.verification.runs import history_at, ironing_plane_strain_run, steady_ratio

#: Meshes and steps: ``--quick`` (the quick mesh of benchmarks/ironing.py) and the default
#: (its default mesh; not run yet: the 3D run would take hours on this machine).
QUICK = dict(h_punch=0.05, h_block=0.2, press_steps=20, slide_steps=100)
DEFAULT = dict(h_punch=0.025, h_block=0.1, press_steps=20, slide_steps=200)

#: Thickness of the extruded layer (the forces are compared per unit thickness).
THICKNESS = 0.1


def difference(plane: list[dict], extruded: list[dict]) -> dict:
    """The largest differences between the forces per unit thickness of the extruded run
    and the 2D one at the pseudo-times both reached (a cut-back in one of them puts extra
    steps in it), relative to the largest |fy|; the number of those times; and the largest
    |Fz| (the force across the plane; nil in plane strain) relative to |Fy|."""
    at = {round(r["time"], 9): r for r in plane}
    common = [(at[round(r["time"], 9)], r) for r in extruded if round(r["time"], 9) in at]
    scale = max(abs(r["fy"]) for r in plane)
    return {
        "fx": max(abs(a["fx"] - b["fx"]) for a, b in common) / scale,
        "fy": max(abs(a["fy"] - b["fy"]) for a, b in common) / scale,
        "common_times": len(common),
        "Fz": max(abs(b["Fz"]) for b in extruded) / (scale * THICKNESS),
    }


def published(history: list[dict]) -> list[dict]:
    """|fy|, |fx| at t = 1.0 and 1.5 against each source of :data:`IRONING_FORCES` (mu = 0.3)."""
    rows = []
    for k, t in enumerate((1.0, 1.5)):
        for j, key in enumerate(("fy", "fx")):
            values = {source: forces[k][j] for source, forces in IRONING_FORCES.items()}
            rows.append(
                {"time": t, "force": key, "here": history_at(history, t, key), "sources": values}
            )
    return rows


def summary(run: dict) -> str:
    """Steps, cut-backs, Newton iterations (total and per step), convergence, wall time."""
    steps = run["history"]
    its = [r["newton_iterations"] for r in steps]
    where = "2D" if run["thickness"] is None else f"extruded (thickness {run['thickness']})"
    return (
        f"  {where}: {run['unknowns']} unknowns, {len(steps)} steps, {len(run['cutbacks'])} "
        f"cut-backs, every step converged: {all(r['converged'] for r in steps)}, Newton "
        f"{sum(its)} ({min(its)}-{max(its)} per step, mean {np.mean(its):.1f}), wall "
        f"{run['wall_s']:.0f} s"
    )


def report(mu: float, plane: dict, extruded: dict) -> None:
    """Print one mu: both runs, their difference, the forces against the publications."""
    print(f"mu = {mu}, master normal {extruded['master_normal']}:")
    print(summary(plane))
    print(summary(extruded))
    d = extruded["difference_to_2d"]
    print(
        f"  extruded - 2D per unit thickness, largest over the history / max|fy|: "
        f"fx {d['fx']:.2e}, fy {d['fy']:.2e} (at the {d['common_times']} times both reached); "
        f"max|Fz| / (max|fy| t) {d['Fz']:.1e}"
    )
    for run in (plane, extruded):
        where = "2D" if run["thickness"] is None else "3D"
        for c in run["cutbacks"]:
            print(f"  cut-back ({where}) at t = {c['time']}: {c['reason']}; {c['why']}")
    print(f"  {'t':>5} {'|fx| 2D':>11} {'|fx| 3D':>11} {'|fy| 2D':>11} {'|fy| 3D':>11}")
    pair = (plane, extruded)
    steps = len(plane["history"])
    for a in plane["history"][:: steps // 12]:
        t = a["time"]
        f = [history_at(run["history"], t, key) for key in ("fx", "fy") for run in pair]
        print(f"  {t:5.2f} {f[0]:11.4e} {f[1]:11.4e} {f[2]:11.4e} {f[3]:11.4e}")
    if mu != 0.3:
        return
    print("  against the published forces (mu = 0.3; IRONING_FORCES, read off the curves):")
    for row in extruded["published"]:
        values = list(row["sources"].values())
        inside = min(values) <= row["here"] <= max(values)
        print(
            f"  |{row['force']}|({row['time']}) here {row['here']:.4e} (2D "
            f"{history_at(plane['history'], row['time'], row['force']):.4e}); published "
            f"{min(values):.4e} - {max(values):.4e} (spread {max(values) / min(values) - 1:.0%})"
            f", {'inside' if inside else 'OUTSIDE'}"
        )
        for source, value in row["sources"].items():
            print(f"      {value:.4e}  {source}")
    ratios = list(IRONING_LITERATURE.values())
    print(
        f"  steady |fx/fy| (1.2 <= t <= 1.7): here {extruded['steady_abs_fx_over_fy']:.4f} "
        f"(2D {plane['steady_abs_fx_over_fy']:.4f}); published at t = 1.5: "
        f"{min(ratios):.2f} - {max(ratios):.2f} ({len(ratios)} sources)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--quick", action="store_true", help="coarse meshes, larger steps")
    parser.add_argument("--mu", type=float, nargs="+", default=[0.0, 0.3])
    parser.add_argument("--normal", default="smoothed", choices=["smoothed", "facet"])
    args = parser.parse_args()
    options = QUICK if args.quick else DEFAULT
    runs = []
    for mu in args.mu:
        pair = []
        for thickness in (None, THICKNESS):
            start = time.perf_counter()
            run, problem = ironing_plane_strain_run(
                mu, thickness=thickness, master_normal=args.normal, **options
            )
            run["wall_s"] = time.perf_counter() - start
            run["search_s"] = problem.search_time
            run["options"] = options
            run["held_multipliers"] = problem.comm.allreduce(problem.held_multipliers)
            run["steady_abs_fx_over_fy"] = steady_ratio(run["history"])
            pair.append(run)
        plane, extruded = pair
        extruded["difference_to_2d"] = difference(plane["history"], extruded["history"])
        if mu == 0.3:
            extruded["published"] = published(extruded["history"])
        runs += pair
        if MPI.COMM_WORLD.rank == 0:
            report(mu, plane, extruded)
            resultfile.write(args.json, runs)  # after every mu: a long run keeps what it made


if __name__ == "__main__":
    main()
