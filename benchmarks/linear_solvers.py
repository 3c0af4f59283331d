"""Linear solvers on a saved contact tangent: MUMPS orderings and options, iterative options.

The tangent is written by ``benchmarks/newton_cost.py --dump FILE`` (the contact tangent at
the end of the solve and the index set of its displacement unknowns, PETSc binary). Each
``--solver`` is a set of PETSc options (``KEY=VALUE`` separated by commas; an empty string:
the default MUMPS LU) applied to the tangent ``J`` and, with ``--glued``, to its displacement
block (the glued bodies, see ``newton_cost.py --glued``). A direct solver is analysed once
and factorised ``--repeat`` times; the record has the fastest CPU seconds of a factorisation
on each rank, MUMPS's flops (RINFOG(3), per rank RINFO(3)), factor entries (INFOG(29)) and
memory (INFOG(22), MB). An iterative one (``ksp_type`` other than ``preonly``) records its
iterations, relative residual and CPU seconds of set-up and solve; with ``pc_type
fieldsplit`` the splits are ``u`` (the displacements, block size ``--bs``) and ``lambda``.

    python benchmarks/newton_cost.py --scenes hertz3d --sizes 0.0125 --dump /tmp/J.bin \\
        --json /tmp/cost.json
    [mpirun -n 2] python benchmarks/linear_solvers.py /tmp/J.bin --glued --json out.json \\
        --solver "" "mat_mumps_icntl_7=3" "mat_mumps_icntl_28=2,mat_mumps_icntl_29=1"
"""

import argparse
import json
import os
import time

import numpy as np
import resultfile
from mpi4py import MPI
from petsc4py import PETSc


def load(path: str, comm: MPI.Comm) -> tuple[PETSc.Mat, PETSc.IS, PETSc.IS]:
    """The saved tangent and the index sets of its displacements and other unknowns (this
    rank's rows: those of the saving rank on as many ranks, an even split otherwise)."""
    viewer = PETSc.Viewer().createBinary(path, "r", comm=comm)
    J = PETSc.Mat().create(comm)
    J.setType("aij")
    J.load(viewer)
    saved = PETSc.IS().create(comm)
    saved.load(viewer)
    everything = np.concatenate(comm.allgather(saved.getIndices()))
    starts = PETSc.IS().create(comm)
    try:
        starts.load(viewer)
        starts = np.concatenate(comm.allgather(starts.getIndices()))
    except PETSc.Error:  # a file without the ranks' rows
        starts = np.zeros(0)
    if len(starts) == comm.size:  # the saving ranks' rows: whole nodes on each rank
        n = J.getSize()[0]
        local = int(np.append(starts, n)[comm.rank + 1] - starts[comm.rank])
        viewer = PETSc.Viewer().createBinary(path, "r", comm=comm)
        J = PETSc.Mat().create(comm)
        J.setType("aij")
        J.setSizes(((local, n), (local, n)))
        J.load(viewer)
    start, end = J.getOwnershipRange()
    u = everything[(everything >= start) & (everything < end)]
    rest = np.setdiff1d(np.arange(start, end), u)
    u, rest = (PETSc.IS().createGeneral(i.astype(PETSc.IntType), comm=comm) for i in (u, rest))
    return J, u, rest


def solve(A: PETSc.Mat, options: dict, repeat: int, splits=None) -> dict:
    """Set up and solve ``A x = b`` (b random) with the PETSc ``options``."""
    comm = A.getComm().tompi4py()
    prefix = "linear_solvers_"
    opts = PETSc.Options()
    settings = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
    settings.update(options)
    for k, v in settings.items():
        opts[prefix + k] = v
    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A)
    ksp.setType(settings["ksp_type"])
    ksp.getPC().setType(settings["pc_type"])
    if settings["pc_type"] == "lu":
        ksp.getPC().setFactorSolverType(settings["pc_factor_mat_solver_type"])
    ksp.setFromOptions()
    pc = ksp.getPC()
    if pc.getType() == PETSc.PC.Type.FIELDSPLIT and splits is not None:
        pc.setFieldSplitIS(*splits)
    b = A.createVecLeft()
    b.setRandom()
    x = b.duplicate()
    cpu = time.process_time()
    ksp.setUp()
    setup = time.process_time() - cpu
    direct = settings["ksp_type"] == "preonly"
    factorisations = []
    for _ in range(repeat if direct else 0):
        comm.Barrier()
        cpu = time.process_time()
        ksp.setOperators(A)
        A.assemble()  # a new state of the same matrix: a numeric factorisation only
        pc.setUp()
        factorisations.append(time.process_time() - cpu)
    cpu = time.process_time()
    ksp.solve(b, x)
    solve_cpu = time.process_time() - cpu
    r = b.duplicate()
    A.mult(x, r)
    r.axpy(-1.0, b)
    record = {
        "options": options,
        "unknowns": A.getSize()[0],
        "ranks": comm.size,
        "load": os.getloadavg()[0],
        "setup_cpu_s": comm.allgather(setup),
        "solve_cpu_s": comm.allgather(solve_cpu),
        "iterations": ksp.getIterationNumber(),
        "relative_residual": r.norm() / b.norm(),
    }
    if direct and settings["pc_factor_mat_solver_type"] == "mumps":
        F = pc.getFactorMatrix()
        record |= {
            "factorisation_cpu_s": comm.allgather(min(factorisations)),
            "ordering": F.getMumpsInfog(7),
            "flops": F.getMumpsRinfog(3),
            "rank_flops": comm.allgather(F.getMumpsRinfo(3)),
            "factor_entries": F.getMumpsInfog(29),
            "off_diagonal_pivots": F.getMumpsInfog(12),
            "delayed_pivots": F.getMumpsInfog(13),
            "memory_MB": F.getMumpsInfog(22),
        }
    ksp.destroy()
    for k in settings:
        del opts[prefix + k]
    return record


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("tangent", help="file written by newton_cost.py --dump")
    parser.add_argument("--solver", nargs="+", default=[""], help="KEY=VALUE,KEY=VALUE")
    parser.add_argument("--glued", action="store_true", help="also the displacement block")
    parser.add_argument("--repeat", type=int, default=3, help="numeric factorisations")
    parser.add_argument("--bs", type=int, default=3, help="block size of the displacements")
    parser.add_argument("--json", required=True, help="output file")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    J, u, rest = load(args.tangent, comm)
    matrices = {"contact": J}
    if args.glued:
        matrices["glued"] = J.createSubMatrix(u, u)
    if comm.allreduce(u.getLocalSize() % args.bs, MPI.MAX) == 0:
        u.setBlockSize(args.bs)  # for GAMG
    records = []
    for solver in args.solver:
        options = dict(kv.split("=", 1) for kv in solver.split(",") if kv)
        for name, A in matrices.items():
            if name == "glued" and options.get("pc_type") == "fieldsplit":
                continue  # no multipliers to split
            splits = (("u", u), ("lambda", rest)) if name == "contact" else None
            record = {"matrix": name, **solve(A, options, args.repeat, splits)}
            records.append(record)
            if comm.rank == 0:
                print(json.dumps(record), flush=True)
    if comm.rank == 0:
        resultfile.write(args.json, records)


if __name__ == "__main__":
    main()
