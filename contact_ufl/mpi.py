"""Small collective helpers over the ranks of a communicator."""

from __future__ import annotations

import functools
import os
import time
from collections.abc import Callable

import numpy as np
from mpi4py import MPI

#: Seconds a rank waits in a :func:`collective` call for the other ranks to make it before
#: it raises :class:`CollectiveCallError` (environment: ``CONTACT_UFL_COLLECTIVE_TIMEOUT``).
#: Long enough for one rank to finish a picture or a file while the others wait.
COLLECTIVE_TIMEOUT = float(os.environ.get("CONTACT_UFL_COLLECTIVE_TIMEOUT", "300"))

_pending: list[MPI.Request] = []  # barriers given up on, kept so MPI can still complete them


class CollectiveCallError(RuntimeError):
    """A collective call made on some ranks only, or different calls made on the ranks at
    once: the run would hang."""


def enter_collective(comm: MPI.Comm, name: str, timeout: float | None = None) -> None:
    """Check that every rank of ``comm`` enters the collective call ``name`` together.

    A non-blocking barrier is polled for ``timeout`` seconds (default
    :data:`COLLECTIVE_TIMEOUT`): a rank that waits longer raises
    :class:`CollectiveCallError`, naming the call, instead of hanging; then the ranks
    compare the calls' names, and different calls raise on every rank. No cost on one rank.
    """
    if comm.size == 1:
        return
    timeout = COLLECTIVE_TIMEOUT if timeout is None else timeout
    request = comm.Ibarrier()
    deadline = time.monotonic() + timeout
    while not request.Test():
        if time.monotonic() > deadline:
            _pending.append(request)
            raise CollectiveCallError(
                f"{name} is collective: every rank must call it, in the same order, but rank "
                f"{comm.rank} waited {timeout:.0f} s for the others (is it called inside "
                "`if comm.rank == 0:`? Call it on every rank and print on one; see the "
                "guide's page on MPI)"
            )
        time.sleep(1e-4)
    names = comm.allgather(name)
    if len(set(names)) > 1:
        raise CollectiveCallError(
            "the ranks made different collective calls at once, by rank: "
            + ", ".join(names)
            + ": every rank must make the same collective calls in the same order"
        )


def collective(method: Callable) -> Callable:
    """Decorate a method of an object with a ``comm`` as collective: on several ranks it
    first checks that every rank makes the call (:func:`enter_collective`)."""

    @functools.wraps(method)
    def checked(self, *args, **kwargs):
        enter_collective(self.comm, f"{type(self).__name__}.{method.__name__}")
        return method(self, *args, **kwargs)

    return checked


def global_bounds(comm: MPI.Comm, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners of the bounding box of ``points`` ``(n, gdim)`` of all ranks."""
    gdim = points.shape[1]
    lo = points.min(axis=0) if len(points) else np.full(gdim, np.inf)
    hi = points.max(axis=0) if len(points) else np.full(gdim, -np.inf)
    glo, ghi = np.empty(gdim), np.empty(gdim)
    comm.Allreduce(np.ascontiguousarray(lo, dtype=float), glo, op=MPI.MIN)
    comm.Allreduce(np.ascontiguousarray(hi, dtype=float), ghi, op=MPI.MAX)
    return glo, ghi


def global_diameter(comm: MPI.Comm, points: np.ndarray) -> float:
    """Diagonal of the bounding box of ``points`` ``(n, gdim)`` of all ranks."""
    lo, hi = global_bounds(comm, points)
    return float(np.linalg.norm(hi - lo))


def comm_max(comm: MPI.Comm, value: int) -> int:
    """Largest value over the ranks."""
    return int(comm.allreduce(value, MPI.MAX))
