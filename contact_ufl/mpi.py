"""Small collective helpers over the ranks of a communicator."""

from __future__ import annotations

import numpy as np
from mpi4py import MPI


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
