"""Analytic solutions the package is verified against."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def plane_strain_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """Contact modulus ``E*`` with ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2``."""
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


@dataclass(frozen=True)
class Hertz2D:
    """Plane-strain Hertz contact of a cylinder of radius ``R`` on a flat (or two cylinders).

    For a load ``P`` per unit length: half-width ``a = sqrt(4 P R / (pi E*))``, peak pressure
    ``p0 = 2 P / (pi a)`` and ``p(x) = p0 sqrt(1 - x^2 / a^2)`` (Johnson, *Contact
    Mechanics*, 1985, section 4.2).
    """

    P: float
    R: float
    E_star: float

    @property
    def a(self) -> float:
        """Contact half-width."""
        return float(np.sqrt(4.0 * self.P * self.R / (np.pi * self.E_star)))

    @property
    def p0(self) -> float:
        """Peak pressure."""
        return 2.0 * self.P / (np.pi * self.a)

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """Pressure at distance ``x`` from the centre of contact."""
        return self.p0 * np.sqrt(np.clip(1.0 - (np.asarray(x) / self.a) ** 2, 0.0, None))


def fit_elliptic_profile(x: np.ndarray, p: np.ndarray, threshold: float = 0.1):
    """Fit ``p = p0 sqrt(1 - (x - xc)^2 / a^2)`` to samples; return ``(a, p0, xc)``.

    ``p^2`` is a quadratic in ``x``: a linear least-squares fit over the samples with
    ``p > threshold * max(p)`` (away from the edge, where a finite element profile is
    smeared over one element).
    """
    keep = p > threshold * p.max()
    A = np.vstack([np.ones(keep.sum()), x[keep], x[keep] ** 2]).T
    c0, c1, c2 = np.linalg.lstsq(A, p[keep] ** 2, rcond=None)[0]
    xc = -c1 / (2.0 * c2)
    p0_sq = c0 - c2 * xc**2
    return float(np.sqrt(-p0_sq / c2)), float(np.sqrt(p0_sq)), float(xc)
