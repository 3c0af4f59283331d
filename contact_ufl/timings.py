"""Wall-clock seconds and counts of the parts of the Newton solves of a problem."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass


@dataclass
class NewtonTimings:
    """Wall-clock seconds of the parts of the Newton solves of a problem, on this rank,
    accumulated since the solver was made or :meth:`reset` (no collectives: on several
    ranks each rank has its own). The operator (:mod:`contact_ufl.operator`) fills the
    search and assembly parts, the driver (:mod:`contact_ufl.newton`) the SNES ones.

    Attributes
    ----------
    search
        Search and contact data update: closest-point projection, contact data, and the
        chain operator ``T`` where the pairing changed.
    residual_assembly
        Assembly of the residual over the fields and its map ``T^T r`` to the unknowns, with
        the Dirichlet rows.
    jacobian_assembly
        Assembly of the tangent: its blocks between unknowns straight into the solver's
        matrix, the blocks of the gathered fields (``K``) over the fields they couple.
    ptap
        ``T^T K T`` of the gathered blocks, its sum into the solver's matrix (whose pattern
        grows, with a reset factorisation, where a new pairing leaves it) and the Dirichlet
        rows.
    newton
        Time inside ``SNES.solve``.
    callbacks
        Time of the residual and Jacobian callbacks inside ``SNES.solve`` (including their
        searches).
    searches, residuals, jacobians, iterations
        Counts: contact updates, residual and Jacobian evaluations (in or out of SNES), and
        Newton iterations.
    new_patterns
        Jacobians assembled on a new sparsity pattern of ``T^T K T`` (the pairing changed):
        a symbolic PtAP.
    analyses
        Sparsity patterns given to the factorisation (the first, and those grown because a
        pairing added a nonzero to the solver matrix's pattern, see
        :class:`~contact_ufl.sparsity.SolverPattern`): each is followed by a symbolic
        analysis, as costly as a numeric factorisation.
    """

    search: float = 0.0
    residual_assembly: float = 0.0
    jacobian_assembly: float = 0.0
    ptap: float = 0.0
    newton: float = 0.0
    callbacks: float = 0.0
    searches: int = 0
    residuals: int = 0
    jacobians: int = 0
    iterations: int = 0
    new_patterns: int = 0
    analyses: int = 0

    @property
    def linear_solve(self) -> float:
        """SNES time outside the callbacks: factorisation and solve of the linear systems,
        plus SNES's own vector work (norms, updates, line search), which is small beside
        them."""
        return max(self.newton - self.callbacks, 0.0)

    def reset(self) -> None:
        """Zero all times and counts."""
        for f in dataclasses.fields(self):
            setattr(self, f.name, f.default)

    def per_iteration(self) -> dict[str, float]:
        """Seconds per Newton iteration of each part (and ``total``, the SNES time).

        The parts include their calls outside SNES (the search at the converged state of a
        step, the evaluations of a closing iterate), so they may add up to more than
        ``total``."""
        n = max(self.iterations, 1)
        parts = ("search", "residual_assembly", "jacobian_assembly", "ptap", "linear_solve")
        out = {name: getattr(self, name) / n for name in parts}
        out["total"] = self.newton / n
        return out
