"""Bulk materials: strain energies written once in UFL (hyperelastic, and small-strain Hooke).

Each material is a stored-energy density ``psi(F)`` per unit reference volume. The first
Piola-Kirchhoff stress is its derivative, taken by UFL. The same expression serves 3D solids
and 2D plane strain (a 2x2 deformation gradient with F_33 = 1: the terms below are written
with the dimension ``d`` of ``F`` so that they equal the 3D energy in plane strain).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import ufl

from contact_ufl.errors import ContactInputError

#: Poisson's ratio above which a solid is nearly incompressible (see :func:`lame_parameters`)
NEARLY_INCOMPRESSIBLE = 0.45


class NearlyIncompressibleWarning(UserWarning):
    """A solid with Poisson's ratio near 1/2: displacement-only elements lock."""


def warn_if_nearly_incompressible(nu: float) -> None:
    """Warn for ``nu > NEARLY_INCOMPRESSIBLE``: the package's elements are displacement only
    (no mixed pressure), which lock as ``nu -> 1/2``."""
    if nu > NEARLY_INCOMPRESSIBLE:
        warnings.warn(
            f"Poisson's ratio nu = {nu} is nearly incompressible: displacement-only elements "
            "lock (the body is too stiff and its pressure oscillates), P1 most; this package "
            "has no mixed (u, p) formulation. Use degree=2 and check the answer on a finer "
            "mesh, or a smaller nu where the body's compressibility does not matter",
            NearlyIncompressibleWarning,
            stacklevel=4,
        )


def lame_parameters(E: float, nu: float) -> tuple[float, float]:
    """Shear modulus and first Lame parameter of Young's modulus ``E`` and Poisson ratio ``nu``;
    a :class:`~contact_ufl.errors.ContactInputError` for ``E`` not positive and finite or
    ``nu`` outside ``(-1, 0.5)`` (NaN included). Every rank makes the same material, so every
    rank raises."""
    if not 0.0 < E < math.inf:
        raise ContactInputError(f"Young's modulus must be positive and finite, got E = {E}")
    if not -1.0 < nu < 0.5:
        raise ContactInputError(f"Poisson's ratio must lie in (-1, 0.5), got nu = {nu}")
    mu = E / (2.0 * (1.0 + nu))
    lmbda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    return mu, lmbda


@dataclass(frozen=True)
class Hyperelastic:
    """Base class of isotropic hyperelastic materials given by ``E`` and ``nu``.

    Parameters
    ----------
    E
        Young's modulus (small-strain limit).
    nu
        Poisson's ratio (small-strain limit).
    """

    E: float
    nu: float

    def __post_init__(self) -> None:
        lame_parameters(self.E, self.nu)
        warn_if_nearly_incompressible(self.nu)

    @property
    def mu(self) -> float:
        """Shear modulus."""
        return lame_parameters(self.E, self.nu)[0]

    @property
    def lmbda(self) -> float:
        """First Lame parameter."""
        return lame_parameters(self.E, self.nu)[1]

    def strain_energy(self, F: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """Stored energy per unit reference volume."""
        raise NotImplementedError

    def first_piola(self, F: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """First Piola-Kirchhoff stress ``d psi / d F``."""
        Fv = ufl.variable(F)
        return ufl.diff(self.strain_energy(Fv), Fv)


@dataclass(frozen=True)
class NeoHookean(Hyperelastic):
    """Compressible Neo-Hookean solid.

    ``psi = mu/2 (tr C - 3 - 2 ln J) + lambda/2 (ln J)^2`` (Ciarlet/Simo form).
    """

    def strain_energy(self, F):
        d = F.ufl_shape[0]
        C = F.T * F
        J = ufl.det(F)
        return 0.5 * self.mu * (ufl.tr(C) - d - 2.0 * ufl.ln(J)) + 0.5 * self.lmbda * ufl.ln(J) ** 2


@dataclass(frozen=True)
class SaintVenantKirchhoff(Hyperelastic):
    """Saint Venant-Kirchhoff solid: ``psi = lambda/2 (tr E)^2 + mu tr(E^2)``, E Green-Lagrange.

    Valid for large rotations with small strains; not polyconvex (it softens in compression).
    """

    def strain_energy(self, F):
        d = F.ufl_shape[0]
        E = 0.5 * (F.T * F - ufl.Identity(d))
        return 0.5 * self.lmbda * ufl.tr(E) ** 2 + self.mu * ufl.inner(E, E)


@dataclass(frozen=True)
class LinearElastic(Hyperelastic):
    """Small-strain linear elasticity (Hooke): ``psi = lambda/2 (tr eps)^2 + mu eps : eps``.

    ``eps = sym(F - I)`` is the small-strain tensor of the displacement gradient ``F - I``, and
    the stress ``P = lambda tr(eps) I + 2 mu eps`` is linear in it. Use it for scenes whose
    strains *and rotations* are small (the energy is not frame-indifferent: a rigid rotation
    strains it): it is the cheapest bulk (a constant tangent) and the one Hertz's solution is
    exact for. The contact kinematics stay large-deformation. In plane strain (``F`` 2x2) the
    energy equals the 3D one with ``eps_33 = 0``.
    """

    def small_strain(self, F: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """``eps = sym(F - I)``."""
        return ufl.sym(F - ufl.Identity(F.ufl_shape[0]))

    def strain_energy(self, F):
        eps = self.small_strain(F)
        return 0.5 * self.lmbda * ufl.tr(eps) ** 2 + self.mu * ufl.inner(eps, eps)

    def first_piola(self, F):
        """Hooke's stress ``lambda tr(eps) I + 2 mu eps`` (the derivative of the energy)."""
        eps = self.small_strain(F)
        return self.lmbda * ufl.tr(eps) * ufl.Identity(F.ufl_shape[0]) + 2.0 * self.mu * eps
