"""Taylor test of the tangent: does the Jacobian differentiate the residual?

For a state z and a direction dz, the remainder ``|R(z + h dz) - R(z) - h J(z) dz|`` of a
consistent tangent falls as ``h^2``; a tangent that misses a term leaves an ``O(h)`` part.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


@dataclass
class TaylorResult:
    """Steps, remainders of order zero (|R(z+h dz) - R(z)|) and one, and the slopes.

    ``active_changed`` also covers stick/slip changes of frictional pairs."""

    h: np.ndarray
    zeroth: np.ndarray
    first: np.ndarray
    facets_changed: bool
    active_changed: bool

    @property
    def slopes(self) -> np.ndarray:
        """Observed orders of the first-order remainder between successive steps."""
        return np.diff(np.log(self.first)) / np.diff(np.log(self.h))


def _signature(problem) -> tuple[list, list]:
    facets = [c.projection.facet.copy() for c in problem.contacts]
    status = [c.active().astype(int) + (c.stick() if c.friction else 0) for c in problem.contacts]
    return facets, status


def _same(a: list, b: list, comm: MPI.Comm) -> bool:
    same = all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    return bool(comm.allreduce(same, MPI.LAND))


def taylor_test(problem, direction: PETSc.Vec, steps: Sequence[float]) -> TaylorResult:
    """Remainders of the residual of ``problem`` at its current state along ``direction``.

    The state is restored afterwards. ``facets_changed``/``active_changed`` report whether
    any slave point changed master facet or contact status over the steps (the remainder
    then has a kink and no order can be expected).
    """
    comm, operator = problem.comm, problem.operator
    z = operator.x.copy()
    operator.forget_state()
    R0 = operator.evaluate_residual(z)
    facets0, active0 = _signature(problem)
    Jdz = R0.duplicate()
    operator.evaluate_jacobian(z).mult(direction, Jdz)
    zeroth, first = [], []
    facets_changed = active_changed = False
    for h in steps:
        zh = z.copy()
        zh.axpy(h, direction)
        Rh = operator.evaluate_residual(zh)
        facets, active = _signature(problem)
        facets_changed |= not _same(facets, facets0, comm)
        active_changed |= not _same(active, active0, comm)
        Rh.axpy(-1.0, R0)
        zeroth.append(Rh.norm())
        Rh.axpy(-h, Jdz)
        first.append(Rh.norm())
    operator.evaluate_residual(z)
    return TaylorResult(
        np.asarray(steps, float), np.array(zeroth), np.array(first), facets_changed, active_changed
    )
