"""Coulomb friction: the tangential multiplier, the slip increment and the disc projection.

With the normal law of :mod:`.normal` (the formulation: ``docs/theory.md``):

    traction   T = <lambda_N + eps_N g> nu - P(q),   q = lambda_T + eps_T s_T
    - int_{S_oc} T . (U1* - U2*(Y)) dS_o
    - int_{S_oc} (lambda_T - P(q)) . lambda_T* dS_o     (the multiplier equation times eps_T)

with ``P(q) = min(1, mu <lambda_N + eps_N g> / |q|) q``, the projection of q onto the disc of
radius ``mu <lambda_N + eps_N g>`` (``P(0) = 0``, as in the formulation; the stick test is
written ``|q|^2 <= radius^2`` so that no square root or division is evaluated at ``q = 0``,
in the residual or in its derivative).

Slip increment (the rate-independent form of ``eps_T V_T``): over a load step,

    s_T = (I - nu (x) nu) (x - ybar_n),    ybar_n = sum_a N_a(xi_n) xhat_n,a

the tangential part of the relative displacement between the slave point x and the master
*material* point Y_n it was projected onto at the end of the last converged step, at its
current position ``ybar_n`` (the current positions ``xhat_n`` of the nodes of that step's
master facet, gathered from the displacement like ``xhat``). It is objective, it follows
the master body when it moves, and it needs no assumption that the point stays on one
master facet (large sliding). A point with no master facet at the last step has s_T = 0.
The master side provides ``ybar_n`` with its history (``slip_reference()``): on a meshed
master as above (:class:`~contact_ufl.contact.kinematics.MeshSlipReference`), on a rigid
obstacle the last step's projected point moved by the obstacle's rigid motion since
(:class:`~contact_ufl.contact.obstacles.ObstacleSlipReference`).

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

from contact_ufl import jit
from contact_ufl.contact.kinematics import MeshKinematics
from contact_ufl.contact.obstacles import ObstacleKinematics
from contact_ufl.contact.slave import SlaveSurface

#: A master side as the laws see it.
MasterKinematics = MeshKinematics | ObstacleKinematics


def disc_projection(q, radius, in_contact=None, round_off=0.0):
    """Projection of the vector ``q`` onto the disc of radius ``max(radius, 0)``.

    Without ``in_contact``, a disc of radius 0 (no contact pressure) projects everything
    to 0, with a zero derivative, also at ``q = 0``: an open point has ``lambda_T = 0``
    whatever q is.

    ``in_contact`` (a UFL condition: the normal bracket counts as positive) decides, where
    given, which points may stick, instead of ``radius > 0``; a trial traction within
    ``round_off`` of the disc sticks (value ``q``, derivative the identity). A point that
    starts touching (``g = 0``, ``lambda = 0``, no slip) has ``q = 0`` and a disc of radius
    0, each up to round-off: without the two, round-off alone would choose between stick
    (tangential stiffness ``eps_T``) and slip (none) for its first iterate, and the Newton
    path would depend on the number of ranks. The value changes by at most ``round_off``.
    The NumPy twin is :func:`disc_projection_at_points`.
    """
    qq = ufl.dot(q, q)
    safe_norm = ufl.sqrt(qq + ufl.conditional(ufl.eq(qq, 0.0), 1.0, 0.0))
    may_stick = ufl.gt(radius, 0.0) if in_contact is None else in_contact
    radius = ufl.max_value(radius, 0.0)  # a bracket within its touching band may be < 0
    stick = ufl.And(ufl.le(qq, (radius + round_off) ** 2), may_stick)
    return ufl.conditional(stick, q, radius / safe_norm * q)


def disc_projection_at_points(
    q: np.ndarray, radius: np.ndarray, in_contact: np.ndarray | None = None, round_off=0.0
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`disc_projection` at points: ``q`` ``(n, gdim)``, ``radius`` and ``in_contact``
    ``(n,)``. Returns the mask of the points that stick and the projections ``(n, gdim)``."""
    qq = np.einsum("pd,pd->p", q, q)
    may_stick = radius > 0.0 if in_contact is None else in_contact
    radius = np.maximum(radius, 0.0)
    stick = (qq <= (radius + round_off) ** 2) & may_stick
    norm = np.sqrt(np.where(qq > 0.0, qq, 1.0))
    scale = np.where(stick, 1.0, radius / norm)
    return stick, scale[:, None] * q


class CoulombLaw:
    """Coulomb friction of a contact pair: ``lambda_T``, the slip and its history.

    Parameters
    ----------
    kinematics
        The pair's master side (normal, projected point, and the slip reference
        ``y_n`` with its history, made by its ``slip_reference()``).
    t_N
        The normal contact traction (UFL, from the normal law).
    in_contact
        Where the normal law counts the point as in contact (a UFL condition; see
        :func:`disc_projection`). ``None``: where ``t_N > 0``.
    round_off
        The normal law's length of round-off: a slip within it of zero counts as stick
        (a trial traction within ``eps_T round_off`` of the disc; :func:`disc_projection`).
    mu
        Friction coefficient (> 0).
    eps_T
        Tangential augmentation parameter (> 0).
    """

    def __init__(
        self,
        kinematics: MasterKinematics,
        t_N,
        mu: float,
        eps_T: float,
        in_contact=None,
        round_off: float = 0.0,
    ):
        self.kinematics = k = kinematics
        self.slave: SlaveSurface = k.slave
        self.gdim = k.gdim
        mesh = k.u.function_space.mesh
        self.L_T = dolfinx.fem.functionspace(
            self.slave.submesh, self.slave.multiplier_element((self.gdim,))
        )
        self.lambda_T = dolfinx.fem.Function(self.L_T, name="lambda_T")
        self.mu = dolfinx.fem.Constant(mesh, float(mu))
        self.eps_T = dolfinx.fem.Constant(mesh, float(eps_T))
        #: the slip reference of the master side (``y_n``, its history and step protocol)
        self.reference = k.slip_reference()
        #: Slip increments s_T of the last converged step at the owned slave points, and
        #: which of them stuck.
        self.last_slip = np.zeros((0, self.gdim))
        self.last_stick = np.zeros(0, dtype=bool)
        self.last_weak_slip = 0.0
        self._t_N = t_N
        nu = k.nu

        def tangential(w):
            return w - ufl.dot(w, nu) * nu

        self.y_n = self.reference.y_n
        self.slip = self.mask_n * tangential(k.x - self.y_n)
        self.q = tangential(self.lambda_T) + self.eps_T * self.slip
        self.round_off = round_off
        self.t_T = disc_projection(self.q, self.mu * t_N, in_contact, self.eps_T * round_off)

    @property
    def mask_n(self) -> dolfinx.fem.Function:
        """1 at the slave points that had a master at the last converged step."""
        return self.reference.mask_n

    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """Fields of the assembled system the law adds: ``lambda_T`` and those of the slip
        reference (on a meshed master, the last step's master nodes)."""
        return [self.lambda_T, *self.reference.fields]

    @property
    def unknowns(self) -> list[dolfinx.fem.Function]:
        """Unknowns the law adds: ``lambda_T``."""
        return [self.lambda_T]

    def traction(self) -> ufl.core.expr.Expr:
        """The frictional traction on the slave surface, ``-P(q)``."""
        return -self.t_T

    def residuals(self) -> list[ufl.Form]:
        """The ``lambda_T`` equation (times eps_T, like the normal one) and the residuals of
        the slip reference's fields."""
        ds = self.slave.ds
        F_t = -ufl.dot(self.lambda_T - self.t_T, ufl.TestFunction(self.L_T)) * ds
        return [F_t, *self.reference.residuals(ds)]

    def surface_integrands(self) -> dict[str, ufl.core.expr.Expr]:
        """``"friction"``, the frictional traction on the slave body ``-P(q)``, and
        ``"dissipation"``, ``P(q) . s_T``."""
        return {"friction": -self.t_T, "dissipation": ufl.dot(self.t_T, self.slip)}

    def gathers(self) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """The gathered fields of the law (after the kinematics' update): those of the slip
        reference."""
        return self.reference.gathers()

    # -- the step protocol ------------------------------------------------------------
    def follow(self, x, gathers: list) -> None:
        """Move the slip reference with the master to the unknowns ``x`` (through this
        law's gathers in ``gathers``, where it is gathered from the displacement)."""
        self.reference.follow(x, gathers)

    def commit(self, x, normal_traction: np.ndarray, in_contact: np.ndarray | None = None) -> None:
        """Remember the converged projection: the reference of the next step's slip.

        The slip reference itself moves only in :meth:`begin_step`, so that until the next
        step starts everything inspected (slip, stick, tractions, contact force) is that of
        the converged step. ``normal_traction``: ``t_N`` at the owned points; ``in_contact``:
        the mask of those in contact (see :meth:`stick`).
        """
        self.last_slip = self.slip_at_points()
        self.last_stick = self.stick(normal_traction, in_contact)
        self.last_weak_slip = self.weak_slip(self.last_stick)
        self.reference.commit(x)

    def begin_step(self) -> None:
        """The last committed projection becomes the reference of the slip (idempotent:
        a step cut back and tried again starts from the same reference)."""
        self.reference.begin_step()

    # -- inspection -------------------------------------------------------------------
    def slip_at_points(self) -> np.ndarray:
        """Slip increment s_T since the last converged step at the owned slave points."""
        k, slave, gdim = self.kinematics, self.slave, self.gdim
        x = slave.positions(k.u).reshape(-1, gdim)
        s = (x - self.reference.y_n_at_points()) * slave.at_points(self.mask_n)
        return self._tangential(s)

    @functools.cached_property
    def _slip_form(self) -> dolfinx.fem.Form:
        return jit.form(
            ufl.dot(self.slip, ufl.TestFunction(self.L_T)) * self.slave.ds,
            entity_maps=[self.slave.entity_map],
        )

    def weak_slip(self, stick: np.ndarray) -> float:
        """Largest ``|int s_T phi_i| / int phi_i`` over the multiplier nodes whose whole
        support is in contact and sticks (``stick``: mask of the owned points, see
        :meth:`stick`): zero to solver tolerance, the stick condition as the multiplier
        equation imposes it. Nodes touching an open or slipping point are left out (0 when
        there is no such node)."""
        slave = self.slave
        owned = slave.P1.dofmap.index_map.size_local
        nodal = slave.assemble_nodal(self._slip_form, self.L_T)[: owned * self.gdim]
        stuck = (slave.count_at_nodes(~stick) == 0) & (slave.nodal_mass > 0)
        values = np.linalg.norm(nodal.reshape(-1, self.gdim)[stuck], axis=1)
        local = (values / slave.nodal_mass[stuck]).max(initial=0.0)
        return slave.V.mesh.comm.allreduce(local, op=MPI.MAX)

    def tangential_multiplier_at_points(self) -> np.ndarray:
        """Tangential part of lambda_T at the owned slave points."""
        return self._tangential(self.slave.p1_at_points(self.lambda_T))

    def _trial_and_radius(self, normal_traction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The trial traction ``q = lambda_T + eps_T s_T`` and the disc radius ``mu t_N``."""
        q = self.tangential_multiplier_at_points() + float(self.eps_T.value) * self.slip_at_points()
        return q, float(self.mu.value) * normal_traction

    def stick(
        self, normal_traction: np.ndarray, in_contact: np.ndarray | None = None
    ) -> np.ndarray:
        """Mask of the owned slave points in stick (``|q| <= mu t_N``, within the round-off
        band ``eps_T round_off``), of those in contact; ``normal_traction``: ``t_N`` at the
        owned points; ``in_contact``: the mask of the points in contact (default:
        ``t_N > 0``; see :func:`disc_projection`)."""
        return self._disc_at_points(normal_traction, in_contact)[0]

    def traction_at_points(
        self, normal_traction: np.ndarray, in_contact: np.ndarray | None = None
    ) -> np.ndarray:
        """The frictional traction on the slave body at the owned slave points, ``-P(q)``
        (``q`` projected onto the Coulomb disc of radius ``mu t_N``; the term of
        :meth:`traction`), ``(n, gdim)``: it opposes the slip. ``in_contact`` as in
        :meth:`stick`."""
        return -self._disc_at_points(normal_traction, in_contact)[1]

    def _disc_at_points(self, normal_traction: np.ndarray, in_contact: np.ndarray | None):
        q, radius = self._trial_and_radius(normal_traction)
        round_off = float(self.eps_T.value) * self.round_off
        return disc_projection_at_points(q, radius, in_contact, round_off)

    def _tangential(self, w: np.ndarray) -> np.ndarray:
        nu = self.kinematics.projection.normal
        return w - np.einsum("pd,pd->p", w, nu)[:, None] * nu
