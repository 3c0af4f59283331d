"""Checkpoints and restart: a run continued from a checkpoint ends where the run never
stopped ends (consistency): bit for bit on one rank, to the run-to-run spread of the
distributed direct solver on two, and to solver tolerance on another number of ranks; on
the frictional ironing (slip references), a plastic indentation (quadrature-point history)
and a membrane inflated by its volume against a plane (the pressure unknown).
"""

from __future__ import annotations

import dataclasses
import re
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from conftest import across_ranks
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.control import VolumeControl
from contact_ufl.errors import ContactInputError
from contact_ufl.verification import scenes

#: two runs of MUMPS on two ranks differ in the last bits (measured: 1e-16 relative in a
#: solve, up to 1.1e-13 of the largest unknown after the ironing's 14 steps, the same code
#: and input): restarts there agree to that spread (the final state, of forces and norms)
SPREAD = 1e-12
#: SNES stops at rtol 1e-9: runs on different numbers of ranks may stop an iterate apart
#: (measured: 1e-15 relative in the forces)
ACROSS_RANKS = 1e-8
SOURCE = "the same run never stopped"


def _ironing(comm):
    return scenes.ironing(mu=0.3, h_punch=0.05, h_block=0.2, comm=comm)


def _plastic(comm):
    return scenes.plastic_indentation(h_contact=0.02, comm=comm)


def _balloon(comm):
    """The inflated sphere octant (coarse), its volume controlled, against a rigid plane."""
    (domain,) = scenes.inflated_sphere(n=8, comm=comm).domains
    growth = 1.3**3 - 1.0
    control = VolumeControl("membrane", lambda t: 1.0 + growth * t)
    domain = dataclasses.replace(domain, loads=[control])
    plane = cu.RigidPlane((0.0, 0.0, 1.12), (0.0, 0.0, -1.0))
    return cu.Scene(domains=[domain], contacts=[cu.ContactPair("membrane", plane, mu=0.3)])


#: scene, the solves (num_steps, t_end), the checkpoint restarted from, and its description
CASES = {
    "ironing": (_ironing, [(10, 1.0), (4, 1.08)], 9, "2D frictional ironing, mu = 0.3, quick"),
    "plastic": (_plastic, [(3, 1.0), (3, 2.0)], 4, "plastic indentation, in and out"),
    "balloon": (_balloon, [(6, 1.0)], 4, "balloon under volume control on a plane, mu = 0.3"),
}


#: the folders a test made: (path, whether its ranks share it), removed after the test
_MADE: list[tuple[Path, bool]] = []


@pytest.fixture(autouse=True)
def _remove_folders():
    _MADE.clear()
    yield
    MPI.COMM_WORLD.barrier()  # every rank done with them
    for path, shared in _MADE:
        if not shared or MPI.COMM_WORLD.rank == 0:
            shutil.rmtree(path, ignore_errors=True)


def _own_folder() -> Path:
    """A new folder of this rank."""
    path = Path(tempfile.mkdtemp(prefix="contact_ufl_restart_"))
    _MADE.append((path, False))
    return path


def _shared_folder(comm) -> Path:
    """A new folder, the same on every rank of ``comm``."""
    name = tempfile.mkdtemp(prefix="contact_ufl_restart_") if comm.rank == 0 else None
    path = Path(comm.bcast(name, root=0))
    _MADE.append((path, comm.size > 1))
    return path


def _problem(case: str, comm) -> cu.ContactProblem:
    options = {"snes_max_it": 40}
    return cu.ContactProblem(CASES[case][0](comm), verbose=False, petsc_options=options)


def _run(case: str, comm, folder: Path | None, restart: int | None = None, every: int = 1):
    problem = _problem(case, comm)
    if restart is not None:
        problem.restart(folder, restart)
    checkpoints = None if folder is None else cu.Checkpoints(folder, every=every, keep=None)
    for num_steps, t_end in CASES[case][1]:
        problem.solve(num_steps=num_steps, t_end=t_end, checkpoint=checkpoints)
    return problem


def _state(problem) -> dict[str, np.ndarray]:
    """This rank's unknowns and histories."""
    state = {"x": problem.solver.x.array.copy()}
    for b in problem.bulks:
        for tag, h in b.histories.items():
            state[f"Cp_inv {tag}"] = h.Cp_inv.x.array.copy()
            state[f"alpha {tag}"] = h.alpha.x.array.copy()
    return state


def _records(problem) -> list[tuple]:
    return [(s.step, s.t, s.newton_iterations, s.active_points) for s in problem.history.steps]


@pytest.mark.serial  # on two ranks: test_restart_on_any_number_of_ranks
@pytest.mark.parametrize("case", list(CASES))
def test_restart_continues_the_run(case, verification):
    """A problem made anew and restarted from a checkpoint in the middle of the run (the
    friction's slip references, the plastic history, the pressure unknown, the schedule of
    the solve under way all from the checkpoint) ends in the state of the run that wrote it,
    bit for bit, with the same step records (one rank)."""
    comm = MPI.COMM_WORLD
    folder = _shared_folder(comm)
    whole = _run(case, comm, folder)
    restart = CASES[case][2]
    # writing checkpoints leaves the results those of the last step
    assert np.array_equal(whole.contact_force(), whole.history.steps[-1].contact_force)
    # the script run again from the top, restarted: it writes its checkpoints again
    restarted = _run(case, comm, folder, restart=restart)
    t = whole.history.steps[restart - 1].t
    assert restarted.restored_from == (folder / f"step_{restart:06d}", restart, t)
    assert _records(restarted) == _records(whole)
    assert len(restarted.history.steps) == len(whole.history.steps)
    reference, state = _state(whole), _state(restarted)
    worst = 0.0
    for name, values in reference.items():
        scale = max(np.abs(values).max(initial=0.0), 1e-300)
        worst = max(worst, np.abs(state[name] - values).max(initial=0.0) / scale)
    worst = comm.allreduce(worst, op=MPI.MAX)
    quantity = f"largest relative difference of the unknowns and histories, from step {restart}"
    verification(CASES[case][3], quantity, worst, 0.0, 0.0, SOURCE, kind="consistency")
    assert worst == 0.0
    whole.close()
    restarted.close()


def _summary(problem) -> dict[str, np.ndarray]:
    """Quantities of the final state that do not depend on the partition: the contact
    force, the norm of each displacement, the sum of each history's equivalent plastic
    strain over its points, the controls' pressures."""
    comm = problem.comm
    summary = {"contact force": problem.contact_force()}
    for k, b in enumerate(problem.bulks):
        owned = b.V.dofmap.index_map.size_local * b.V.dofmap.index_map_bs
        summary[f"|u_{k}|"] = np.sqrt(comm.allreduce(np.sum(b.u.x.array[:owned] ** 2)))
        for tag, h in b.histories.items():
            points = h.alpha.function_space.dofmap.index_map.size_local
            summary[f"sum alpha {tag}"] = comm.allreduce(h.alpha.x.array[:points].sum())
    for k, control in enumerate(problem.controls):
        summary[f"pressure {k}"] = control.pressure
    return summary


def _difference(problem, reference) -> float:
    """The largest relative difference of the :func:`_summary` quantities."""
    ours, theirs = _summary(problem), _summary(reference)
    worst = 0.0
    for name, value in theirs.items():
        scale = max(np.abs(value).max(), 1e-300)
        worst = max(worst, np.abs(np.asarray(ours[name]) - value).max() / scale)
    return worst


@across_ranks
@pytest.mark.parametrize("case", list(CASES))
def test_restart_on_any_number_of_ranks(case, verification):
    """Checkpoints written on one rank restart on two, and those of two ranks on one (and,
    for the ironing, on two); the restarted runs end in the state of the run never stopped
    (contact force, displacement norms, plastic strain, pressure): to solver tolerance on
    another number of ranks, to MUMPS's run-to-run spread on the same."""
    world, alone = MPI.COMM_WORLD, MPI.COMM_SELF
    restart = CASES[case][2]
    own = _own_folder()
    single = _run(case, alone, own)
    distributed = _problem(case, world)
    distributed.restart(world.bcast(own, root=0), restart)  # rank 0's
    for num_steps, t_end in CASES[case][1]:
        distributed.solve(num_steps=num_steps, t_end=t_end)
    one_to_two = _difference(distributed, single)
    from_one = _shared_folder(world)
    shared = _run(case, world, from_one)
    restarted_alone = _problem(case, alone)
    restarted_alone.restart(from_one, restart)
    for num_steps, t_end in CASES[case][1]:
        restarted_alone.solve(num_steps=num_steps, t_end=t_end)
    two_to_one = _difference(restarted_alone, shared)
    prefix = "largest relative difference of the final state"
    checks = [
        (f"{prefix}, 1 rank -> 2 ranks", one_to_two, ACROSS_RANKS),
        (f"{prefix}, 2 ranks -> 1 rank", two_to_one, ACROSS_RANKS),
    ]
    problems = [single, distributed, shared, restarted_alone]
    if case == "ironing":  # the same count (2 -> 2) once: the others' keys are those of 1 -> 2
        restarted = _run(case, world, from_one, restart=restart)
        checks.append((f"{prefix}, 2 ranks -> 2 ranks", _difference(restarted, shared), SPREAD))
        assert _records(restarted) == _records(shared)
        problems.append(restarted)
    for quantity, value, tol in checks:
        verification(CASES[case][3], quantity, value, 0.0, tol, SOURCE, kind="consistency")
        assert value < tol
    assert _records(distributed) == _records(single)
    for p in problems:
        p.close()


def test_checkpoints_refuse_bad_input():
    """Bad input names the problem, on every rank, before any work."""
    for options, message in (
        ({"every": 0}, "every must be a whole number"),
        ({"every": 1.5}, "every must be a whole number"),
        ({"keep": 0}, "keep must be a whole number"),
    ):
        with pytest.raises(ContactInputError, match=message):
            cu.Checkpoints("unused", **options)


def test_restart_refuses_what_it_cannot_continue():
    """A missing folder or step, a problem that solved already, a checkpoint of another mesh
    or of another format: each a :class:`ContactInputError` naming it, on every rank; a
    partial checkpoint (a write cut short) is not one."""
    comm = MPI.COMM_WORLD
    folder = _shared_folder(comm)
    written = cu.ContactProblem(scenes.patch(comm=comm), verbose=False)
    written.solve(num_steps=2, checkpoint=cu.Checkpoints(folder, keep=1))
    assert cu.Checkpoints(folder).steps() == [2]  # keep=1: the last one only
    if comm.rank == 0:
        (folder / "step_000003.partial").mkdir()
    comm.barrier()
    assert cu.Checkpoints(folder).steps() == [2]
    with pytest.raises(ContactInputError, match="no complete checkpoint in"):
        cu.ContactProblem(scenes.patch(comm=comm), verbose=False).restart(folder / "none")
    with pytest.raises(ContactInputError, match=r"no complete checkpoint of step 1 .*\[2\]"):
        cu.ContactProblem(scenes.patch(comm=comm), verbose=False).restart(folder, 1)
    with pytest.raises(ContactInputError, match="restart a problem just made"):
        written.restart(folder)
    other = cu.ContactProblem(scenes.patch(comm=comm, height=0.6), verbose=False)  # moved nodes
    with pytest.raises(ContactInputError, match="written for another mesh 0"):
        other.restart(folder)
    comm.barrier()
    if comm.rank == 0:
        meta = folder / "step_000002" / "meta.json"
        meta.write_text(meta.read_text().replace('"format": 1', '"format": 99'))
    comm.barrier()
    with pytest.raises(ContactInputError, match="has format 99"):
        cu.ContactProblem(scenes.patch(comm=comm), verbose=False).restart(folder)
    written.close()


def test_result_files_go_on_after_a_restart():
    """A restarted run writes its VTX files beside the first run's (named from its step)
    and goes on with the contact surface's ``.pvd`` series after the checkpoint's step
    (the steps after it, written by the first run, replaced)."""
    comm = MPI.COMM_WORLD
    folder = _shared_folder(comm)
    first = cu.ContactProblem(scenes.patch(comm=comm), verbose=False)
    writer = cu.ResultWriter(first, folder / "out")
    first.solve(num_steps=3, callback=writer, checkpoint=folder / "checkpoints")
    writer.close()
    again = cu.ContactProblem(scenes.patch(comm=comm), verbose=False)
    again.restart(folder / "checkpoints", 2)
    writer = cu.ResultWriter(again, folder / "out")
    again.solve(num_steps=3, callback=writer)
    writer.close()
    names = sorted(p.name for p in (folder / "out").glob("*.bp"))
    assert names == [
        "contact_0.bp",
        "contact_0_from_step_2.bp",
        "displacement_0.bp",
        "displacement_0_from_step_2.bp",
        "displacement_1.bp",
        "displacement_1_from_step_2.bp",
    ] or names == [
        "contact_0.bp",
        "contact_0_from_step_2.bp",
        "displacement.bp",
        "displacement_from_step_2.bp",
    ]
    series = (folder / "out" / "contact_surface_0.pvd").read_text()
    times = [float(t) for t in re.findall(r'timestep="([^"]*)"', series)]
    files = re.findall(r'file="([^"]*)"', series)
    assert times == pytest.approx([1 / 3, 2 / 3, 1.0])
    assert files == [f"contact_surface_0/step_{k:05d}.vtu" for k in range(3)]
    first.close()
    again.close()


def test_meshes_are_written_once_with_their_tags():
    """The checkpoint folder holds each mesh and its tags once, as XDMF, readable by
    DOLFINx on any number of ranks (the same cells and tagged entities)."""
    import dolfinx.io

    comm = MPI.COMM_WORLD
    folder = _shared_folder(comm)
    problem = cu.ContactProblem(scenes.patch(comm=comm), verbose=False)
    problem.solve(num_steps=2, checkpoint=folder)
    for k, b in enumerate(problem.bulks):
        mesh, tags = b.V.mesh, b.domain.cell_tags
        with dolfinx.io.XDMFFile(comm, folder / "meshes" / f"mesh_{k}.xdmf", "r") as f:
            read = f.read_mesh(name=mesh.name)
            read_tags = f.read_meshtags(read, name=tags.name)
        cells = read.topology.index_map(read.topology.dim).size_global
        assert cells == mesh.topology.index_map(mesh.topology.dim).size_global
        owned = mesh.topology.index_map(mesh.topology.dim).size_local
        read_owned = read.topology.index_map(read.topology.dim).size_local
        count = comm.allreduce(int(np.sum(tags.indices < owned)))
        assert comm.allreduce(int(np.sum(read_tags.indices < read_owned))) == count
    problem.close()


@pytest.mark.serial
def test_checkpoints_leave_the_run_as_it_was(verification):
    """Writing checkpoints (each step after one a restart point) changes the run by
    round-off only: the same Newton iterations, the same contact forces at every step."""
    comm = MPI.COMM_WORLD
    plain = _run("ironing", comm, None)
    written = _run("ironing", comm, _shared_folder(comm))
    assert [s.newton_iterations for s in written.history.steps] == [
        s.newton_iterations for s in plain.history.steps
    ]
    forces = np.array([s.contact_force for s in plain.history.steps])
    difference = np.abs(np.array([s.contact_force for s in written.history.steps]) - forces)
    worst = float(difference.max() / np.abs(forces).max())
    bound = 1e-14  # measured: 6e-16
    case, quantity = CASES["ironing"][3], "largest relative change of a step's contact force"
    source = "the same run without checkpoints"
    verification(case, quantity, worst, 0.0, bound, source, kind="consistency")
    assert worst < bound
    assert np.array_equal(written.contact_force(), written.history.steps[-1].contact_force)


@pytest.mark.slow
def test_restart_in_3d_is_bit_for_bit(verification):
    """The 3D frictional ironing (coarse), restarted during the slide: the same unknowns,
    bit for bit, as the run that wrote the checkpoints (one rank; in 3D the solver matrix's
    pattern is the union of the pairings met, which a restart point starts anew)."""
    comm = MPI.COMM_SELF
    folder = _own_folder()

    def run(restart=None):
        problem = cu.ContactProblem(
            scenes.ironing_3d(mu=0.3, h_die=0.6, h_slab=0.75, comm=comm), verbose=False
        )
        if restart is not None:
            problem.restart(folder, restart)
        checkpoints = cu.Checkpoints(folder, every=3, keep=None)
        problem.solve(num_steps=6, t_end=1.0, checkpoint=checkpoints)
        problem.solve(num_steps=4, t_end=1.2, checkpoint=checkpoints)
        return problem

    whole = run()
    restarted = run(restart=6)
    worst = float(np.abs(restarted.solver.x.array - whole.solver.x.array).max())
    case = "3D frictional ironing, mu = 0.3, h = 0.6 / 0.75"
    quantity = "largest difference of the unknowns, restarted from step 6"
    verification(case, quantity, worst, 0.0, 0.0, SOURCE, kind="consistency")
    assert worst == 0.0
    assert _records(restarted) == _records(whole)
