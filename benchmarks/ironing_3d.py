"""3D ironing (large frictional sliding of a die over a slab): Puso & Laursen 2004, example 2.

A Neo-Hookean slab 9 x 4 x 3 (E = 1, nu = 0.3) clamped at its bottom, and a die 1000
times stiffer whose bottom is a cylinder of radius 3 across the slab (5.2 wide, the slab 4):
the die's top is pressed down 1.4 (pseudo-time 0 to 1), then moved 4 along the slab (1 to 2),
with mu = 0 and mu = 0.3; slave surface the slab's top, master the die's cylinder with the
smoothed normal (node fans). (:func:`contact_ufl.verification.scenes.ironing_3d`; the data
are those of the LLNL Smith example ``die-on-slab``, which restates the publication.)

Prints the forces on the die's top and Newton iterations per step, the checks that need no
publication (every step converged; with mu = 0 the mirror symmetry of the slab about its
middle: Fx antisymmetric and Fz symmetric about t = 1.5, the die's middle position; with
mu = 0.3 Coulomb's ratio of the frictional to the normal part of the contact force,
:func:`~contact_ufl.verification.runs.coulomb_ratio_3d`), and what the literature has
(:data:`contact_ufl.verification.literature.IRONING_3D`: curves only, no numbers). Writes
JSON (a list of runs, each with ``mu``, ``history``: records ``time``, ``Fx``, ``Fy``,
``Fz``, ``newton_iterations``, ``converged``, contact force parts, energies; ``cutbacks``,
``wall_s``) and, with ``--png``, the force histories.

    python benchmarks/ironing_3d.py --quick --json benchmarks/results/ironing_3d_quick.json \
        --png docs/ironing_3d_forces.png
"""

import argparse
import time

import resultfile
from mpi4py import MPI

from contact_ufl.verification.literature import IRONING_3D
from contact_ufl.verification.runs import coulomb_ratio_3d, history_at, ironing_3d_run

#: Meshes and steps: ``--quick`` (a few minutes on one core) and the default (not run yet).
QUICK = dict(h_die=0.6, h_slab=0.75, press_steps=10, slide_steps=20)
DEFAULT = dict(h_die=0.4, h_slab=0.5, press_steps=10, slide_steps=40)

#: Pseudo-times at which the forces are printed (the die at x = 2.5 + 4 (t - 1)).
REPORT_TIMES = (0.5, 1.0, 1.25, 1.5, 1.75, 2.0)


def symmetry(history: list[dict]) -> dict:
    """mu = 0: the slab is mirror-symmetric about x = 4.5 and the frictionless elastic
    state depends only on the die's position, so ``Fx(t) = -Fx(3 - t)`` and ``Fz(t) =
    Fz(3 - t)`` over the slide; the mismatches at t = 1 and 2 (the die 2.5 from either
    end), relative to |Fz|, and Fx at t = 1.5 (the middle; zero by symmetry)."""
    fz = abs(history_at(history, 1.0, "Fz"))
    fx1 = [r["Fx"] for r in history if abs(r["time"] - 1.0) < 1e-9][0]
    fx2 = [r["Fx"] for r in history if abs(r["time"] - 2.0) < 1e-9][0]
    mid = min(history, key=lambda r: abs(r["time"] - 1.5))
    return {
        "Fx_antisymmetry": (fx1 + fx2) / fz,
        "Fz_symmetry": (history_at(history, 1.0, "Fz") - history_at(history, 2.0, "Fz")) / fz,
        "Fx_middle": mid["Fx"] / fz,
    }


def plot(runs: list[dict], path: str) -> None:
    """Force histories against the die's travel: Fz and Fx of each mu (the force of the
    support on the die's top), and the Coulomb ratio of the mu > 0 runs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    for run in runs:
        h = run["history"]
        t = [r["time"] for r in h]
        ax.plot(t, [abs(r["Fz"]) for r in h], "o-", ms=3, label=f"|Fz|, mu = {run['mu']:g}")
        ax.plot(t, [r["Fx"] for r in h], "s--", ms=3, label=f"Fx, mu = {run['mu']:g}")
        if run["mu"] > 0:
            ratio = [
                abs(r["contact_friction"][0] / r["contact_normal"][2]) if t_ > 1.0 else None
                for r, t_ in zip(h, t, strict=True)
            ]
            bx.plot(t, ratio, "o-", ms=3, label=f"|F_fric,x / F_normal,z|, mu = {run['mu']:g}")
            bx.plot(t, [abs(r["Fx"] / r["Fz"]) for r in h], "s--", ms=3, label="|Fx / Fz|")
            bx.axhline(run["mu"], color="k", lw=0.8)
    ax.set_xlabel("pseudo-time (pressing 0-1, sliding 4 over 1-2)")
    ax.set_ylabel("force on the die's top")
    ax.legend(fontsize=8)
    bx.set_xlabel("pseudo-time")
    bx.set_ylabel("ratio")
    bx.set_ylim(0.0, 0.5)
    bx.legend(fontsize=8)
    fig.suptitle("3D ironing (Puso & Laursen 2004, ex. 2), quick mesh")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--png", help="write the force histories to this picture")
    parser.add_argument("--quick", action="store_true", help="coarse meshes, larger steps")
    parser.add_argument("--mu", type=float, nargs="+", default=[0.0, 0.3])
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    options = QUICK if args.quick else DEFAULT
    runs = []
    for mu in args.mu:
        start = time.perf_counter()
        run, problem = ironing_3d_run(mu, **options)
        run["wall_s"] = time.perf_counter() - start
        run["search_s"] = problem.search_time
        run["options"] = options
        if mu == 0.0:
            run["symmetry"] = symmetry(run["history"])
        else:
            run["coulomb_ratio"] = coulomb_ratio_3d(run["history"])
        runs.append(run)
        if comm.rank == 0:
            report(run)
    if comm.rank == 0:
        print(f"published force histories: {IRONING_3D['status']}")
        resultfile.write(args.json, runs)
        if args.png:
            plot(runs, args.png)


def report(run: dict) -> None:
    """Print one run: totals, forces at :data:`REPORT_TIMES`, Newton per step, checks."""
    steps = run["history"]
    its = [r["newton_iterations"] for r in steps]
    print(
        f"mu = {run['mu']}: {run['unknowns']} unknowns, {len(steps)} steps, "
        f"{len(run['cutbacks'])} cut-backs, all converged: {all(r['converged'] for r in steps)}, "
        f"Newton {sum(its)} (per step {min(its)}-{max(its)}), "
        f"wall {run['wall_s']:.0f} s (search {run['search_s']:.1f} s)"
    )
    print(f"{'t':>6} {'x_die':>6} {'Fx':>9} {'Fy':>9} {'Fz':>9} {'|Fx/Fz|':>8} {'newton':>6}")
    for t in REPORT_TIMES:
        r = min(steps, key=lambda r: abs(r["time"] - t))
        x_die = 2.5 + r["top_displacement"][0]
        print(
            f"{r['time']:6.3f} {x_die:6.2f} {r['Fx']:9.4f} {r['Fy']:9.4f} {r['Fz']:9.4f} "
            f"{abs(r['Fx'] / r['Fz']):8.4f} {r['newton_iterations']:6d}"
        )
    if "symmetry" in run:
        s = run["symmetry"]
        print(
            f"mirror symmetry (mu = 0), relative to |Fz|: Fx(1) + Fx(2) = "
            f"{s['Fx_antisymmetry']:+.2e}, Fz(1) - Fz(2) = {s['Fz_symmetry']:+.2e}, "
            f"Fx(1.5) = {s['Fx_middle']:+.2e}"
        )
    if "coulomb_ratio" in run:
        print(
            f"steady sliding (1.5 <= t <= 1.9): |F_fric,x / F_normal,z| = "
            f"{run['coulomb_ratio']:.4f} (Coulomb: mu = {run['mu']})"
        )


if __name__ == "__main__":
    main()
