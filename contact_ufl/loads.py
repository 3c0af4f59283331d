"""Prescribed loads and displacements, scaled by the pseudo-time (load factor) t.

Values are given either as constants or as callables of the pseudo-time ``t``; they are
refreshed into DOLFINx constants at every load step, so forms are compiled once.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl

Value = float | Sequence[float] | Callable[[float], float | Sequence[float]]


def evaluate(value: Value, t: float) -> np.ndarray:
    """The value at pseudo-time ``t`` as an array."""
    return np.asarray(value(t) if callable(value) else value, dtype=float)


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement on tagged facets.

    Parameters
    ----------
    tag
        Facet tag.
    value
        Displacement vector (or, with ``component``, one component), or a callable of ``t``.
    component
        Constrain only this component.
    """

    tag: int
    value: Value
    component: int | None = None


@dataclass(frozen=True)
class DeadTraction:
    """Nominal (first Piola) traction per unit reference area, fixed in direction."""

    tag: int
    value: Value

    def virtual_work(self, u, v, ds, constant):
        """External virtual work ``int T . v dS_o``."""
        return ufl.dot(constant, v) * ds(self.tag)


@dataclass(frozen=True)
class BodyForce:
    """Dead body force per unit reference volume (``rho_0 f`` of ``formulation.md``)."""

    tag: int
    value: Value

    def virtual_work(self, u, v, dx, constant):
        """External virtual work ``int rho_0 f . v dOmega_o``."""
        return ufl.dot(constant, v) * dx(self.tag)


def load_constant(mesh: dolfinx.mesh.Mesh, load) -> dolfinx.fem.Constant:
    """A constant of the right shape for ``load``, initialised at t = 0."""
    shape = evaluate(load.value, 0.0).shape
    return dolfinx.fem.Constant(mesh, np.zeros(shape))
