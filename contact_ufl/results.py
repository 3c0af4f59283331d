"""Results of a solved problem: contact tractions at the slave points, resultants."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class ContactSamples:
    """Contact quantities at the slave quadrature points of all ranks.

    Attributes
    ----------
    x
        Current positions ``(n, gdim)``.
    lambda_N
        Normal multiplier (nominal pressure, per unit reference area).
    pressure
        Cauchy contact pressure (per unit current area): ``lambda_N dA / da``.
    gap
        Proximity g (> 0 penetration; -inf where no master facet was found).
    """

    x: np.ndarray
    lambda_N: np.ndarray
    pressure: np.ndarray
    gap: np.ndarray


def contact_samples(problem, pair: int = 0) -> ContactSamples:
    """Gather the contact quantities of contact pair ``pair`` on every rank."""
    c = problem.contacts[pair]
    comm = problem.comm
    gdim = c.gdim
    x = c.slave.positions(problem.u).reshape(-1, gdim)
    lam = c.multiplier_at_points()
    ratio = c.slave.area_ratio(problem.u).ravel()
    gap = np.where(c.projection.facet >= 0, c.projection.gap, -np.inf)

    def gather(a):
        return np.concatenate(comm.allgather(a))

    return ContactSamples(gather(x).reshape(-1, gdim), gather(lam), gather(lam / ratio),
                          gather(gap))
