"""Finite-strain J2 elastoplasticity (Simo 1988; Simo & Hughes 1998, Box 9.1).

Multiplicative split ``F = F_e F_p``, an uncoupled Neo-Hookean-type elastic energy
``psi = U(J) + mu/2 (tr bbar_e - 3)`` with ``U(J) = kappa/2 ((J^2 - 1)/2 - ln J)`` and
``bbar_e = J^(-2/3) F C_p^-1 F^T``, the von Mises yield function
``f = |s| - sqrt(2/3) (sigma_y + H alpha)`` on the Kirchhoff deviator ``s = mu dev bbar_e``,
linear isotropic hardening ``H``, and the associative flow rule integrated by the
radial return of the box:

- trial state: ``bbar_e^tr = J^(-2/3) F C_p,n^-1 F^T``, ``s^tr = mu dev bbar_e^tr``,
  ``mubar = mu tr(bbar_e^tr) / 3``;
- where ``f^tr > 0``: ``dgamma = f^tr / (2 mubar (1 + H / (3 mubar)))``,
  ``s = s^tr - 2 mubar dgamma s^tr / |s^tr|``, ``alpha = alpha_n + sqrt(2/3) dgamma``;
- Kirchhoff stress ``tau = J U'(J) I + s``; ``P = tau F^-T``;
- history: ``bbar_e = s / mu + c I`` with ``c`` (close to ``tr(bbar_e^tr) / 3``) such that
  ``det bbar_e = 1`` (the flow keeps the volume), stored as
  ``C_p^-1 = J^(2/3) F^-1 bbar_e F^-T``.

The return map is closed-form UFL (a conditional on ``f^tr``), so ``ufl.derivative`` of the
residual is the consistent (algorithmic) tangent. The history lives at the quadrature
points of the bulk integrals and moves only when a step is committed, so a step that is cut
back starts again from the same history. Plane strain embeds the 2x2 ``F`` in 3x3 with
``F_33 = 1``; the history is 3x3 (``C_p,33`` evolves).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import basix.ufl
import dolfinx
import numpy as np
import ufl
from petsc4py import PETSc

from contact_ufl import jit
from contact_ufl.errors import ContactInputError
from contact_ufl.loads import deformation_gradient
from contact_ufl.materials import lame_parameters, warn_if_nearly_incompressible


@dataclass(frozen=True)
class J2Plasticity:
    """Finite-strain von Mises plasticity with linear isotropic hardening.

    Parameters
    ----------
    E, nu
        Young's modulus and Poisson's ratio (small-strain limit of the elastic response).
    yield_stress
        Initial yield stress ``sigma_y`` (Kirchhoff, uniaxial).
    hardening
        Linear isotropic hardening modulus ``H`` (0: perfect plasticity).
    """

    E: float
    nu: float
    yield_stress: float
    hardening: float = 0.0

    def __post_init__(self) -> None:
        lame_parameters(self.E, self.nu)
        warn_if_nearly_incompressible(self.nu)
        if not 0.0 < self.yield_stress < np.inf:
            raise ContactInputError(
                f"the yield stress must be positive and finite, got yield_stress = "
                f"{self.yield_stress}"
            )
        if not 0.0 <= self.hardening < np.inf:
            raise ContactInputError(
                f"the hardening modulus must be >= 0 and finite, got hardening = {self.hardening}"
            )

    @property
    def mu(self) -> float:
        """Shear modulus."""
        return lame_parameters(self.E, self.nu)[0]

    @property
    def kappa(self) -> float:
        """Bulk modulus."""
        mu, lmbda = lame_parameters(self.E, self.nu)
        return lmbda + 2.0 * mu / 3.0

    def return_map(
        self, F: ufl.core.expr.Expr, Cp_inv_n: ufl.core.expr.Expr, alpha_n: ufl.core.expr.Expr
    ) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """Kirchhoff stress and updated history of the radial return.

        Parameters
        ----------
        F
            Deformation gradient (3x3) at the end of the step.
        Cp_inv_n, alpha_n
            History of the last converged step: ``C_p^-1`` (3x3) and the equivalent
            plastic strain.

        Returns
        -------
        tau, Cp_inv, alpha
            UFL expressions: the Kirchhoff stress, ``C_p^-1`` and the equivalent plastic
            strain at the end of the step. The spherical part of the updated ``bbar_e`` is
            corrected so that ``det bbar_e = 1`` (Simo & Hughes 1998, 9.3.2): the plastic
            flow keeps the volume (``det C_p = 1``), and the stress is unchanged.
        """
        I = ufl.Identity(3)
        J = ufl.det(F)
        b_trial = J ** (-2.0 / 3.0) * F * Cp_inv_n * F.T
        I_e = ufl.tr(b_trial) / 3.0
        mu, H = self.mu, self.hardening
        s_trial = mu * (b_trial - I_e * I)
        mubar = mu * I_e
        norm = ufl.sqrt(ufl.inner(s_trial, s_trial))
        f_trial = norm - np.sqrt(2.0 / 3.0) * (self.yield_stress + H * alpha_n)
        plastic = ufl.gt(f_trial, 0.0)
        dgamma = ufl.conditional(plastic, f_trial / (2.0 * mubar * (1.0 + H / (3.0 * mubar))), 0.0)
        # the radial return scales s_trial; |s_trial| only enters where it is > 0
        scale = ufl.conditional(plastic, 1.0 - 2.0 * mubar * dgamma / norm, 1.0)
        s = scale * s_trial
        tau = 0.5 * self.kappa * (J**2 - 1.0) * I + s
        b_e = _unimodular(s / mu, I_e)
        F_inv = ufl.inv(F)
        Cp_inv = J ** (2.0 / 3.0) * F_inv * b_e * F_inv.T
        return tau, Cp_inv, alpha_n + np.sqrt(2.0 / 3.0) * dgamma


def _unimodular(d: ufl.core.expr.Expr, guess: ufl.core.expr.Expr, iterations: int = 4):
    """``d + c I`` with the scalar ``c`` such that ``det(d + c I) = 1`` (``d`` deviatoric),
    by Newton's method from ``c = guess`` (a closed-form UFL expression: ``iterations``
    Newton steps, quadratic from a guess off by the plastic increment times the elastic
    strain)."""
    I = ufl.Identity(3)
    c = guess
    for _ in range(iterations):
        b = d + c * I
        c = c - (ufl.det(b) - 1.0) / ufl.tr(ufl.cofac(b))
    return d + c * I


def _embed(F: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """The 3x3 deformation gradient of a 2x2 (plane strain) or 3x3 one."""
    if F.ufl_shape[0] == 3:
        return F
    return ufl.as_matrix([[F[0, 0], F[0, 1], 0.0], [F[1, 0], F[1, 1], 0.0], [0.0, 0.0, 1.0]])


class PlasticHistory:
    """History of a :class:`J2Plasticity` body at the quadrature points of the bulk rule.

    Parameters
    ----------
    material
        The material.
    u
        The displacement.
    quadrature_degree
        Degree of the bulk quadrature rule (the history's points are that rule's).
    cells
        The body's cells (local indices; the owned ones are committed). The history of
        other cells stays at its initial value (no plastic strain).

    Attributes
    ----------
    Cp_inv, alpha
        The history: ``C_p^-1`` (3x3) and the equivalent plastic strain, quadrature
        functions on the whole mesh.
    F3, tau
        UFL expressions: the 3x3 deformation gradient and the Kirchhoff stress of the
        return map from the history.
    """

    def __init__(
        self,
        material: J2Plasticity,
        u: dolfinx.fem.Function,
        quadrature_degree: int,
        cells: np.ndarray,
    ):
        mesh = u.function_space.mesh
        owned = mesh.topology.index_map(mesh.topology.dim).size_local
        self._cells = np.asarray(cells, dtype=np.int32)[np.asarray(cells) < owned]
        cell = mesh.basix_cell()

        def space(shape):
            element = basix.ufl.quadrature_element(
                cell, value_shape=shape, degree=quadrature_degree
            )
            return dolfinx.fem.functionspace(mesh, element)

        self.material = material
        self.u = u
        #: the degree of the quadrature rule of the history's points
        self.quadrature_degree = quadrature_degree
        self.Cp_inv = dolfinx.fem.Function(space((3, 3)), name="Cp_inv")
        self.Cp_inv.x.array.reshape(-1, 9)[:] = np.eye(3).ravel()
        self.alpha = dolfinx.fem.Function(space(()), name="equivalent_plastic_strain")
        self.F3 = _embed(deformation_gradient(u))
        self.tau, Cp_inv, alpha = material.return_map(self.F3, self.Cp_inv, self.alpha)
        points = self.Cp_inv.function_space.element.interpolation_points
        self._updates = [
            (self.Cp_inv, jit.expression(Cp_inv, points)),
            (self.alpha, jit.expression(alpha, points)),
        ]

    def first_piola(self) -> ufl.core.expr.Expr:
        """First Piola-Kirchhoff stress ``tau F^-T`` (``gdim x gdim``) at the current
        displacement and the committed history."""
        P = self.tau * ufl.inv(self.F3).T
        gdim = self.u.function_space.mesh.geometry.dim
        return ufl.as_matrix([[P[i, j] for j in range(gdim)] for i in range(gdim)])

    def elastic_energy_density(self) -> ufl.core.expr.Expr:
        """The stored (elastic) energy density ``U(J) + mu/2 (tr bbar_e - 3)`` at the current
        displacement and the committed history (the converged state's once committed)."""
        J = ufl.det(self.F3)
        b_e = J ** (-2.0 / 3.0) * self.F3 * self.Cp_inv * self.F3.T
        m = self.material
        return m.kappa / 2.0 * ((J**2 - 1.0) / 2.0 - ufl.ln(J)) + m.mu / 2.0 * (ufl.tr(b_e) - 3.0)

    @functools.cached_property
    def _cell_mean_forms(self) -> tuple[dolfinx.fem.Form, dolfinx.fem.Form]:
        mesh = self.u.function_space.mesh
        v = ufl.TestFunction(self.plastic_strain.function_space)
        dx = ufl.dx(domain=mesh)
        return jit.form(self.alpha * v * dx), jit.form(v * dx)

    @functools.cached_property
    def plastic_strain(self) -> dolfinx.fem.Function:
        """The cell means of the equivalent plastic strain (DG0, for output; see
        :meth:`update_plastic_strain`)."""
        DG0 = dolfinx.fem.functionspace(self.u.function_space.mesh, ("DG", 0))
        return dolfinx.fem.Function(DG0, name="equivalent_plastic_strain")

    def update_plastic_strain(self) -> dolfinx.fem.Function:
        """Set :attr:`plastic_strain` to ``int_cell alpha dV / |cell|`` of the committed
        history and return it."""
        integral, volume = (dolfinx.fem.assemble_vector(f).array for f in self._cell_mean_forms)
        out = self.plastic_strain
        n = out.function_space.dofmap.index_map.size_local
        out.x.array[:n] = integral[:n] / volume[:n]
        out.x.scatter_forward()
        return out

    def begin_step(self) -> None:
        """Begin a load step (step protocol): nothing to do, the history moves only in
        :meth:`commit`, so a step cut back begins again from the same history."""

    def commit(self, x: PETSc.Vec | None = None) -> None:
        """The return map at the converged displacement becomes the history (every field
        evaluated from the old history before any is overwritten).

        Parameters
        ----------
        x
            The converged unknowns (step protocol; unused: the return map reads the
            displacement function).
        """
        mesh, cells = self.u.function_space.mesh, self._cells
        values = [expr.eval(mesh, cells) for _, expr in self._updates]
        for (target, _), value in zip(self._updates, values, strict=True):
            bs = target.function_space.dofmap.index_map_bs
            dofs = target.function_space.dofmap.list[cells]
            target.x.array.reshape(-1, bs)[dofs.ravel()] = value.reshape(-1, bs)
            target.x.scatter_forward()
