"""Why a Newton solve of a contact problem failed, from what its iterates showed.

:class:`StepDiagnosis` watches the iterates of each solve (the contact state of each, and
the inverted cells of an iterate whose residual is not a number) and tells, at the last
iterate of a failed one: inverted elements and where, a contact pairing or status that
cycles (the pairing alone: where the residual stalls), or a residual that stalls with
neither (a limit point, a singular tangent); with hints where a body is free to turn, or a
faceted master normal could cycle.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from mpi4py import MPI


class StepDiagnosis:
    """The iterates of the last Newton solve, and what went wrong in them.

    Parameters
    ----------
    comm
        The problem's communicator.
    contacts
        The contact interfaces.
    free_pieces
        ``(piece, its pairs)`` of the pieces of the meshes with a free rigid mode and
        contact pairs (:mod:`contact_ufl.free_bodies`).
    inverted_cells
        ``inverted_cells()``: the centres of the cells inverted at the current state.

    Attributes
    ----------
    signatures
        A signature of the contact state (pairing, contact and stick/slip status of this
        rank's points) at each iterate of the last solve.
    statuses
        A signature of the contact and stick/slip status alone at each iterate.
    not_finite
        The inverted cells of the last iterate whose residual was not a number.
    """

    def __init__(
        self,
        comm: MPI.Comm,
        contacts: list,
        free_pieces: list,
        inverted_cells: Callable[[], np.ndarray],
    ):
        self.comm = comm
        self.contacts = contacts
        self.free_pieces = [(piece, on) for piece, on in free_pieces if on]
        self._inverted_cells = inverted_cells
        self.signatures: list[int] = []
        self.statuses: list[int] = []
        self.not_finite: np.ndarray | None = None

    def start_solve(self) -> None:
        """A new solve: forget the last one's iterates."""
        self.signatures = []
        self.statuses = []
        self.not_finite = None

    def record_iterate(self, norm: float) -> None:
        """The contact state of an iterate (the pairing, the contact status and, with
        friction, the stick/slip status)."""
        paired = [c for c in self.contacts if c.projection is not None]
        status = [
            np.concatenate(
                [c.active().astype(np.int64)] + ([c.stick().astype(np.int64)] if c.friction else [])
            )
            for c in paired
        ]
        pairing = [c.projection.facet for c in paired]
        state = [np.concatenate([f, s]) for f, s in zip(pairing, status, strict=True)]
        self.signatures.append(hash(np.concatenate(state).tobytes()) if state else 0)
        self.statuses.append(hash(np.concatenate(status).tobytes()) if status else 0)

    def record_not_finite(self) -> None:
        """An iterate whose residual is not a number: where are its inverted cells?"""
        self.not_finite = self._inverted_cells()

    def diagnose(self, norms: list[float]) -> str:
        """Why the last solve (residual ``norms`` of its iterates) failed, at its last
        iterate (collective): inverted elements (and where), contact pairing or status that
        cycles between iterates, or a residual that stalls with neither (a limit point, or a
        singular tangent); otherwise how far the residual fell and in how many iterates the
        contact state changed. Where a piece of a mesh with contact pairs is free to turn (no
        support holds a rotation), it says so and where it turns."""
        return self._cause(norms) + self._turning_hint()

    def _cause(self, norms: list[float]) -> str:
        centres = self._inverted_cells()
        if not len(centres) and self.not_finite is not None:
            centres = self.not_finite  # the trial iterate the line search rejected
        if len(centres):
            where = ", ".join("(" + ", ".join(f"{v:.3g}" for v in c) + ")" for c in centres[:3])
            return f"inverted elements in {len(centres)} cells, e.g. at {where}"
        signatures = self.signatures
        revisits = any(
            signatures[k] in signatures[: k - 1] and signatures[k] != signatures[k - 1]
            for k in range(2, len(signatures))
        )
        if self.comm.allreduce(revisits, MPI.LOR):
            if self._pairing_alone() and len(norms) > 1 and norms[0] > 0.0:
                stall = norms[-1] / norms[0]
                return (
                    "the contact pairing cycles: the master facets of some slave points "
                    "alternate between iterates while no point changes contact status (the "
                    "iterates straddle edges between master facets, where the facet normal "
                    f"jumps); the residual stalls at {norms[-1]:.3g}, {stall:.2g} of the "
                    f"first: a snes_rtol above {stall:.2g} (petsc_options) accepts that state "
                    "(pairing cycling)" + self._normal_hint()
                )
            return (
                "the contact pairing or status cycles: an iterate returns to the contact state "
                "of an earlier one (active-set cycling)" + self._normal_hint()
            )
        changed = np.array([a != b for a, b in zip(signatures, signatures[1:], strict=False)])
        changes = int(np.count_nonzero(self.comm.allreduce(changed.astype(np.int64), MPI.SUM)))
        if changes == 0 and len(signatures) > 2:
            return (
                "the residual stalls with no inverted element and no change of contact state: "
                "a limit point or a singular tangent (a load beyond a maximum, a body free "
                "to move)"
            )
        state = (
            f"the contact pairing or status changing in {changes} of them"
            if changes
            else "no change of contact state"
        )
        fell = (
            f": it fell from {norms[0]:.3g} to {norms[-1]:.3g} in {len(norms) - 1} iterates, "
            + state
            if len(norms) > 1
            else ""
        )
        return f"the residual does not converge (no inverted element, no contact cycling){fell}"

    def _pairing_alone(self) -> bool:
        """Whether the last four iterates share one contact status on every rank (what
        cycles is then the pairing alone; collective)."""
        statuses = self.statuses
        alone = len(statuses) == len(self.signatures) >= 4 and len(set(statuses[-4:])) == 1
        return bool(self.comm.allreduce(alone, MPI.LAND))

    def _turning_hint(self) -> str:
        """The hint for a piece free to turn (the same on every rank)."""
        hints = []
        for piece, on in self.free_pieces:
            if not piece.rotates:
                continue
            point = piece.turning_point()
            about = "" if point is None else " about (" + ", ".join(f"{v:.3g}" for v in point) + ")"
            pairs = ", ".join(self.contacts[k].pair.surface("slave") for k in on)
            hints.append(
                f"; the body with the contact pair(s) of slave surface {pairs} is free to turn"
                f"{about}: no support holds that rotation, only the contact, which a "
                "frictionless contact of a curved surface may not (the tangent is then near "
                "singular): hold it by a support"
            )
        return "".join(hints)

    def _normal_hint(self) -> str:
        """The hint for active-set cycling where a pair could have the smoothed master
        normal and has the facet one (a solid master of a degree-1 displacement; the same on
        every rank: the pairs are)."""
        faceted = [
            c.pair.surface("master")
            for c in self.contacts
            if not c.pair.on_obstacle
            and c.pair.master_normal == "facet"
            and not (c.master.two_sided or c.pair.self_contact)
            and c.V.ufl_element().embedded_superdegree == 1
        ]
        if not faceted:
            return ""
        return (
            f"; the master surface {', '.join(faceted)} has the facet normal, which jumps "
            'at every facet edge: master_normal="smoothed" in its ContactPair removes those '
            "jumps (continuous normal from facet to facet)"
        )
