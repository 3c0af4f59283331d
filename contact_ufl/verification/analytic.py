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


def _elastica_tip(k: float, psi0: float, psiL: float) -> tuple[float, float]:
    """Chord of the elastica ``psi'' + k sin(psi) = 0`` on ``0 <= s <= 1`` from ``psi0`` to
    the turning point ``psiL`` (``psi'(1) = 0``), ``psi = pi/2 - phi`` with ``phi`` the
    tangent's angle in the frame of the load: its components ``(dx', dy')`` across and along
    the load's line, by the closed forms of :func:`cantilever_elastica`."""
    from scipy.special import ellipe, ellipeinc

    m = np.sin(0.5 * psiL) ** 2
    eta0 = np.arcsin(np.clip(np.sin(0.5 * psi0) / np.sqrt(m), -1.0, 1.0))
    dx = np.sqrt(2.0 * (np.cos(psi0) - np.cos(psiL)) / k)
    dy = 2.0 * (ellipe(m) - ellipeinc(eta0, m)) / np.sqrt(k) - 1.0
    return float(dx), float(dy)


def cantilever_elastica(k: float, follower: bool) -> tuple[float, float, float]:
    """Tip of an inextensible, shear-rigid cantilever (Euler elastica) under a tip force, in
    closed form (elliptic integrals).

    The beam of length ``L`` lies along ``+x``, clamped at ``x = 0``; the force of magnitude
    ``P`` at ``x = L`` points initially in ``-y``. ``follower=True``: the force stays
    perpendicular to the deformed tip tangent (follower load); ``False``: it stays in ``-y``
    (dead load). Lengths over ``L``, ``k = P L^2 / EI``.

    Derivation. In equilibrium the follower force is a fixed force, ``P (sin theta_L, -cos
    theta_L)`` with ``theta_L`` the final tip angle: the beam has the shape of a cantilever
    under that dead force. In a frame turned so that this force points in ``-y'``, with
    ``phi(s)`` the tangent's angle there, the bending moment is that of the tip force about
    the point at ``s``, ``EI phi' = M = -P (x'_L - x')``, so ``M' = P cos(phi)``; with ``psi
    = pi/2 - phi`` this is the pendulum ``psi'' + k sin(psi) = 0``; the free tip, ``psi'(1)
    = 0``, is its turning point ``psi_L``, and ``psi'^2 = 2 k (cos psi - cos psi_L)``. With
    ``sin(psi / 2) = p sin(eta)``, ``p = sin(psi_L / 2)``, ``m = p^2``, the length is
    ``sqrt(k) = K(m) - F(eta_0 | m)`` (``eta = pi/2`` at the tip, ``eta_0`` at the clamp's
    ``psi_0``), and the chord has ``dx' = int sin(psi) ds = psi'(0) / k = sqrt(2 (cos psi_0
    - cos psi_L) / k)`` (from ``sin psi = -psi'' / k``) across the load and ``dy' = int
    cos(psi) ds = int (1 - 2 m sin^2 eta) ds = 2 (E(m) - E(eta_0 | m)) / sqrt(k) - 1``
    along it (``F``, ``E``: incomplete elliptic integrals of the first and second kind,
    ``K``, ``E``: complete).

    * Dead force (Bisshopp & Drucker, "Large deflection of cantilever beams", Q. Appl. Math.
      3, 272-275, 1945): the frame is the global one, ``psi_0 = pi/2`` at the clamp and the
      unknown amplitude ``psi_L = pi/2 - theta_L`` solves ``K(m) - F(eta_0 | m) = sqrt(k)``,
      ``sin(eta_0) = sin(pi/4) / p``.
    * Follower force: the force is perpendicular to the tip, ``psi_L = pi/2``: ``m = 1/2``
      for every load, and the clamp's angle in the turned frame, ``phi_0 = -theta_L``
      (``psi_0 = pi/2 + theta_L``), solves ``F(eta_0 | 1/2) = K(1/2) - sqrt(k)`` with
      ``sin(psi_0 / 2) = sin(eta_0) / sqrt(2)``; the chord is turned back by ``theta_L``.
      (The classical follower-load benchmark, e.g. Argyris & Symeonidis, Comput. Methods
      Appl. Mech. Eng. 26, 75-123, 1981.)

    Each case is one scalar equation, solved by bisection (``brentq``).

    Parameters
    ----------
    k
        Load parameter ``P L^2 / EI`` (``EI`` per unit width in plane strain, see
        :func:`bending_stiffness_plane_strain`); ``0 < k < 4 K(1/2)^2 = 13.75`` for the
        follower force (a tip rotation below pi).
    follower
        Follower (perpendicular to the deformed axis) or dead (fixed ``-y``) force.

    Returns
    -------
    u/L, v/L, theta_L
        Tip displacement along and across the undeformed axis, over ``L``, and the tip
        rotation (radians, negative: clockwise).
    """
    from scipy.optimize import brentq
    from scipy.special import ellipk, ellipkinc

    root_k = np.sqrt(k)
    if follower:
        K = ellipk(0.5)
        if not 0.0 < root_k < 2.0 * K:
            raise ValueError(f"k = {k} is not in (0, 4 K(1/2)^2) = (0, {4.0 * K**2:.4f})")
        eta0 = brentq(
            lambda eta: ellipkinc(eta, 0.5) - (K - root_k), -0.5 * np.pi, 0.5 * np.pi, xtol=1e-15
        )
        psi0, psiL = 2.0 * np.arcsin(np.sin(eta0) / np.sqrt(2.0)), 0.5 * np.pi
        theta_L = psi0 - 0.5 * np.pi
    else:
        if not 0.0 < root_k < np.inf:
            raise ValueError(f"k = {k} must be positive and finite")
        psi0 = 0.5 * np.pi

        def length(psiL: float) -> float:
            m = np.sin(0.5 * psiL) ** 2
            return ellipk(m) - ellipkinc(np.arcsin(np.sin(0.25 * np.pi) / np.sqrt(m)), m) - root_k

        psiL = brentq(length, 0.5 * np.pi * (1.0 + 1e-14), np.pi * (1.0 - 1e-14), xtol=1e-15)
        theta_L = 0.5 * np.pi - psiL
    dx, dy = _elastica_tip(k, psi0, psiL)
    # turn the chord back into the global frame, where the clamp's tangent is along x
    turn = theta_L if follower else 0.0
    c, s = np.cos(turn), np.sin(turn)
    return float(c * dx - s * dy - 1.0), float(s * dx + c * dy), float(theta_L)


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


# -- Free inflation of membranes under a follower pressure -------------------------------------
#
# A pressure p (per unit current area) inflates a membrane of reference radius R and
# thickness t0 homogeneously: every point moves radially, the stretch l = r / R is uniform.
# With W(l) the membrane energy per unit reference area, the virtual work balance of a
# sphere, 4 pi R^2 W'(l) = p dV/dl with V = 4/3 pi R^3 l^3, gives p = W'(l) / (R l^2); of a
# long tube at axial stretch 1 (per unit length, or a plane-strain string ring per unit
# depth), 2 pi R W'(l) = p dV/dl with V = pi R^2 l^2, gives p = W'(l) / (R l).


def sphere_inflation_neo_hookean(mu: float, t0: float, R: float, stretch):
    """Pressure of an incompressible Neo-Hookean spherical membrane at the stretch ``l``.

    Equi-biaxial stretches ``l, l`` and the thickness stretch ``1/l^2``: ``W = t0 mu/2 (2 l^2
    + l^-4 - 3)``, ``W' = 2 t0 mu (l - l^-5)`` and ``p = 2 mu t0 / R (1/l - 1/l^7)``; its
    maximum is at ``l = 7^(1/6)``.
    """
    l = np.asarray(stretch, dtype=float)
    return 2.0 * mu * t0 / R * (1.0 / l - l**-7)


def sphere_inflation_svk(E: float, nu: float, t0: float, R: float, stretch):
    """Pressure of a Saint Venant-Kirchhoff spherical membrane (plane stress) at the stretch ``l``.

    ``E_s = e I`` with ``e = (l^2 - 1)/2``: ``W = t0 E / (2 (1 - nu^2)) ((1 - nu) 2 e^2 + nu (2
    e)^2) = t0 E e^2 / (1 - nu)``, ``W' = 2 t0 E e l / (1 - nu)`` and ``p = t0 E (l^2 - 1) /
    ((1 - nu) R l)``.
    """
    l = np.asarray(stretch, dtype=float)
    return t0 * E * (l**2 - 1.0) / ((1.0 - nu) * R * l)


def tube_inflation_neo_hookean(mu: float, t0: float, R: float, stretch):
    """Pressure of an incompressible Neo-Hookean tube at axial stretch 1 (hoop stretch ``l``).

    Stretches ``l, 1`` and the thickness stretch ``1/l``: ``W = t0 mu/2 (l^2 + l^-2 - 2)``,
    ``W' = t0 mu (l - l^-3)`` and ``p = mu t0 / R (1 - l^-4)`` (bounded by ``mu t0 / R``).
    """
    l = np.asarray(stretch, dtype=float)
    return mu * t0 / R * (1.0 - l**-4)


def tube_inflation_svk(E: float, nu: float, t0: float, R: float, stretch):
    """Pressure of a Saint Venant-Kirchhoff tube (plane stress) at axial stretch 1.

    ``E_s = diag(e, 0)`` with ``e = (l^2 - 1)/2``: ``W = t0 E e^2 / (2 (1 - nu^2))``, ``W' = t0 E
    e l / (1 - nu^2)`` and ``p = t0 E (l^2 - 1) / (2 (1 - nu^2) R)``.
    """
    l = np.asarray(stretch, dtype=float)
    return t0 * E * (l**2 - 1.0) / (2.0 * (1.0 - nu**2) * R)


def _condensed_neo_hookean(E: float, nu: float, area_stretch_sq):
    """Lame parameters and ``J^2`` of the compressible Neo-Hookean membrane in plane stress
    (:class:`~contact_ufl.membranes.MembraneCompressibleNeoHookean`): ``l3^2 = (2 mu +
    lambda) / (2 mu + lambda J_s^2)``, ``J^2 = J_s^2 l3^2``."""
    mu = E / (2.0 * (1.0 + nu))
    lmbda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    J_sq = area_stretch_sq * (2.0 * mu + lmbda) / (2.0 * mu + lmbda * area_stretch_sq)
    return mu, lmbda, J_sq


def sphere_inflation_compressible_neo_hookean(E: float, nu: float, t0: float, R: float, stretch):
    """Pressure of a compressible Neo-Hookean spherical membrane (plane stress) at ``l``.

    ``psi = mu/2 (I1 - 3 - 2 ln J) + lambda/4 (J^2 - 1 - 2 ln J)`` with ``I1 = 2 l^2 + l3^2``,
    ``J = l^2 l3`` and ``l3`` condensed (``d psi / d l3 = 0``); by that condition ``W' = t0
    d psi / d l`` at fixed ``l3`` ``= t0 (2 mu (l - 1/l) + lambda (J^2 - 1) / l)``, and ``p = W'
    / (R l^2)``.
    """
    l = np.asarray(stretch, dtype=float)
    mu, lmbda, J_sq = _condensed_neo_hookean(E, nu, l**4)
    return t0 * (2.0 * mu * (l - 1.0 / l) + lmbda * (J_sq - 1.0) / l) / (R * l**2)


def tube_inflation_compressible_neo_hookean(E: float, nu: float, t0: float, R: float, stretch):
    """Pressure of a compressible Neo-Hookean tube (plane stress) at axial stretch 1.

    ``I1 = l^2 + 1 + l3^2``, ``J = l l3``, ``l3`` condensed: ``W' = t0 (mu (l - 1/l) + lambda
    (J^2 - 1) / (2 l))`` and ``p = W' / (R l)``.
    """
    l = np.asarray(stretch, dtype=float)
    mu, lmbda, J_sq = _condensed_neo_hookean(E, nu, l**2)
    return t0 * (mu * (l - 1.0 / l) + lmbda * (J_sq - 1.0) / (2.0 * l)) / (R * l)


# -- An inflated tube pressed between two rigid plates -----------------------------------------
#
# A Neo-Hookean tube of reference radius R0 and thickness t0 (a long tube at axial stretch 1,
# per unit length; or a string ring in 2D, plane strain, per unit depth: the same law with the
# out-of-plane stretch 1) is inflated to the pressure p and then pressed between two
# frictionless rigid flat plates at y = +-r. See :func:`tube_between_plates`.


def tube_hoop_tension_neo_hookean(mu: float, t0: float, stretch):
    """Hoop tension (force per unit length of the tube, or per unit depth of a string) of the
    incompressible Neo-Hookean tube at axial stretch 1 and hoop stretch ``l``.

    :class:`~contact_ufl.membranes.MembraneNeoHookean` stores ``W = t0 mu/2 (I1 + J_s^-2 - 3)``
    per unit reference area with ``I1 = l^2 + 1`` and ``J_s = l`` (the string: its
    out-of-plane stretch 1 in ``I1``): ``W = t0 mu/2 (l^2 + l^-2 - 2)``. The tension is the
    work conjugate of the stretch, ``T = dW/dl = mu t0 (l - l^-3)`` (per unit reference
    axial length, which is the current one at axial stretch 1; a string's tension is a force,
    the same per unit reference or current length). It grows monotonically with ``l``.
    """
    l = np.asarray(stretch, dtype=float)
    return mu * t0 * (l - l**-3)


def _check_tube(mu: float, t0: float, R0: float, p: float) -> None:
    for name, value in (("mu", mu), ("t0", t0), ("R0", R0), ("p", p)):
        if not 0.0 < value < np.inf:
            raise ValueError(f"{name} must be positive and finite, got {name} = {value}")
    if not p * R0 < mu * t0:
        raise ValueError(
            f"the pressure p = {p} reaches the tube's limit mu t0 / R0 = {mu * t0 / R0}: "
            "no free equilibrium (the Neo-Hookean tube inflates without bound)"
        )


def tube_free_radius(mu: float, t0: float, R0: float, p: float) -> float:
    """Radius ``r_free`` of the Neo-Hookean tube freely inflated to the pressure ``p``.

    Equilibrium of the circular tube, ``T = p r`` with ``r = l R0`` and ``T = mu t0 (l -
    l^-3)`` (:func:`tube_hoop_tension_neo_hookean`), gives ``p = mu t0 / R0 (1 - l^-4)``
    (:func:`tube_inflation_neo_hookean`), whence ``r_free = R0 (1 - p R0 / (mu t0))^(-1/4)``.
    Needs ``0 < p < mu t0 / R0`` (``ValueError`` otherwise).
    """
    _check_tube(mu, t0, R0, p)
    return R0 * (1.0 - p * R0 / (mu * t0)) ** -0.25


def _hoop_stretch(q: np.ndarray) -> np.ndarray:
    """The root ``l >= 1`` of ``l - l^-3 = q`` (``q >= 0``), by Newton's method from ``l = 1``.

    ``f(l) = l - l^-3 - q`` is increasing and concave for ``l > 0``: its tangents lie above
    it, so the iterates from ``f(1) = -q <= 0`` stay left of the root and increase to it.
    """
    l = np.ones_like(q)
    for _ in range(100):
        f = l - l**-3 - q
        if np.all(np.abs(f) <= 1e-15 * (1.0 + q)):
            break
        l = l - f / (1.0 + 3.0 * l**-4)
    return l


def tube_between_plates(mu: float, t0: float, R0: float, p: float, r) -> dict[str, np.ndarray]:
    """The inflated Neo-Hookean tube pressed between two frictionless rigid flat plates.

    The tube (reference radius ``R0``, thickness ``t0``, shear modulus ``mu``; a long tube
    at axial stretch 1 per unit length, or a string ring in 2D per unit depth) holds the
    pressure ``p`` (per unit current area, constant) and lies between the plates ``y = -r``
    and ``y = r``, ``r <= r_free`` (:func:`tube_free_radius`).

    Derivation. The plates are frictionless and the pressure normal to the tube, so no load
    is tangential: the tangential equilibrium of the tube, ``dT/ds = 0``, makes the tension
    ``T`` uniform, hence (``T(l)`` increasing) the hoop stretch ``l`` uniform. Normal
    equilibrium of the free parts, ``T kappa = p``, makes them arcs of one curvature; each
    joins the two plates tangentially (a membrane has no bending stiffness, but a kink would
    carry a concentrated force, which the plates cannot give outside the contact zones and
    the pressure cannot give at all), so each is a half circle of diameter ``2r``: ``T = p
    r``. In a flat contact zone ``kappa = 0``, so the contact pressure equals ``p``. The
    cross-section is a stadium: two flat zones of width ``w`` (one on each plate, ``|x| <=
    w/2``) and two half circles of radius ``r`` centred at ``(+-w/2, 0)``; its current length
    is the reference length stretched, ``2 pi r + 2 w = 2 pi R0 l``. Hence

    * ``mu t0 (l - l^-3) = p r`` (:func:`tube_hoop_tension_neo_hookean`): ``l``, one root
      ``l >= 1`` found by Newton's method;
    * ``w = pi (R0 l - r)``: the contact width on each plate;
    * the plate force ``F = p w`` (per unit length; in 2D per unit depth): the contact
      pressure ``p`` over the width ``w``; the same from the vertical balance of the upper
      half, cut at ``y = 0``: the pressure lifts it by ``p (w + 2 r)``, the tension at the
      two cuts pulls it down by ``2 T = 2 p r``, so the plate pushes down by ``F = p w``.

    At ``r = r_free``, ``w = 0``; as ``mu -> inf`` (a rigid tube) ``l -> 1`` and ``w -> pi
    (R0 - r)``. Frictionless contact makes the state path independent: a test may inflate
    the tube freely to ``p`` first (the plates away) and then close the plates from
    ``r_free`` to ``r`` at constant ``p`` (the pressure is the control; solved
    quasi-statically, the end state is this one).

    Parameters
    ----------
    mu, t0, R0
        Shear modulus, reference thickness (a string: cross-section area per unit depth) and
        reference radius.
    p
        Inflation pressure, ``0 < p < mu t0 / R0``.
    r
        Half the separation of the plates (scalar or array), ``0 < r <= r_free``.

    Returns
    -------
    dict
        ``stretch`` (the uniform hoop stretch ``l``), ``width`` (the contact width ``w`` on
        each plate), ``force`` (``p w``, per plate), ``tension`` (``T = p r``) and
        ``contact_pressure`` (``p``), as arrays of the shape of ``r``.

    Raises
    ------
    ValueError
        A non-positive parameter, ``p >= mu t0 / R0``, or ``r`` not in ``(0, r_free]`` (the
        plates do not touch the tube).
    """
    r_free = tube_free_radius(mu, t0, R0, p)
    r = np.asarray(r, dtype=float)
    beyond = ~((r > 0.0) & (r <= r_free * (1.0 + 1e-12)))
    if np.any(beyond):
        raise ValueError(
            f"half plate separation r = {r[beyond].ravel()[0]} is not in (0, r_free], "
            f"r_free = {r_free} (the free radius at p = {p}): the plates would not touch the "
            "tube"
        )
    l = _hoop_stretch(p * r / (mu * t0))
    width = np.maximum(np.pi * (R0 * l - r), 0.0)
    return {
        "stretch": l,
        "width": width,
        "force": p * width,
        "tension": p * r,
        "contact_pressure": np.full_like(r, p),
    }


# -- A pre-tensioned square membrane under a small uniform pressure ----------------------------


def pretensioned_square_membrane(T: float, p: float, L: float, x, y, terms: int = 201):
    """Small deflection ``w(x, y)`` of a square membrane ``[0, L]^2`` under the uniform
    tension ``T`` (force per unit length) and a uniform pressure ``p``, clamped on its edges.

    Linearised about the flat tensioned state, the transverse equilibrium is ``T Laplace w =
    -p`` with ``w = 0`` on the edges (Prandtl's torsion problem). With ``p = sum_{m, n odd}
    16 p / (pi^2 m n) sin(m pi x / L) sin(n pi y / L)``,

    ``w = 16 p L^2 / (pi^4 T) sum_{m, n odd} sin(m pi x / L) sin(n pi y / L) / (m n (m^2 +
    n^2))``;

    at the centre ``w = 0.0736713... p L^2 / T``. Valid while the added strain ``~ (w / L)^2``
    is small beside the pre-strain (the tension stays ``T``). The series runs over odd ``m, n
    < terms``; its terms fall like ``1 / (m n (m^2 + n^2))``.

    Parameters
    ----------
    T, p, L
        Tension, pressure and side (in the current configuration).
    x, y
        Points (arrays of one shape) in ``[0, L]^2``.
    terms
        Upper bound of the odd indices of the series.
    """
    k = np.arange(1, terms, 2, dtype=float)
    m, n = np.meshgrid(k, k, indexing="ij")
    coefficient = 1.0 / (m * n * (m**2 + n**2))
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    sx = np.sin(np.pi * np.multiply.outer(x, k) / L)
    sy = np.sin(np.pi * np.multiply.outer(y, k) / L)
    series = np.einsum("...m,mn,...n->...", sx, coefficient, sy)
    return 16.0 * p * L**2 / (np.pi**4 * T) * series


def equibiaxial_tension_neo_hookean(mu: float, t0: float, stretch: float) -> float:
    """Cauchy tension (force per unit *current* length) of the incompressible Neo-Hookean
    membrane stretched equi-biaxially by ``s``.

    ``W = t0 mu/2 (l1^2 + l2^2 + (l1 l2)^-2 - 3)``: the nominal tension ``dW/dl1 = mu t0 (l1 -
    l1^-3 l2^-2)`` per unit reference length, over ``l2`` per unit current length; at ``l1 =
    l2 = s``, ``T = mu t0 (1 - s^-6)``.
    """
    return mu * t0 * (1.0 - stretch**-6)


def pressurised_string(mu: float, t0: float, a: float, chord: float, p: float) -> dict[str, float]:
    """A Neo-Hookean string of reference length ``2 a`` whose ends are held on a chord of
    length ``2 chord`` (e.g. the pre-stretched string drumhead: ``chord = stretch * a``),
    under a uniform follower pressure ``p`` (plane strain, per unit depth).

    No load is tangential, so the tension ``T`` and the stretch ``l`` are uniform and the
    string is a circular arc of radius ``rho = T / p`` (``T kappa = p``), of half angle
    ``theta`` with ``rho sin(theta) = chord`` and length ``2 rho theta = 2 a l``; with ``T =
    mu t0 (l - l^-3)`` (:func:`tube_hoop_tension_neo_hookean`), one equation in ``theta in (0,
    pi/2]``: ``T(rho theta / a) = p rho``, ``rho = chord / sin(theta)``, solved by bisection
    (``brentq``). The sag (the arc's height over the chord) is ``rho (1 - cos theta)``; the
    small-deflection limit is the parabola ``p (chord^2 - x^2) / (2 T)``.

    Returns
    -------
    dict
        ``radius`` ``rho``, ``half_angle`` ``theta``, ``stretch`` ``l``, ``tension`` ``T``,
        ``sag``.

    Raises
    ------
    ValueError
        Non-positive parameters, a chord shorter than ``2 a`` (a slack string), or a pressure
        that would blow the string beyond a half circle.
    """
    from scipy.optimize import brentq

    for name, value in (("mu", mu), ("t0", t0), ("a", a), ("chord", chord), ("p", p)):
        if not 0.0 < value < np.inf:
            raise ValueError(f"{name} must be positive and finite, got {name} = {value}")
    if not chord > a:
        raise ValueError(f"the chord {chord} must exceed the half length {a}: the string is slack")

    def residual(theta: float) -> float:
        rho = chord / np.sin(theta)
        return float(tube_hoop_tension_neo_hookean(mu, t0, rho * theta / a)) - p * rho

    if residual(0.5 * np.pi) <= 0.0:
        raise ValueError(f"the pressure p = {p} blows the string beyond a half circle")
    theta = brentq(residual, 1e-12, 0.5 * np.pi, xtol=1e-15, rtol=1e-15)
    rho = chord / np.sin(theta)
    return {
        "radius": rho,
        "half_angle": theta,
        "stretch": rho * theta / a,
        "tension": p * rho,
        "sag": rho * (1.0 - np.cos(theta)),
    }


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
