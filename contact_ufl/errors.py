"""Errors raised collectively, so that bad input never leaves one MPI rank hanging."""

from __future__ import annotations

from mpi4py import MPI


class ContactInputError(ValueError):
    """Bad input: wrong tags, empty or non-facing surfaces, invalid parameters."""


class NonUniqueSolutionWarning(UserWarning):
    """The scene leaves a body a rigid motion that nothing holds: the answer along it is
    arbitrary (it may differ between runs and numbers of ranks)."""


class CrackWarning(UserWarning):
    """Distinct nodes of one body at the same place: the body is cut there (a crack), which
    is rarely meant (a mesh of pieces not merged: gmsh ``Coherence``, ``fragment``)."""


class ConvergenceError(RuntimeError):
    """A load step could not be converged, even after cutting it back."""


def collective_check(
    comm: MPI.Comm, ok: bool, message: str, error: type[Exception] = ContactInputError
) -> None:
    """Raise ``error(message)`` on every rank if ``ok`` is false on any rank.

    The message of the lowest failing rank is raised everywhere.
    """
    messages = comm.allgather(None if ok else message)
    failed = [m for m in messages if m is not None]
    if failed:
        raise error(failed[0])


def check_positive(comm: MPI.Comm, **values: float) -> None:
    """Raise on every rank unless every named value is a finite positive number."""
    for name, value in values.items():
        collective_check(
            comm,
            bool(value > 0.0 and value < float("inf")),
            f"{name} must be positive, got {name} = {value}",
        )
