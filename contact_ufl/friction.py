"""Coulomb friction: the tangential multiplier, the slip increment and the disc projection.

Adds to the frictionless terms of :mod:`contact_ufl.contact` (``formulation.md``):

    traction   T = <lambda_N + eps_N g> nu - P(q),   q = lambda_T + eps_T s_T
    - int_{S_oc} T . (U1* - U2*(Y)) dS_o
    - int_{S_oc} (lambda_T - P(q)) . lambda_T* dS_o     (the seed's equation times eps_T)

with ``P(q) = min(1, mu <lambda_N + eps_N g> / |q|) q``, the projection of q onto the disc of
radius ``mu <lambda_N + eps_N g>`` (``P(0) = 0``, the seed's rule; the stick test is written
``|q|^2 <= radius^2`` so that no square root or division is evaluated at ``q = 0``, in the
residual or in its derivative).

Slip increment (the rate-independent form of ``eps_T V_T``): over a load step,

    s_T = (I - nu (x) nu) (x - ybar_n),    ybar_n = sum_a N_a(xi_n) xhat_n,a

the tangential part of the relative displacement between the slave point x and the master
*material* point Y_n it was projected onto at the end of the last converged step, at its
current position ``ybar_n`` (the current positions ``xhat_n`` of the nodes of that step's
master facet, gathered from the displacement like ``xhat``). It is objective, it follows
the master body when it moves, and it needs no assumption that the point stays on one
master facet (large sliding). A point with no master facet at the last step has s_T = 0.

Discrete multiplier: ``lambda_T`` is a continuous P1 vector field on the slave submesh; only
its part tangent to the master surface enters q, and its multiplier equation drives its
normal part to zero.
"""

from __future__ import annotations

import functools

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contact_ufl.contact import (
    ContactPair,
    FrictionlessContact,
    _interpolate,
    master_shape_functions,
)
from contact_ufl.errors import collective_check
from contact_ufl.projection import shape_functions


def disc_projection(q, radius):
    """Projection of the vector ``q`` onto the disc of radius ``radius >= 0``.

    A disc of radius 0 (no contact pressure) projects everything to 0, with a zero
    derivative, also at ``q = 0``: an open point has ``lambda_T = 0`` whatever q is.
    """
    qq = ufl.dot(q, q)
    safe_norm = ufl.sqrt(qq + ufl.conditional(ufl.eq(qq, 0.0), 1.0, 0.0))
    stick = ufl.And(ufl.le(qq, radius**2), ufl.gt(radius, 0.0))
    return ufl.conditional(stick, q, radius / safe_norm * q)


class FrictionalContact(FrictionlessContact):
    """Contact terms with Coulomb friction of one contact pair (``pair.mu > 0``)."""

    def __init__(
        self, u: dolfinx.fem.Function, facet_tags: dolfinx.mesh.MeshTags, pair: ContactPair
    ):
        super().__init__(u, facet_tags, pair)
        mesh = u.function_space.mesh
        collective_check(mesh.comm, pair.mu > 0.0, "FrictionalContact needs mu > 0")
        sub = self.slave.submesh
        self.L_T = dolfinx.fem.functionspace(sub, ("Lagrange", 1, (self.gdim,)))
        self.lambda_T = dolfinx.fem.Function(self.L_T, name="lambda_T")
        self.mu = dolfinx.fem.Constant(mesh, float(pair.mu))
        self.eps_T = dolfinx.fem.Constant(mesh, float(pair.eps_T or pair.eps_N))
        self.xhat_n = dolfinx.fem.Function(self.Qx, name="master_nodes_last_step")
        self.xi_n = dolfinx.fem.Function(self.xi0.function_space)
        self.mask_n = dolfinx.fem.Function(self.mask.function_space)
        self._zero = dolfinx.fem.Function(self.mask.function_space)
        self._gather_n = None
        self._x_commit = None
        self._xhat_n_commit = None
        self._work = None  # vectors of update_history, allocated once
        self._committed = None  # the converged state, until the next step begins
        #: Slip increments s_T of the last converged step at the owned slave points, and
        #: which of them stuck.
        self.last_slip = np.zeros((0, self.gdim))
        self.last_stick = np.zeros(0, dtype=bool)
        self.last_weak_slip = 0.0
        self._friction_kinematics()

    def _friction_kinematics(self) -> None:
        gdim, nn = self.gdim, self.nn
        nodes = ufl.as_matrix([[self.xhat_n[a * gdim + i] for i in range(gdim)] for a in range(nn)])
        N_n, _ = master_shape_functions(nn, self.xi_n)
        self.y_n = _interpolate(N_n, nodes, gdim)
        nu = self.nu

        def tangential(w):
            return w - ufl.dot(w, nu) * nu

        self.slip = self.mask_n * tangential(self.x - self.y_n)
        self.q = tangential(self.lambda_T) + self.eps_T * self.slip
        self.t_T = disc_projection(self.q, self.mu * self.t_N)

    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        return [self.xhat, self.lambda_N, self.lambda_T, self.xhat_n]

    @property
    def unknowns(self) -> list[dolfinx.fem.Function]:
        return [self.lambda_N, self.lambda_T]

    def traction(self) -> ufl.core.expr.Expr:
        """Contact traction on the slave surface, ``T = t_N nu - P(q)``."""
        return self.t_N * self.nu - self.t_T

    def surface_integrands(self) -> dict[str, ufl.core.expr.Expr]:
        """Those of :class:`FrictionlessContact`, and ``"friction"``, the frictional
        traction on the slave body ``-P(q)``, and ``"dissipation"``, ``P(q) . s_T``."""
        return {
            **super().surface_integrands(),
            "friction": -self.t_T,
            "dissipation": ufl.dot(self.t_T, self.slip),
        }

    def residuals(self, v: ufl.Argument) -> tuple[ufl.Form, list[ufl.Form]]:
        F_u, (F_x, F_l) = super().residuals(v)
        lambda_test = ufl.TestFunction(self.L_T)
        # times eps_T, like the normal multiplier equation (see FrictionlessContact)
        F_t = -ufl.dot(self.lambda_T - self.t_T, lambda_test) * self.ds
        # xhat_n has no equation of its own: a zero residual, present so that derivatives
        # with respect to it are assembled and chained onto the displacement by T
        F_n = self._zero * ufl.dot(self.xhat_n, ufl.TestFunction(self.Qx)) * self.ds
        return F_u, [F_x, F_l, F_t, F_n]

    def update(self, layout):
        gathers = super().update(layout)
        if self._gather_n is None:
            self._gather_n = np.full_like(self._gather, -1)
        return [*gathers, (self.xhat_n, self._gather_n)]

    def update_history(self, T, x, block_slice) -> None:
        """Current positions of the last step's master facet nodes: ``xhat_n,commit +
        P_n (u - u_commit)``, evaluated through T (the nodes may live on any rank)."""
        owned = len(self._gather_n)
        if self._x_commit is None:
            self.xhat_n.x.array[:owned] = self.xhat.x.array[:owned]
        else:
            if self._work is None:
                self._work = (x.duplicate(), T.createVecLeft())
            dx, full = self._work
            x.copy(dx)
            dx.axpy(-1.0, self._x_commit)
            T.mult(dx, full)
            moved = full.array[block_slice(self.xhat_n)]
            self.xhat_n.x.array[:owned] = self._xhat_n_commit + moved
        self.xhat_n.x.scatter_forward()

    def commit(self, x) -> None:
        """Remember the converged projection: the reference of the next step's slip.

        The slip reference itself moves only in :meth:`begin_step`, so that until the next
        step starts everything inspected (slip, stick, tractions, contact force) is that of
        the converged step.
        """
        owned = len(self._gather)
        self.last_slip = self.slip_at_points()
        self.last_stick = self.stick()
        self.last_weak_slip = self.weak_slip(self.last_stick)
        self._committed = (
            self._gather.copy(),
            self.xhat.x.array[:owned].copy(),
            x.copy(),
            self.xi0.x.array.copy(),
            self.mask.x.array.copy(),
            self.xhat.x.array.copy(),
        )

    def begin_step(self) -> None:
        """The last committed projection becomes the reference of the slip (idempotent:
        a step cut back and tried again starts from the same reference)."""
        if self._committed is None:
            return
        gather, xhat_owned, x, xi, mask, xhat = self._committed
        self._gather_n = gather
        self._xhat_n_commit = xhat_owned
        self._x_commit = x
        self.xi_n.x.array[:] = xi
        self.mask_n.x.array[:] = mask
        self.xhat_n.x.array[:] = xhat
        self._committed = None

    # -- inspection -------------------------------------------------------------------
    def slip_at_points(self) -> np.ndarray:
        """Slip increment s_T since the last converged step at the owned slave points."""
        gdim = self.gdim
        x = self.slave.positions(self.u).reshape(-1, gdim)
        nodes = self._values(self.xhat_n).reshape(len(x), self.nx, gdim)[:, : self.nn]
        N_n = shape_functions(self.nn, gdim, self._values(self.xi_n))[0]
        s = (x - np.einsum("pa,pad->pd", N_n, nodes)) * self._values(self.mask_n)
        return self._tangential(s)

    @functools.cached_property
    def _slip_form(self) -> dolfinx.fem.Form:
        return dolfinx.fem.form(
            ufl.dot(self.slip, ufl.TestFunction(self.L_T)) * self.ds,
            entity_maps=[self.slave.entity_map],
        )

    def weak_slip(self, stick: np.ndarray) -> float:
        """Largest ``|int s_T phi_i| / int phi_i`` over the multiplier nodes whose whole
        support is in contact and sticks (``stick``: mask of the owned points, see
        :meth:`stick`): zero to solver tolerance, the stick condition as the multiplier
        equation imposes it. Nodes touching an open or slipping point are left out (0 when
        there is no such node)."""
        owned = self.L.dofmap.index_map.size_local
        nodal = self.assemble_nodal(self._slip_form, self.L_T)[: owned * self.gdim]
        stuck = (self.count_at_nodes(~stick) == 0) & (self.nodal_mass > 0)
        values = np.linalg.norm(nodal.reshape(-1, self.gdim)[stuck], axis=1)
        local = (values / self.nodal_mass[stuck]).max(initial=0.0)
        return self.u.function_space.mesh.comm.allreduce(local, op=MPI.MAX)

    def tangential_multiplier_at_points(self) -> np.ndarray:
        """Tangential part of lambda_T at the owned slave points."""
        return self._tangential(self._vector_at_points(self.lambda_T))

    def _trial_and_radius(self) -> tuple[np.ndarray, np.ndarray]:
        """The trial traction ``q = lambda_T + eps_T s_T`` and the disc radius ``mu t_N``."""
        q = self.tangential_multiplier_at_points() + float(self.eps_T.value) * self.slip_at_points()
        return q, float(self.mu.value) * self.normal_traction_at_points()

    def stick(self) -> np.ndarray:
        """Mask of the owned slave points in stick (``|q| <= mu t_N``), of those in contact."""
        q, radius = self._trial_and_radius()
        return (np.einsum("pd,pd->p", q, q) <= radius**2) & (radius > 0)

    def tangential_traction_at_points(self) -> np.ndarray:
        """The frictional traction on the slave body at the owned slave points, ``-P(q)``
        (``q`` projected onto the Coulomb disc of radius ``mu t_N``; the term of
        :meth:`traction`), ``(n, gdim)``: it opposes the slip."""
        q, radius = self._trial_and_radius()
        norm = np.linalg.norm(q, axis=1)
        scale = np.where(norm <= radius, 1.0, radius / np.where(norm > 0.0, norm, 1.0))
        return np.where(radius[:, None] > 0.0, -scale[:, None] * q, 0.0)

    def traction_at_points(self) -> np.ndarray:
        """Contact traction (normal and frictional) on the slave body at the owned points."""
        return super().traction_at_points() + self.tangential_traction_at_points()

    def _tangential(self, w: np.ndarray) -> np.ndarray:
        nu = self.projection.normal
        return w - np.einsum("pd,pd->p", w, nu)[:, None] * nu

    def _values(self, f: dolfinx.fem.Function) -> np.ndarray:
        bs = f.function_space.dofmap.index_map_bs
        return f.x.array.reshape(-1, bs)[self._owned_blocks(f.function_space)]

    def _vector_at_points(self, f: dolfinx.fem.Function) -> np.ndarray:
        dofs = f.function_space.dofmap.list[: self.slave.num_cells]
        values = f.x.array.reshape(-1, self.gdim)[dofs]  # (nc, ndofs, gdim)
        return np.einsum("qn,cnd->cqd", self._phi_lambda, values).reshape(-1, self.gdim)
