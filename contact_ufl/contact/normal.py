"""The normal contact law: the Macaulay bracket and the equation of the normal multiplier.

    t_N = <lambda_N + eps_N g>
    - int_{S_oc} (lambda_N - t_N) lambda_N* dS_o        (the multiplier equation times eps_N)

Discrete multiplier: ``lambda_N`` is continuous piecewise linear on the slave submesh (P1).
It interpolates a continuous contact pressure with the same resolution as the slave trace
of a P1 displacement, so the active set and the gap condition are imposed in the weak
(mortar) sense at the contact quadrature points, and the multiplier *is* the nodal pressure
(property (c) of the formulation, ``docs/theory.md``). With a degree-2 displacement it stays
P1 by default (``ContactPair.multiplier_degree``: 2 gives P2, ``"iso"`` P1-iso-P2; the
evidence is in ``docs/quadratic-contact.md``). The slave side should be the finer mesh, as
usual with standard mortar multipliers.
"""

from __future__ import annotations

import dolfinx
import numpy as np
import ufl

from contact_ufl.contact.search import Projection
from contact_ufl.contact.slave import SlaveSurface


def macaulay(a: ufl.core.expr.Expr, touching: float | ufl.core.expr.Expr = 0.0):
    """Macaulay bracket ``<a> = max(a, 0)``.

    With ``touching > 0``, the values ``-touching < a <= 0`` count as positive (value ``a``,
    derivative 1): a point within round-off of touching is in contact. Scenes that start
    exactly at ``g = 0`` with ``lambda = 0`` sit on the kink of the bracket, where round-off
    alone would pick a random active set (and a singular tangent) for the first iterate; the
    value changes by at most ``touching``.
    """
    return ufl.conditional(ufl.gt(a, -touching), a, 0.0)


class NormalLaw:
    """Unilateral contact in the normal direction, augmented by ``eps_N``.

    Parameters
    ----------
    slave
        The slave surface (it carries ``lambda_N``).
    eps_N
        Normal augmentation parameter.
    round_off
        A length of round-off: a gap within it of zero counts as touching (:func:`macaulay`).

    Attributes
    ----------
    contact_threshold
        The length within which an open point counts as in contact (a constant of the
        forms): ``round_off``, except in a step strategy's iterate that moves it
        (:meth:`count_in_contact_within`, :mod:`contact_ufl.strategies`).
    """

    def __init__(self, slave: SlaveSurface, eps_N: float, round_off: float):
        self.slave = slave
        self.L = slave.P1
        self.lambda_N = dolfinx.fem.Function(self.L, name="lambda_N")
        self.eps_N = dolfinx.fem.Constant(slave.V.mesh, float(eps_N))
        self.round_off = round_off
        self.contact_threshold = dolfinx.fem.Constant(slave.V.mesh, float(round_off))

    def count_in_contact_within(self, distance: float) -> None:
        """Count the open points within ``distance`` of the master as in contact (a
        closing iterate); a negative ``distance``: only the points that overlap it by more
        than ``-distance`` (a first contact's predictor iterate). The forms see it at once."""
        self.contact_threshold.value = distance

    def restore_contact_threshold(self) -> None:
        """Back to the contact law: within round-off of touching counts as in contact."""
        self.contact_threshold.value = self.round_off

    def traction(self, gap: ufl.core.expr.Expr, mask: ufl.core.expr.Expr):
        """The normal contact traction ``t_N = <lambda_N + eps_N g>`` (0 where ``mask`` is 0)."""
        return mask * macaulay(self._argument(gap), self.eps_N * self.contact_threshold)

    def in_contact_condition(self, gap: ufl.core.expr.Expr, mask: ufl.core.expr.Expr):
        """Where the bracket of :meth:`traction` counts as positive (a UFL condition; the
        forms' twin of :meth:`in_contact`)."""
        positive = ufl.gt(self._argument(gap), -self.eps_N * self.contact_threshold)  # see macaulay
        return ufl.And(ufl.gt(mask, 0.5), positive)

    def _argument(self, gap: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """The bracket's argument ``lambda_N + eps_N g``."""
        return self.lambda_N + self.eps_N * gap

    def residual(self, t_N: ufl.core.expr.Expr) -> ufl.Form:
        """The multiplier equation, times ``eps_N``: its rows are forces like those of the
        displacement (one tolerance for all, and conditioning)."""
        test = ufl.TestFunction(self.L)
        return -(self.lambda_N - t_N) * test * self.slave.ds

    # -- at the slave points (NumPy) ----------------------------------------------------
    def multiplier_at_points(self) -> np.ndarray:
        """lambda_N at the owned slave quadrature points, ``(ncells * nq,)``."""
        return self.slave.p1_at_points(self.lambda_N)

    def _bracket_argument(self, proj: Projection) -> np.ndarray:
        eps = float(self.eps_N.value)
        gap = np.where(proj.facet >= 0, proj.gap, -np.inf)
        return self.multiplier_at_points() + eps * gap

    def traction_at_points(self, proj: Projection) -> np.ndarray:
        """``t_N = <lambda_N + eps_N g>`` at the owned slave points (0 where unpaired)."""
        return np.maximum(self._bracket_argument(proj), 0.0)

    def in_contact(self, proj: Projection, margin: float = 0.0) -> np.ndarray:
        """Mask of the owned points where the bracket counts as positive (:func:`macaulay`);
        with a ``margin`` (a length), also those within it of counting so."""
        threshold = float(self.contact_threshold.value) + margin
        return self._bracket_argument(proj) > -float(self.eps_N.value) * threshold

    def deepest_overlap(self, proj: Projection) -> float:
        """The largest proximity ``g`` (overlap with the master) of this rank's paired
        points (0 if none overlaps)."""
        return float(proj.gap[proj.facet >= 0].max(initial=0.0))

    def overlap_moments(self, proj: Projection, weights: np.ndarray) -> np.ndarray:
        """``[sum w g, sum w]`` over this rank's paired points that overlap the master
        (``g > 0``), ``weights`` their measures: the mean overlap is the first over the
        second."""
        g = np.where(proj.facet >= 0, proj.gap, 0.0)
        over = g > 0.0
        return np.array([np.dot(weights[over], g[over]), weights[over].sum()])

    def nearest_open_gap(self, proj: Projection) -> float:
        """The smallest distance from the master surface of this rank's open points that have
        a master facet (``inf`` if none): how far the nearest open point is from touching."""
        gap = proj.gap[(proj.facet >= 0) & (proj.gap < 0.0)]
        return float(-gap.max(initial=-np.inf))
