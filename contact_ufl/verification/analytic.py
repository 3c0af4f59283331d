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


# -- Cantilever elastica under a tip force -----------------------------------------------------


def bending_stiffness_plane_strain(E: float, nu: float, h: float) -> float:
    """Bending stiffness per unit width ``EI = E' h^3 / 12``, ``E' = E / (1 - nu^2)``, of a
    plane-strain beam of thickness ``h``."""
    return E / (1.0 - nu**2) * h**3 / 12.0


def _elastica_from_tip(k: float, tip_angle: float, follower: bool) -> np.ndarray:
    """Integrate the elastica from the free end ``s = 1`` back to the clamp ``s = 0``.

    Unknowns ``(theta, theta', x, y)`` along the arc length ``s`` (unit length); the
    curvature equation is ``theta'' = k cos(theta - theta_tip)`` for a force perpendicular
    to the tip tangent and ``theta'' = k cos(theta)`` for a dead force in ``-y``; at the tip
    ``theta = tip_angle``, ``theta' = 0`` (no moment), position ``(0, 0)``. Returns the state
    at ``s = 0``.
    """
    from scipy.integrate import solve_ivp

    shift = tip_angle if follower else 0.0

    def rhs(s, z):
        return [z[1], k * np.cos(z[0] - shift), np.cos(z[0]), np.sin(z[0])]

    sol = solve_ivp(rhs, (1.0, 0.0), [tip_angle, 0.0, 0.0, 0.0], rtol=1e-12, atol=1e-14)
    return sol.y[:, -1]


def cantilever_elastica(k: float, follower: bool) -> tuple[float, float, float]:
    """Tip of an inextensible, shear-rigid cantilever (Euler elastica) under a tip force.

    The beam of length ``L`` lies along ``+x``, clamped at ``x = 0``; the force of magnitude
    ``P`` at ``x = L`` points initially in ``-y``. ``follower=True``: the force stays
    perpendicular to the deformed tip tangent (follower load); ``False``: it stays in ``-y``
    (dead load). With the moment ``M = EI theta'`` the equilibrium of the part beyond ``s``
    gives ``theta'' = k cos(theta - theta_L)`` (follower) or ``k cos(theta)`` (dead), ``k =
    P L^2 / EI``, ``theta(0) = 0``, ``theta'(L) = 0``. Integrated from the tip, where the state
    is known up to the tip angle ``theta_L``: for the follower load the clamp condition only
    rotates the solution (``theta_L = -phi(0)`` of the problem with ``theta_L = 0``); for the
    dead load ``theta_L`` is found by bisection.

    Parameters
    ----------
    k
        Load parameter ``P L^2 / EI`` (``EI`` per unit width in plane strain, see
        :func:`bending_stiffness_plane_strain`).
    follower
        Follower (perpendicular to the deformed axis) or dead (fixed ``-y``) force.

    Returns
    -------
    u/L, v/L, theta_L
        Tip displacement along and across the undeformed axis, over ``L``, and the tip
        rotation (radians, negative: clockwise).
    """
    from scipy.optimize import brentq

    if follower:
        phi0 = _elastica_from_tip(k, 0.0, True)
        tip = -phi0[0]
    else:
        tip = brentq(
            lambda a: _elastica_from_tip(k, a, False)[0], -0.5 * np.pi + 1e-12, 0.0, xtol=1e-15
        )
    _, _, x0, y0 = _elastica_from_tip(k, tip, follower)
    # positions relative to the tip; the clamp is at angle 0 in the global frame
    return float(-x0 - 1.0), float(-y0), float(tip)


#: Tip displacements ``(u/L, v/L)`` of the cantilever elastica under a tip force ``P``
#: initially in ``-y``, by load parameter ``k = P L^2 / EI``. Follower force perpendicular to
#: the deformed axis: the follower-load elastica (the classical benchmark of e.g. Argyris &
#: Symeonidis, "Nonlinear finite element analysis of elastic systems under nonconservative
#: loading - natural formulation. Part I", Comput. Methods Appl. Mech. Eng. 26, 75-123,
#: 1981), values to five digits of :func:`cantilever_elastica`.
ELASTICA_FOLLOWER_TIP: dict[float, tuple[float, float]] = {
    1.0: (-0.06435, -0.32064),
    2.0: (-0.23264, -0.57384),
}

#: Same for a dead tip force fixed in ``-y``: Bisshopp & Drucker, "Large deflection of
#: cantilever beams", Q. Appl. Math. 3, 272-275 (1945) (reproduced by
#: :func:`cantilever_elastica`).
ELASTICA_DEAD_TIP: dict[float, tuple[float, float]] = {
    1.0: (-0.05643, -0.30172),
    2.0: (-0.16064, -0.49346),
}


def neo_hookean_pressure_stretch(mu: float, lmbda: float, p: float, follower: bool) -> float:
    """Stretch ``l`` of a plane-strain Neo-Hookean block in homogeneous biaxial compression.

    The block is loaded by a pressure ``p`` on all its sides (``F = diag(l, l, 1)``); with
    :class:`~contact_ufl.materials.NeoHookean`, ``P = mu (F - F^-T) + lambda ln(J) F^-T`` and
    ``P_11 = mu (l - 1/l) + 2 lambda ln(l) / l``. A follower pressure (``p`` per unit current
    area, nominal traction ``-p J F^-T N = -p l N``) gives ``P_11 = -p l``; a dead traction
    ``-p N`` per unit reference area gives ``P_11 = -p``.

    Parameters
    ----------
    mu, lmbda
        Lame parameters.
    p
        Pressure (positive in compression, ``0 <= p``).
    follower
        Follower pressure or dead traction.

    Returns
    -------
    The stretch ``l`` (``<= 1``).
    """
    from scipy.optimize import brentq

    def residual(l: float) -> float:
        load = -p * l if follower else -p
        return mu * (l - 1.0 / l) + 2.0 * lmbda * np.log(l) / l - load

    return float(brentq(residual, 1e-6, 1.0, xtol=1e-15))


@dataclass(frozen=True)
class CattaneoMindlin2D:
    """Plane Cattaneo-Mindlin problem: two elastically identical cylinders under the normal
    load ``P`` and then a monotonically increasing tangential load ``Q < mu P`` (per unit
    length). The stick zone is ``|x| < c`` with ``c = a sqrt(1 - Q / (mu P))``; the shear
    traction is ``mu p0 (sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2))`` in it and ``mu p(x)``
    in the slip zones (Johnson, *Contact Mechanics*, 1985, section 7.1).
    """

    hertz: Hertz2D
    Q: float
    mu: float

    @property
    def c(self) -> float:
        """Half-width of the stick zone."""
        return self.hertz.a * float(np.sqrt(1.0 - self.Q / (self.mu * self.hertz.P)))

    def shear(self, x: np.ndarray) -> np.ndarray:
        """Magnitude of the shear traction at distance ``x`` from the centre."""
        x = np.asarray(x)
        a, c, p0 = self.hertz.a, self.c, self.hertz.p0
        stick = self.mu * (c / a) * p0 * np.sqrt(np.clip(1.0 - (x / c) ** 2, 0.0, None))
        return self.mu * self.hertz.pressure(x) - np.where(np.abs(x) < c, stick, 0.0)


# -- 3D Hertz: a sphere on a flat ---------------------------------------------------------------


@dataclass(frozen=True)
class Hertz3D:
    """Hertz contact of a sphere of radius ``R`` on a flat (or of two spheres, ``1/R = 1/R1 +
    1/R2``), both bodies elastic half-spaces of contact modulus ``E*``
    (:func:`plane_strain_modulus`), under the force ``P``.

    The contact area is a disc of radius ``a`` and the pressure ``p(r) = p0 sqrt(1 - r^2 /
    a^2)`` (Johnson, *Contact Mechanics*, 1985, section 4.2). Derivation: this pressure on a
    half-space displaces its surface normally by ``u_z = pi p0 (2 a^2 - r^2) / (4 a E_i')``,
    ``E_i' = E_i / (1 - nu_i^2)``, for ``r <= a`` (Johnson 3.41); the two surfaces together
    move by ``u_z1 + u_z2 = pi p0 (2 a^2 - r^2) / (4 a E*)``, and within the contact disc
    this must close the initial gap ``r^2 / (2 R)`` up to the approach ``d`` of distant
    points: ``pi p0 (2 a^2 - r^2) / (4 a E*) = d - r^2 / (2 R)`` for all ``r <= a``. The
    ``r^2`` terms give ``a = pi p0 R / (2 E*)``, the constants ``d = pi a p0 / (2 E*) = a^2
    / R``. The force is ``P = int p dA = 2 pi a^2 p0 / 3``. Eliminating ``p0``: ``a^3 = 3 P
    R / (4 E*)``, ``p0 = 3 P / (2 pi a^2) = (6 P E*^2 / (pi^3 R^2))^(1/3)``; in terms of the
    approach: ``a = sqrt(R d)`` and ``P = 4/3 E* sqrt(R) d^(3/2)``.
    """

    P: float
    R: float
    E_star: float

    @classmethod
    def from_approach(cls, d: float, R: float, E_star: float) -> Hertz3D:
        """The contact under the approach ``d`` of distant points: ``P = 4/3 E* sqrt(R)
        d^(3/2)``."""
        return cls(4.0 / 3.0 * E_star * np.sqrt(R) * d**1.5, R, E_star)

    @property
    def a(self) -> float:
        """Contact radius ``(3 P R / (4 E*))^(1/3)``."""
        return float(np.cbrt(3.0 * self.P * self.R / (4.0 * self.E_star)))

    @property
    def p0(self) -> float:
        """Peak pressure ``(6 P E*^2 / (pi^3 R^2))^(1/3) = 3 P / (2 pi a^2)``."""
        return float(np.cbrt(6.0 * self.P * self.E_star**2 / (np.pi**3 * self.R**2)))

    @property
    def approach(self) -> float:
        """Approach of distant points ``d = a^2 / R``."""
        return self.a**2 / self.R

    def pressure(self, r: np.ndarray) -> np.ndarray:
        """Pressure at distance ``r`` from the centre of contact."""
        return self.p0 * np.sqrt(np.clip(1.0 - (np.asarray(r) / self.a) ** 2, 0.0, None))


def fit_radial_profile(
    r: np.ndarray, p: np.ndarray, weights: np.ndarray | None = None
) -> tuple[float, float]:
    """The Hertz profile ``p0 sqrt(1 - r^2 / a^2)`` (zero beyond ``a``) nearest to samples
    ``p`` at radii ``r`` in the weighted L2 sense; return ``(a, p0)``.

    Minimises ``sum w (p - p0 s_a)^2``, ``s_a = sqrt(max(1 - r^2 / a^2, 0))``. For a given
    ``a`` the best ``p0 = sum w p s_a / sum w s_a^2``; the misfit, continuous in ``a``, is
    then minimised over ``a`` between half and twice the radius of the farthest sample
    above a tenth of the largest (bounded Brent). With the quadrature weights of the samples
    the fit uses the whole profile, the smeared edge and the tail beyond it included.
    """
    from scipy.optimize import minimize_scalar

    r, p = np.asarray(r, dtype=float), np.asarray(p, dtype=float)
    w = np.ones_like(p) if weights is None else np.asarray(weights, dtype=float)

    def best_p0(a: float) -> tuple[float, float]:
        s = np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None))
        p0 = np.sum(w * p * s) / np.sum(w * s * s)
        return float(p0), float(np.sum(w * (p - p0 * s) ** 2))

    a0 = float(r[p > 0.1 * p.max()].max())
    fit = minimize_scalar(
        lambda a: best_p0(a)[1],
        bounds=(0.5 * a0, 2.0 * a0),
        method="bounded",
        options={"xatol": 1e-8 * a0},
    )
    return float(fit.x), best_p0(fit.x)[0]
