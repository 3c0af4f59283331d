"""The cost of a Newton iteration and its parts, with contact and without (issue 12, item 4).

Solves each scene with :class:`~contact_ufl.problem.ContactProblem` and reads the solver's
:class:`~contact_ufl.timings.NewtonTimings` (seconds on rank 0, reset after the solver is
made, so the set-up is not counted):

* 2D Hertz (:func:`contact_ufl.verification.scenes.hertz_2d`, P1, depth 0.02 in two load
  steps), ``h_contact`` from 0.02 down to 0.0025;
* 3D two-beam scene (:func:`contact_ufl.verification.scenes.beams`, hexahedra, three load
  steps to a third of the demo's load);
* 3D Hertz, sphere on a block (:func:`contact_ufl.verification.scenes.hertz_3d`, P1
  tetrahedra, two load steps), ``h_contact`` 0.025 and 0.0125 (the benchmark's meshes;
  ``--sizes 0.00625 0.0045`` gives the 50,000 and 115,000 unknowns of README's tables).

Each scene is solved again as a *bulk* problem on the same mesh with the contact pair removed
(Hertz: the disc's arc, or the sphere's cap, held fixed instead, so the body is squeezed;
beams: the upper beam bends freely). The bulk problem still goes through the contact
solver, whose ``T`` is then the identity; its per-iteration cost counted here is residual
assembly + Jacobian assembly + linear solve (the identity PtAP and the empty search, which a
plain bulk Newton does not do, are left out). The ratio is contact / bulk seconds per Newton
iteration (issue 12's target: at most 1.3 at 100,000 unknowns in 2D and at the largest 3D size).

    python benchmarks/newton_cost.py --json benchmarks/results/newton_cost.json [--quick]
        [--repeat N] [--scenes hertz beams hertz3d] [--sizes ...] [--glued]
        [--ranks 1 2] [--option KEY=VALUE ...] [--partition bodies|graph]

``--glued`` adds the fair baseline of a contact scene (issue 12's bulk problem with the
bodies *coupled*, not free): the bodies glued where the contact pairs them. Its tangent is
the displacement block of the contact tangent at the end of the solve (the slave points
tied to their master facets: the pattern of a penalty tie at every paired point, the same
couplings between the bodies, no multipliers); the record ``case = "glued"`` has the bulk
record's residual and Jacobian assembly and the factorisation and solve of that block,
timed as the contact tangent's own factorisation and solve (``tangent_*`` in the contact
record: one analysis, then ``--repeat``-fold numeric factorisations, MUMPS's flops
RINFOG(3) and factor entries INFOG(29)), so that contact and glued are timed alike. The
contact record adds ``glued_ratio`` (its ``total_s`` over the glued ``bulk_s``) and
``factor_ratio`` (its tangent's factorisation flops over the glued block's).

``--ranks 1 2`` runs every case under ``mpirun -n k`` for each k, interleaved ``--repeat``
times (the fastest run of each is kept), and writes all records with ``speedup`` (wall time
of the solve on one rank over that on k ranks) and ``per_rank`` (each rank's parts, its
slave points and its share of the rows and nonzeros of ``K`` and ``T``: where the work is).
``--partition graph`` distributes the meshes with DOLFINx's graph partition (whole bodies on
ranks) instead of the default that splits every body over all ranks
(:mod:`contact_ufl.partition`); the records say which (``partition``).
``--option`` passes PETSc options to the solver (e.g. ``mat_mumps_icntl_7=3``);
``--field-split`` solves with the package's
:data:`~contact_ufl.newton.FIELD_SPLIT_PETSC_OPTIONS` (``--option`` on top of them; the bulk
case, which has no multipliers, takes its ``u`` split's GAMG on the whole); ``--dump
FILE`` writes the contact tangent at the end of the solve for ``benchmarks/linear_solvers.py``
(orderings, MUMPS options, iterative solvers on it).

The machine may be loaded: ``--repeat N`` solves each bulk / contact pair N times,
interleaved, and keeps the fastest run of each (least disturbed); the process CPU time is
recorded beside the wall times, and the load average at the start of each run.

Records: ``scene``, ``size`` (h_contact or divisions), ``case`` (``contact`` or ``bulk``),
``dofs``, ``newton_iterations``, ``new_patterns`` (Jacobians on a new pairing: a symbolic
PtAP), ``analyses`` (symbolic analyses of the factorisation: the solver matrix's pattern was
new or grew), ``residuals`` (residual evaluations, line searches' included), ``wall_s``,
``cpu_s`` (process CPU time of the solve), ``load`` (1-minute load average at the start),
``peak_rss_MB`` (each rank's largest resident memory so far: the cases run in order, bulk
then contact, smaller sizes first)
and, per Newton iteration, ``total_s`` (SNES time), ``search_s``,
``residual_assembly_s``, ``jacobian_assembly_s``, ``ptap_s``, ``linear_solve_s``,
``analysis_s`` and ``factorisation_s`` (PETSc's ``MatLUFactorSym`` and ``MatLUFactorNum``
events: MUMPS's analysis and numeric factorisation, inside ``linear_solve_s``), ``cpu_per_it_s``
and ``bulk_s`` (residual + Jacobian assembly + linear solve), ``solution_norm`` (of the unknowns:
the same answers on any number of ranks) and ``contact_force``; contact records add ``ratio``
(their ``total_s`` over the bulk record's ``bulk_s``) and ``cpu_ratio`` (their
``cpu_per_it_s`` over the bulk record's).
"""

import argparse
import dataclasses
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
import resultfile
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl.gmshio import PARTITION_VARIABLE
from contact_ufl.loads import Dirichlet
from contact_ufl.newton import FIELD_SPLIT_PETSC_OPTIONS
from contact_ufl.partition import PARTITIONS
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes

HERTZ_FULL = [0.02, 0.01, 0.005, 0.0025]
HERTZ_QUICK = [0.02, 0.01]
BEAMS_FULL = [3, 4]
BEAMS_QUICK = [3]
HERTZ3D_FULL = [0.025, 0.0125]
HERTZ3D_QUICK = [0.025]
PARTS = ("search", "residual_assembly", "jacobian_assembly", "ptap", "linear_solve")


def hertz(h: float, contact: bool):
    """The 2D Hertz scene, or its bulk counterpart (no contact, the arc held fixed)."""
    scene = scenes.hertz_2d(h_contact=h, depth=0.02).scene
    if not contact:
        arc = Dirichlet(scene.tags["cylinder_contact"], (0.0, 0.0))
        scene = dataclasses.replace(scene, contacts=[], dirichlet=[*scene.dirichlet, arc])
    return scene, 2, 1.0


def beams(divisions: int, contact: bool):
    """The two-beam scene (a third of the demo's load), or the same without contact."""
    scene = scenes.beams(divisions=divisions).scene
    if not contact:
        scene = dataclasses.replace(scene, contacts=[])
    return scene, 3, 1.0 / 3.0


def hertz3d(h: float, contact: bool):
    """The 3D Hertz scene, or its bulk counterpart (no contact, the sphere's cap held fixed)."""
    scene = scenes.hertz_3d(h_contact=h).scene
    if not contact:
        cap = Dirichlet(scene.tags["sphere_contact"], (0.0, 0.0, 0.0))
        scene = dataclasses.replace(scene, contacts=[], dirichlet=[*scene.dirichlet, cap])
    return scene, 2, 1.0


MAKERS = {"hertz": hertz, "beams": beams, "hertz3d": hertz3d}
FACTOR_EVENTS = {"analysis": "MatLUFactorSym", "factorisation": "MatLUFactorNum"}


def _event_seconds() -> dict[str, float]:
    """Seconds so far in PETSc's factorisation events (this rank)."""
    return {k: PETSc.Log.Event(e).getPerfInfo()["time"] for k, e in FACTOR_EVENTS.items()}


def _factorise(A: PETSc.Mat, options: dict, repeat: int) -> dict:
    """Analyse ``A`` once with MUMPS LU (the solver's options), factorise it ``repeat`` times
    and solve with it: the fastest wall and CPU seconds of a factorisation (this rank), of
    a solve, and MUMPS's flops and factor entries."""
    comm = A.getComm().tompi4py()
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    pc.setFactorSolverType("mumps")
    opts = PETSc.Options()
    prefix = "newton_cost_factor_"
    ksp.setOptionsPrefix(prefix)
    mumps = {k: v for k, v in options.items() if k.startswith("mat_mumps_")}
    for k, v in mumps.items():
        opts[prefix + k] = v
    ksp.setFromOptions()
    b = A.createVecLeft()
    b.set(1.0)
    x = b.duplicate()
    start = time.perf_counter()
    ksp.setUp()
    first = time.perf_counter() - start
    walls, cpus = [], []
    for _ in range(repeat):
        comm.Barrier()
        cpu, start = time.process_time(), time.perf_counter()
        A.assemble()  # a new state of the same matrix: a numeric factorisation only
        ksp.setOperators(A)
        pc.setUp()
        walls.append(time.perf_counter() - start)
        cpus.append(time.process_time() - cpu)
    comm.Barrier()
    cpu, start = time.process_time(), time.perf_counter()
    ksp.solve(b, x)
    solve, solve_cpu = time.perf_counter() - start, time.process_time() - cpu
    F = pc.getFactorMatrix()
    out = {
        "first_setup_s": first,
        "factorisation_s": min(walls),
        "factorisation_cpu_s": min(cpus),
        "solve_s": solve,
        "solve_cpu_s": solve_cpu,
        "flops": F.getMumpsRinfog(3),
        "factor_entries": F.getMumpsInfog(29),
        "rank_flops": comm.allgather(F.getMumpsRinfo(3)),
    }
    for k in mumps:
        del opts[prefix + k]
    ksp.destroy()
    return out


def displacement_block(problem: ContactProblem) -> PETSc.Mat:
    """The displacement block (the meshes' displacements, no multipliers) of the contact
    tangent at the current state: the bodies tied where the contact pairs them."""
    J = problem.operator.evaluate_jacobian(problem.operator.x)
    layout = problem.layout
    rows = [layout.owned(b, np.arange(layout.local_sizes[b])) for b in range(len(problem.bulks))]
    index = PETSc.IS().createGeneral(np.concatenate(rows).astype(PETSc.IntType), comm=problem.comm)
    return J.createSubMatrix(index, index)


def glued(problem: ContactProblem, options: dict, repeat: int) -> tuple[dict, dict]:
    """The factorisations of the contact tangent and of its displacement block (the glued
    bodies), timed alike (see the module's ``--glued``)."""
    J = problem.operator.evaluate_jacobian(problem.operator.x)
    tangent = _factorise(J, options, repeat)
    G = displacement_block(problem)
    block = _factorise(G, options, repeat)
    block["dofs"] = G.getSize()[0]
    G.destroy()
    return tangent, block


def _nonzeros(A: PETSc.Mat | None) -> int:
    """This rank's nonzeros of ``A`` (0 for none)."""
    return 0 if A is None else int(A.getInfo(PETSc.Mat.InfoType.LOCAL)["nz_used"])


def _per_rank(problem: ContactProblem, cpu: float, timings) -> list[dict]:
    """Each rank's parts (seconds per Newton iteration), CPU seconds of the solve, slave
    points, and share of the rows and nonzeros of ``K`` (the gathered blocks, through
    ``T^T K T``), ``A`` (the unknowns' blocks, assembled straight) and ``T``: where the work
    is."""
    operator = problem.operator
    local = PETSc.Mat.InfoType.LOCAL
    n = max(timings.iterations, 1)
    mine = {
        "rank": problem.comm.rank,
        "cpu_s": cpu,
        **{f"{k}_s": v for k, v in timings.per_iteration().items()},
        "search_own_s": sum(c.search_time for c in problem.contacts) / n,
        "slave_points": int(sum(len(c.projection.facet) for c in problem.contacts)),
        "unknowns": problem.layout.local_size,
        "K_rows": operator._gathered_tangent.getLocalSize()[0]
        if operator._gathered_tangent is not None
        else 0,
        "K_nonzeros": _nonzeros(operator._gathered_tangent),
        "A_nonzeros": _nonzeros(operator._unknown_blocks),
        "T_nonzeros": int(operator._T.getInfo(local)["nz_used"]),
        "J_nonzeros": int(operator.matrix.getInfo(local)["nz_used"]),
    }
    return problem.comm.allgather(mine)


def save_tangent(problem: ContactProblem, path: str) -> None:
    """Write the contact tangent at the current state and the index set of its displacement
    unknowns (PETSc binary; read by ``benchmarks/linear_solvers.py``)."""
    J = problem.operator.evaluate_jacobian(problem.operator.x)
    layout = problem.layout
    rows = [layout.owned(b, np.arange(layout.local_sizes[b])) for b in range(len(problem.bulks))]
    index = PETSc.IS().createGeneral(np.concatenate(rows).astype(PETSc.IntType), comm=problem.comm)
    start = np.array([J.getOwnershipRange()[0]], dtype=PETSc.IntType)
    viewer = PETSc.Viewer().createBinary(path, "w", comm=problem.comm)
    J.view(viewer)
    index.view(viewer)
    PETSc.IS().createGeneral(start, comm=problem.comm).view(viewer)  # the ranks' rows
    viewer.destroy()


def _peak_rss_mb() -> float:
    """The largest resident memory of this process so far, in MB (Linux: KB units)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def run(
    make,
    size,
    contact: bool,
    options: dict | None = None,
    glue: int = 0,
    dump: str = "",
    eps: str = "scene",
) -> dict:
    """Solve one scene and return its record (``glue``: with the glued baseline, its
    factorisations repeated ``glue`` times; ``dump``: write the contact tangent there;
    ``eps``: ``"scene"``, each scene's eps_N (E / h), or ``"default"``, the package's)."""
    scene, steps, t_end = make(size, contact)
    if eps == "default":  # the package's default eps_N (E / L) instead of the scene's E / h
        pairs = [dataclasses.replace(p, eps_N=None) for p in scene.contacts]
        scene = dataclasses.replace(scene, contacts=pairs)
    options = options or {}  # a field split is the u split's preconditioner without contact
    problem = ContactProblem(scene, verbose=False, petsc_options=options)
    timings = problem.solver.timings
    timings.reset()
    load = os.getloadavg()[0]
    events = _event_seconds()
    cpu = time.process_time()
    start = time.perf_counter()
    problem.solve(num_steps=steps, t_end=t_end)
    wall = time.perf_counter() - start
    cpu = time.process_time() - cpu
    events = {k: v - events[k] for k, v in _event_seconds().items()}
    per = timings.per_iteration()
    n = max(timings.iterations, 1)
    record = {
        "scene": make.__name__,
        "size": size,
        "case": "contact" if contact else "bulk",
        "dofs": problem.layout.global_size,
        "newton_iterations": timings.iterations,
        "new_patterns": timings.new_patterns,
        "analyses": timings.analyses,
        "residuals": timings.residuals,
        "wall_s": wall,
        "cpu_s": cpu,
        "load": load,
        "total_s": per["total"],
        **{f"{name}_s": per[name] for name in PARTS},
        **{f"{name}_s": t / n for name, t in events.items()},
        "cpu_per_it_s": cpu / n,
        "bulk_s": per["residual_assembly"] + per["jacobian_assembly"] + per["linear_solve"],
        "ranks": problem.comm.size,
        "options": options,
        "partition": os.environ.get(PARTITION_VARIABLE, "bodies"),
        "eps": eps,
        "solution_norm": problem.solver.x.norm(),  # the same answers on any number of ranks
        "contact_force": [float(f) for f in problem.contact_force()] if contact else None,
        "peak_rss_MB": problem.comm.allgather(_peak_rss_mb()),
    }
    record["per_rank"] = _per_rank(problem, cpu, timings)
    if dump and contact:
        save_tangent(problem, dump)
    if glue and contact:
        record["tangent"], record["glued"] = glued(problem, options, glue)
    elif glue:  # the bulk tangent timed alike, to be replaced by the glued block's
        J = problem.operator.evaluate_jacobian(problem.operator.x)
        record["tangent"] = _factorise(J, options, glue)
    return record


def fastest(records: list[dict]) -> dict:
    """The record of least CPU time per iteration (the least disturbed run), with the
    spread of that time over the runs."""
    best = dict(min(records, key=lambda r: r["cpu_per_it_s"]))
    best["runs"] = len(records)
    best["cpu_per_it_max_s"] = max(r["cpu_per_it_s"] for r in records)
    return best


COLUMNS = (*PARTS, "analysis", "factorisation")


def row(r: dict) -> str:
    """A line of the table (milliseconds per Newton iteration)."""
    ratios = " ".join(f"{r[k]:6.2f}" if k in r else f"{'':>6}" for k in ("ratio", "cpu_ratio"))
    return (
        f"{r['scene']:>7} {r['size']:7g} {r['case']:>7} {r['dofs']:8d} "
        f"{r['newton_iterations']:4d} {r['new_patterns']:4d} {r['analyses']:4d} "
        f"{1e3 * r['total_s']:7.1f} "
        + " ".join(f"{1e3 * r[p + '_s']:8.1f}" for p in COLUMNS)
        + f" {1e3 * r['cpu_per_it_s']:7.1f} {r['load']:5.2f} {ratios}"
    )


def glued_record(with_contact: dict, bulk: dict) -> dict:
    """The glued baseline's record: the bulk record's times with its tangent's
    factorisation and solve replaced by the glued block's (all timed alike by
    :func:`_factorise`; wall and CPU seconds); sets the contact record's ``glued_ratio``,
    ``glued_cpu_ratio`` and ``factor_ratio`` (flops)."""
    block, tangent = with_contact["glued"], with_contact["tangent"]
    free = bulk["tangent"]
    linear = block["factorisation_s"] + block["solve_s"]
    linear_cpu = block["factorisation_cpu_s"] + block["solve_cpu_s"]
    free_linear = free["factorisation_s"] + free["solve_s"]
    free_cpu = free["factorisation_cpu_s"] + free["solve_cpu_s"]
    record = {
        **{k: bulk[k] for k in ("scene", "size", "load", "ranks", "options")},
        "case": "glued",
        "dofs": block["dofs"],
        "newton_iterations": bulk["newton_iterations"],
        "new_patterns": 0,
        "analyses": 0,
        "total_s": bulk["total_s"] - free_linear + linear,
        **{f"{p}_s": 0.0 for p in PARTS},
        "residual_assembly_s": bulk["residual_assembly_s"],
        "jacobian_assembly_s": bulk["jacobian_assembly_s"],
        "linear_solve_s": bulk["linear_solve_s"] - free_linear + linear,
        "analysis_s": 0.0,
        "factorisation_s": block["factorisation_s"],
        "cpu_per_it_s": bulk["cpu_per_it_s"] - free_cpu + linear_cpu,
        "bulk_s": bulk["bulk_s"] - free_linear + linear,
        "flops": block["flops"],
        "factor_entries": block["factor_entries"],
    }
    tangent_linear = tangent["factorisation_s"] + tangent["solve_s"]
    with_contact["glued_ratio"] = with_contact["total_s"] / record["bulk_s"]
    with_contact["glued_cpu_ratio"] = with_contact["cpu_per_it_s"] / record["cpu_per_it_s"]
    with_contact["factor_ratio"] = tangent["flops"] / block["flops"]
    with_contact["factor_time_ratio"] = tangent_linear / linear
    return record


def _arguments() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--quick", action="store_true", help="two 2D sizes, one 3D each")
    parser.add_argument("--repeat", type=int, default=1, help="interleaved runs per case")
    parser.add_argument("--scenes", nargs="+", default=list(MAKERS), choices=list(MAKERS))
    parser.add_argument("--sizes", nargs="+", type=float, help="sizes (default: the scene's)")
    parser.add_argument("--glued", action="store_true", help="add the glued baseline")
    parser.add_argument("--ranks", nargs="+", type=int, help="run under mpirun -n k for each k")
    parser.add_argument("--option", nargs="*", default=[], help="PETSc options KEY=VALUE")
    parser.add_argument(
        "--field-split", action="store_true", help="the package's FIELD_SPLIT_PETSC_OPTIONS"
    )
    parser.add_argument("--partition", choices=PARTITIONS, default="bodies", help="mesh partition")
    parser.add_argument("--eps", choices=("scene", "default"), default="scene", help="eps_N")
    parser.add_argument("--dump", default="", help="write the contact tangent (last size)")
    return parser.parse_args()


def _by_ranks(args: argparse.Namespace) -> None:
    """Run the cases under ``mpirun -n k`` for each k of ``--ranks``, interleaved, and
    write their records with the speed-up of each over one rank."""
    mpirun = os.path.join(os.path.dirname(sys.executable), "mpirun")
    rest, skip = [], False  # the arguments of each run: not --ranks, --repeat, --json
    for a in sys.argv[1:]:
        if a.startswith("--"):
            skip = a in ("--ranks", "--repeat", "--json")
        if not skip:
            rest.append(a)
    runs: dict[int, list[list[dict]]] = {k: [] for k in args.ranks}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):
            for k in args.ranks:
                out = os.path.join(tmp, f"n{k}.json")
                command = [mpirun, "-n", str(k), sys.executable, __file__, *rest, "--json", out]
                subprocess.run(command, check=True)
                runs[k].append(resultfile.load(out))
    records = []
    for k in args.ranks:
        for j in range(len(runs[k][0])):
            records.append(fastest([r[j] for r in runs[k]]))
    one = {(r["scene"], r["size"], r["case"]): r for r in records if r["ranks"] == 1}
    for r in records:
        base = one.get((r["scene"], r["size"], r["case"]))
        if base is not None and "wall_s" in r:
            r["speedup"] = base["wall_s"] / r["wall_s"]
            r["cpu_speedup"] = base["cpu_per_it_s"] / r["cpu_per_it_s"]
    for r in records:
        print(f"{r['ranks']:2d} " + row(r) + f" {r.get('speedup', float('nan')):6.2f}")
    resultfile.write(args.json, records, ranks=args.ranks)


def main() -> None:
    args = _arguments()
    os.environ[PARTITION_VARIABLE] = args.partition  # read by every mesh made (and mpirun's)
    if args.ranks:
        _by_ranks(args)
        return
    options = dict(o.split("=", 1) for o in args.option)
    if args.field_split:
        options = FIELD_SPLIT_PETSC_OPTIONS | options
    PETSc.Log.begin()
    sizes = {
        "hertz": HERTZ_QUICK if args.quick else HERTZ_FULL,
        "beams": BEAMS_QUICK if args.quick else BEAMS_FULL,
        "hertz3d": HERTZ3D_QUICK if args.quick else HERTZ3D_FULL,
    }
    cases = [(MAKERS[name], args.sizes or sizes[name]) for name in args.scenes]
    rank0 = MPI.COMM_WORLD.rank == 0
    header = (
        f"{'scene':>7} {'size':>7} {'case':>7} {'dofs':>8} {'its':>4} {'new':>4} {'ana':>4} "
        f"{'ms/it':>7} "
        + " ".join(f"{p[:8]:>8}" for p in COLUMNS)
        + f" {'cpu/it':>7} {'load':>5} {'ratio':>6} {'cpu_r':>6}"
    )
    if rank0:
        print(header, flush=True)
    records = []
    glue = 3 if args.glued else 0
    for make, sizes in cases:
        for size in sizes:
            size = int(size) if make is beams else size
            runs = [
                (
                    run(make, size, False, options, glue, eps=args.eps),
                    run(make, size, True, options, glue, args.dump, args.eps),
                )
                for _ in range(args.repeat)
            ]
            bulk = fastest([b for b, _ in runs])
            with_contact = fastest([c for _, c in runs])
            with_contact["ratio"] = with_contact["total_s"] / bulk["bulk_s"]
            with_contact["cpu_ratio"] = with_contact["cpu_per_it_s"] / bulk["cpu_per_it_s"]
            rows = [with_contact, bulk]
            if args.glued:
                rows.append(glued_record(with_contact, bulk))
            for r in rows:
                records.append(r)
                if rank0:
                    print(row(r), flush=True)
            if rank0 and args.glued:
                print(
                    f"  glued: ratio {with_contact['glued_ratio']:.2f} (cpu "
                    f"{with_contact['glued_cpu_ratio']:.2f}), factorisation flops contact / "
                    f"glued {with_contact['factor_ratio']:.2f}, time "
                    f"{with_contact['factor_time_ratio']:.2f}",
                    flush=True,
                )
    if rank0:
        resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
