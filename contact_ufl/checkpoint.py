"""Checkpoints of a load-stepped run, and the restart from one.

A checkpoint is a folder ``step_<n>`` (``n`` the accepted step) inside the checkpoint folder,
holding ``state.npz`` (every field of the state, each value named by a key that does not
depend on the partition, :mod:`contact_ufl.dof_keys`) and ``meta.json`` (pseudo-time, the
schedule of the solve, the step records, the meshes' fingerprints). Rank 0 writes it into
``step_<n>.partial`` and renames that folder once every file is on disk: a checkpoint is
complete or absent. Every rank reads the files and takes the values of its own dofs, so a
run written on some number of ranks restarts on any other. See the user guide, *Restart*.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from collections.abc import Iterator
from dataclasses import asdict
from pathlib import Path

import dolfinx
import dolfinx.io
import numpy as np
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI

from contact_ufl.dof_keys import entity_keys, find_keys, find_points, quadrature_positions
from contact_ufl.errors import ContactInputError
from contact_ufl.stepping import Cutback, History, Schedule, StepRecord

#: version of the files' layout
FORMAT = 1
STATE, META = "state.npz", "meta.json"


class Checkpoints:
    """Where and how often a run writes its checkpoints.

    Give it to :meth:`ContactProblem.solve <contact_ufl.problem.ContactProblem.solve>`
    (``checkpoint=``); restart with :meth:`ContactProblem.restart
    <contact_ufl.problem.ContactProblem.restart>`.

    Parameters
    ----------
    folder
        The checkpoint folder (made if missing).
    every
        Write at every ``every``-th accepted step, and at the last step of a solve.
    keep
        How many of the latest checkpoints to keep (``None``: all).
    """

    def __init__(self, folder: str | Path, every: int = 1, keep: int | None = 2):
        if not (isinstance(every, int | np.integer) and every >= 1):
            raise ContactInputError(f"every must be a whole number >= 1, got {every!r}")
        if keep is not None and not (isinstance(keep, int | np.integer) and keep >= 1):
            raise ContactInputError(f"keep must be a whole number >= 1 or None, got {keep!r}")
        self.folder = Path(folder)
        self.every, self.keep = int(every), keep

    def due(self, step: int, last: bool) -> bool:
        """Whether accepted step ``step`` is written (``last``: the solve's last step)."""
        return last or step % self.every == 0

    def steps(self) -> list[int]:
        """The steps of the complete checkpoints in the folder, in order (this rank's view of
        the file system)."""
        if not self.folder.is_dir():
            return []
        found = []
        for path in self.folder.glob("step_*"):
            number = path.name.removeprefix("step_")
            if number.isdigit() and (path / META).is_file():
                found.append(int(number))
        return sorted(found)

    def path(self, step: int) -> Path:
        """The folder of the checkpoint of ``step``."""
        return self.folder / f"step_{step:06d}"

    def write(self, problem, history: History, schedule: Schedule) -> Path:
        """Write the committed state of ``problem`` (collective): its fields gathered on
        rank 0, which writes them into a partial folder and then renames it."""
        comm = problem.comm
        step = len(history.steps)
        arrays, kinds = {}, {}
        for name, kind, key_name, keys, values in _state(problem):
            kinds[name] = [kind, key_name]
            if f"{key_name}.keys" not in arrays:  # fields on one space share their keys
                gathered = comm.gather(keys, root=0)
                arrays[f"{key_name}.keys"] = (
                    _compact(np.concatenate(gathered)) if gathered else None
                )
            gathered = comm.gather(values, root=0)
            arrays[f"{name}.values"] = np.concatenate(gathered) if gathered else None
        arrays = {k: v for k, v in arrays.items() if v is not None}
        self._write_meshes(problem)
        meta = _meta(problem, history, schedule, kinds)
        final = self.path(step)
        error = None
        if comm.rank == 0:
            try:
                self._write_files(final, arrays, meta)
                self._prune()
            except OSError as e:
                error = f"the checkpoint of step {step} could not be written to {final}: {e}"
        error = comm.bcast(error, root=0)
        if error is not None:
            raise OSError(error)
        return final

    def _write_meshes(self, problem) -> None:
        """Write the meshes and their tags once, as XDMF (``meshes/mesh_<k>.xdmf``), for
        a look at the run without its script; a restart reads the script's meshes and
        checks them against the fingerprints of each checkpoint (collective)."""
        comm = problem.comm
        final = self.folder / "meshes"
        if comm.bcast(final.is_dir() if comm.rank == 0 else None, root=0):
            return
        partial = self.folder / "meshes.partial"
        if comm.rank == 0:
            shutil.rmtree(partial, ignore_errors=True)
            partial.mkdir(parents=True)
        comm.barrier()
        for k, b in enumerate(problem.bulks):
            mesh, domain = b.V.mesh, b.domain
            with dolfinx.io.XDMFFile(comm, partial / f"mesh_{k}.xdmf", "w") as f:
                f.write_mesh(mesh)
                mesh.topology.create_connectivity(mesh.topology.dim - 1, mesh.topology.dim)
                f.write_meshtags(domain.cell_tags, mesh.geometry)
                f.write_meshtags(domain.facet_tags, mesh.geometry)
        comm.barrier()
        if comm.rank == 0:
            partial.rename(final)
        comm.barrier()

    def _write_files(self, final: Path, arrays: dict, meta: dict) -> None:
        partial = final.with_name(final.name + ".partial")
        shutil.rmtree(partial, ignore_errors=True)
        partial.mkdir(parents=True)
        with open(partial / STATE, "wb") as f:
            np.savez(f, **arrays)
            f.flush()
            os.fsync(f.fileno())
        with open(partial / META, "w") as f:
            json.dump(meta, f, indent=1, default=_plain)
            f.flush()
            os.fsync(f.fileno())
        if final.exists():  # a checkpoint of this step from an earlier run
            stale = final.with_name(final.name + ".stale")
            shutil.rmtree(stale, ignore_errors=True)
            final.rename(stale)
            shutil.rmtree(stale)
        partial.rename(final)
        descriptor = os.open(final.parent, os.O_RDONLY)
        try:
            os.fsync(descriptor)
        finally:
            os.close(descriptor)

    def _prune(self) -> None:
        if self.keep is None:
            return
        for step in self.steps()[: -self.keep]:
            shutil.rmtree(self.path(step), ignore_errors=True)


def _plain(value):
    """NumPy scalars as Python numbers (for JSON)."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not stored in a checkpoint's meta data")


def _owned(f: dolfinx.fem.Function) -> np.ndarray:
    V = f.function_space
    bs = V.dofmap.index_map_bs
    return f.x.array.reshape(-1, bs)[: V.dofmap.index_map.size_local]


def _unknown_fields(problem) -> Iterator[tuple[str, dolfinx.fem.Function]]:
    for i, f in enumerate(problem.unknowns):
        yield f"unknown_{i}", f


def _point_fields(problem) -> Iterator[tuple[str, str, dolfinx.fem.Function]]:
    """The plastic histories (quadrature functions on the bulk meshes): name, name of their
    points, field."""
    for k, b in enumerate(problem.bulks):
        for tag, h in b.histories.items():
            yield f"plastic_{k}_{tag}_Cp_inv", f"plastic_{k}_{tag}", h.Cp_inv
            yield f"plastic_{k}_{tag}_alpha", f"plastic_{k}_{tag}", h.alpha


def _slave_arrays(problem) -> Iterator[tuple[str, int, object, str]]:
    """The point data of the slave surfaces: name, pair, its holder and attribute."""
    for k, c in enumerate(problem.contacts):
        if c.master_two_sided:
            yield f"contact_{k}_sides", k, c.kinematics, "sides"
        if c.friction:
            yield f"contact_{k}_last_slip", k, c.friction, "last_slip"
            yield f"contact_{k}_last_stick", k, c.friction, "last_stick"


def _slave_points(problem, k: int) -> np.ndarray:
    """The reference positions of the owned slave points of pair ``k``, ``(n, gdim)``."""
    c = problem.contacts[k]
    return c.slave.X.reshape(-1, c.gdim)


def _state(problem) -> Iterator[tuple[str, str, str, np.ndarray, np.ndarray]]:
    """Every field of the committed state: name, kind of key (``entity`` or ``point``), the
    name of its keys (shared by the fields of one space), keys and values of this rank's
    owned dofs or points."""
    keys = {}
    for name, f in _unknown_fields(problem):
        owned = f.function_space.dofmap.index_map.size_local
        keys[name] = entity_keys(f.function_space)[:owned]
        yield name, "entity", name, keys[name], _owned(f)
    last = problem.solver.predictor.last
    if last is not None:
        increments = [f.copy() for f in problem.unknowns]
        fem_petsc.assign(last[2], increments)
        for (name, _), d in zip(_unknown_fields(problem), increments, strict=True):
            yield f"increment_{name}", "entity", name, keys[name], _owned(d)
    for name, points, f in _point_fields(problem):
        yield name, "point", points, quadrature_positions(f.function_space), _owned(f)
    for name, k, holder, attribute in _slave_arrays(problem):
        positions = _slave_points(problem, k)
        values = np.asarray(getattr(holder, attribute), dtype=float)
        yield name, "point", f"contact_{k}_points", positions, values.reshape(len(positions), -1)


def _compact(keys: np.ndarray) -> np.ndarray:
    """Entity keys as 32-bit integers where they fit (positions as they are)."""
    if keys.dtype.kind == "i" and (len(keys) == 0 or np.abs(keys).max() < 2**31):
        return keys.astype(np.int32)
    return keys


def _fingerprints(problem) -> list[dict]:
    """Global sizes and the sum of the coordinates of each mesh (checked on restart)."""
    prints = []
    for b in problem.bulks:
        mesh = b.V.mesh
        nodes = mesh.geometry.index_map().size_local
        total = problem.comm.allreduce(mesh.geometry.x[:nodes].sum(axis=0))
        cells = mesh.topology.index_map(mesh.topology.dim).size_global
        prints.append(
            {
                "nodes": mesh.geometry.index_map().size_global,
                "cells": cells,
                "coordinate_sum": [float(v) for v in total],
                "dofs": b.V.dofmap.index_map.size_global,
            }
        )
    return prints


def _meta(problem, history: History, schedule: Schedule, kinds: dict) -> dict:
    last = problem.solver.predictor.last
    return {
        "format": FORMAT,
        "step": len(history.steps),
        "t": problem.t,
        "ranks": problem.comm.size,
        "written": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "meshes": _fingerprints(problem),
        "fields": kinds,
        "schedule": asdict(schedule),
        "predictor": None if last is None else [last[0], last[1]],
        "weak_slip": [c.friction.last_weak_slip if c.friction else None for c in problem.contacts],
        "history": {
            "steps": [
                asdict(r) | {"contact_force": np.asarray(r.contact_force).tolist()}
                for r in history.steps
            ],
            "cutbacks": [c._asdict() for c in history.cutbacks],
        },
    }


def _chosen(checkpoints: Checkpoints, step: int | None, comm: MPI.Comm) -> int:
    """The step to restart from, as rank 0 sees the folder (collective)."""
    found = checkpoints.steps() if comm.rank == 0 else None
    found = comm.bcast(found, root=0)
    if not found:
        raise ContactInputError(f"no complete checkpoint in {checkpoints.folder}")
    if step is None:
        return found[-1]
    if step not in found:
        raise ContactInputError(
            f"no complete checkpoint of step {step} in {checkpoints.folder} (there are {found})"
        )
    return step


def _check_meshes(problem, meta: dict, path: Path) -> None:
    prints = _fingerprints(problem)
    if len(prints) != len(meta["meshes"]):
        raise ContactInputError(
            f"{path} was written for {len(meta['meshes'])} meshes, this scene has {len(prints)}"
        )
    for k, (now, then) in enumerate(zip(prints, meta["meshes"], strict=True)):
        same = all(now[key] == then[key] for key in ("nodes", "cells", "dofs")) and np.allclose(
            now["coordinate_sum"], then["coordinate_sum"], rtol=1e-9, atol=1e-12
        )
        if not same:
            counts = (then["nodes"], then["cells"], then["dofs"])
            moved = counts == (now["nodes"], now["cells"], now["dofs"])
            raise ContactInputError(
                f"{path} was written for another mesh {k} or degree: it had {then['nodes']} "
                f"nodes, {then['cells']} cells and {then['dofs']} displacement dofs, this one "
                f"{now['nodes']}, {now['cells']} and {now['dofs']}"
                + (" (the same numbers, but its nodes elsewhere)" if moved else "")
            )


def _set_owned(f: dolfinx.fem.Function, values: np.ndarray) -> None:
    _owned(f)[:] = values
    f.x.scatter_forward()


def restart(problem, folder: str | Path, step: int | None = None) -> float:
    """Set ``problem`` to the state of a checkpoint and make its solver there (collective):
    see :meth:`ContactProblem.restart <contact_ufl.problem.ContactProblem.restart>`.

    Returns
    -------
    The pseudo-time of the checkpoint.
    """
    if problem.has_solver:
        raise ContactInputError(
            "restart a problem just made from the scene, before any solve: this one has a "
            "solver already"
        )
    checkpoints = Checkpoints(folder)
    step = _chosen(checkpoints, step, problem.comm)
    path = checkpoints.path(step)
    meta = json.loads((path / META).read_text())
    if meta.get("format") != FORMAT:
        raise ContactInputError(
            f"{path} has format {meta.get('format')}, this version reads {FORMAT}"
        )
    _check_meshes(problem, meta, path)
    size = problem.scales()[0]
    with np.load(path / STATE) as data:

        def values(name: str, wanted: np.ndarray, kind: str) -> np.ndarray:
            if name not in meta["fields"]:
                raise ContactInputError(f"{path} holds no {name}: it was written for another scene")
            stored = data[f"{meta['fields'][name][1]}.keys"]
            if kind == "entity":
                at = find_keys(stored.astype(np.int64), wanted, name)
            else:
                at = find_points(stored, wanted, 1e-9 * size, name)
            return data[f"{name}.values"][at]

        def entity_values(name: str, f: dolfinx.fem.Function) -> np.ndarray:
            owned = f.function_space.dofmap.index_map.size_local
            return values(name, entity_keys(f.function_space)[:owned], "entity")

        for name, f in _unknown_fields(problem):
            _set_owned(f, entity_values(name, f))
        for name, _, f in _point_fields(problem):
            _set_owned(f, values(name, quadrature_positions(f.function_space), "point"))
        slave_data = {}
        for name, k, holder, attribute in _slave_arrays(problem):
            slave_data[name] = (holder, attribute, values(name, _slave_points(problem, k), "point"))
        increments = None
        if meta["predictor"] is not None:
            increments = [f.copy() for f in problem.unknowns]
            for (name, _), d in zip(_unknown_fields(problem), increments, strict=True):
                _set_owned(d, entity_values(f"increment_{name}", d))
    problem.set_time(meta["t"])
    sides = [(h, a, v) for h, a, v in slave_data.values() if a == "sides"]
    for holder, attribute, v in sides:  # the search reads them: before the solver is made
        setattr(holder, attribute, v.ravel())
    solver = problem.resume_solver()
    for holder, attribute, v in slave_data.values():
        if attribute == "last_slip":
            holder.last_slip = v.reshape(-1, problem.gdim)
        elif attribute == "last_stick":
            holder.last_stick = v.ravel() > 0.5
    for c, weak in zip(problem.contacts, meta["weak_slip"], strict=True):
        if c.friction:
            c.friction.last_weak_slip = weak
    if increments is not None:
        increment = solver.x.duplicate()
        fem_petsc.assign(increments, increment)
        solver.predictor.resume(*meta["predictor"], solver.x, increment)
    stepper = problem.stepper
    stepper.history = History(
        [
            StepRecord(**(r | {"contact_force": np.asarray(r["contact_force"])}))
            for r in meta["history"]["steps"]
        ],
        [Cutback(**c) for c in meta["history"]["cutbacks"]],
    )
    stepper.resume(Schedule(**meta["schedule"]), meta["t"])
    problem.restored_from = (path, step, meta["t"])
    return meta["t"]
