"""Rigid obstacles: analytic master surfaces with a prescribed rigid motion.

A rigid obstacle is the master side of a contact pair that has no mesh and no unknowns: a
plane, a sphere (a circle in 2D) or a cylinder (3D), moved rigidly in pseudo-time. Write it
where a master facet tag would go::

    plane = RigidPlane(point=(0.0, 0.0), normal=(0.0, 1.0))
    ContactPair(slave="disc_contact", master=plane)

Rigid motion
------------
``motion`` is a callable of the pseudo-time ``t`` returning either a translation ``c(t)``
(``gdim`` numbers, e.g. ``lambda t: (0.0, -0.1 * t)``) or a pair ``(c(t), Q(t))`` of a
translation and a rotation matrix (``gdim x gdim``, orthogonal with determinant 1). A point
``P`` of the obstacle in its reference position moves to

    p(t) + Q(t) (P - p0),     p(t) = p0 + c(t),

``p0`` the obstacle's reference point (the plane's ``point``, the sphere's ``centre``, the
cylinder's ``point``): the rotation is about the reference point, then the translation.
``motion=None`` is a fixed obstacle.

Kinematics (:class:`ObstacleKinematics`)
----------------------------------------
The closest point on the moved surface is explicit, so the projected point, the normal and
the proximity are closed-form UFL expressions of the slave point ``x = X + u`` and their
Gateaux derivatives are exact (no linearised reference coordinates): with ``nu`` the outward
normal of the obstacle (it points towards the slave body),

* plane (moved point ``p``, normal ``n = Q n0``): ``nu = n``, ``g = -n . (x - p)``;
* sphere of radius ``r`` and moved centre ``p``: ``nu = (x - p) / |x - p|``,
  ``g = r - |x - p|``;
* cylinder of radius ``r``, axis ``a = Q a0`` through ``p``: ``d = (I - a a) (x - p)``,
  ``nu = d / |d|``, ``g = r - |d|``;

and ``y = x + g nu`` (``g > 0``: penetration, as for a meshed master). The pose (``p`` and
``Q``) enters the forms as constants set with the pseudo-time. Points farther than the
pair's search radius from the surface are unpaired, as with a meshed master.

Friction: the slip reference of a point is the point of the obstacle it was projected onto
at the last converged step, carried along by the rigid motion since then
(:class:`ObstacleSlipReference`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contact_ufl.contact.search import Projection
from contact_ufl.contact.slave import SlaveSurface
from contact_ufl.errors import collective_check
from contact_ufl.layout import StackedLayout

#: A rigid motion: ``t -> c(t)`` or ``t -> (c(t), Q(t))`` (see the module docstring).
Motion = Callable[[float], Any]


def _vector(value) -> tuple[float, ...]:
    return tuple(float(v) for v in np.ravel(np.asarray(value, dtype=float)))


def _is_vector(value, gdim: int) -> bool:
    """Whether ``value`` is a translation (``gdim`` numbers), not a pair (c, Q)."""
    try:
        return np.asarray(value, dtype=float).shape == (gdim,)
    except (ValueError, TypeError):
        return False


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class RigidObstacle:
    """Base of the rigid obstacles: the rigid motion and the closest-point geometry."""

    def __post_init__(self) -> None:
        for name in self._vectors:
            object.__setattr__(self, name, _vector(getattr(self, name)))

    #: names of the vector fields (stored as tuples of floats)
    _vectors: ClassVar[tuple[str, ...]] = ()

    @property
    def reference_point(self) -> np.ndarray:
        """The point ``p0`` the rotation of the motion is about."""
        raise NotImplementedError

    @property
    def name(self) -> str:
        """A short description for messages."""
        return type(self).__name__

    def pose(self, t: float, gdim: int) -> tuple[np.ndarray, np.ndarray]:
        """The moved reference point ``p(t) = p0 + c(t)`` and the rotation ``Q(t)``."""
        c, Q = np.zeros(gdim), np.eye(gdim)
        if self.motion is not None:
            value = self.motion(t)
            if _is_vector(value, gdim):
                c = np.asarray(value, dtype=float)
            else:
                c, Q = (np.asarray(v, dtype=float) for v in value)
        return np.asarray(self.reference_point) + c, Q

    def validate(self, comm: MPI.Comm, gdim: int) -> None:
        """Raise a clear error (on every rank) for a degenerate shape or a bad motion."""
        for name in self._vectors:
            value = np.asarray(getattr(self, name))
            collective_check(
                comm,
                value.shape == (gdim,),
                f"{self.name}: {name} must have {gdim} components in {gdim}D, "
                f"got {tuple(value.tolist())}",
            )
        self._check_shape(comm, gdim)
        if self.motion is not None:
            self._check_motion(comm, gdim)

    def _check_shape(self, comm: MPI.Comm, gdim: int) -> None:
        pass

    def _check_radius(self, comm: MPI.Comm) -> None:
        collective_check(
            comm,
            bool(self.radius > 0.0 and np.isfinite(self.radius)),
            f"{self.name}: the radius must be positive, got radius = {self.radius}",
        )

    def _check_direction(self, comm: MPI.Comm, name: str) -> None:
        value = np.asarray(getattr(self, name))
        collective_check(
            comm,
            bool(np.linalg.norm(value) > 0.0),
            f"{self.name}: the {name} must be a nonzero vector, got {tuple(value.tolist())}",
        )

    def _check_motion(self, comm: MPI.Comm, gdim: int) -> None:
        try:
            p, Q = self.pose(0.0, gdim)
            ok = p.shape == (gdim,) and Q.shape == (gdim, gdim)
            ok = ok and bool(np.allclose(Q.T @ Q, np.eye(gdim), atol=1e-10))
            ok = ok and bool(np.linalg.det(Q) > 0.0)
        except (ValueError, TypeError):
            ok = False
        collective_check(
            comm,
            ok,
            f"{self.name}: motion(t) must return a translation of {gdim} components or a "
            f"pair (translation, rotation matrix {gdim}x{gdim}, orthogonal, det 1)",
        )

    # -- geometry of the moved surface (overridden by each shape) -------------------------
    def closest_ufl(self, x, p, Q, mask) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """UFL outward normal ``nu`` and proximity ``g`` of ``x`` for the pose ``(p, Q)``
        (``nu`` finite where ``mask`` is 0)."""
        raise NotImplementedError

    def closest(self, x: np.ndarray, p: np.ndarray, Q: np.ndarray):
        """NumPy twin of :meth:`closest_ufl` for points ``(n, gdim)``: ``nu``, ``g`` and
        whether the closest point is unique (``|x - p| > 0`` for a sphere)."""
        raise NotImplementedError


def _radial(d, mask, radius):
    """Normal and proximity of a point at radial vector ``d`` from a sphere's centre or a
    cylinder's axis (UFL; ``d = 0`` guarded where ``mask`` is 0)."""
    r = ufl.sqrt(ufl.dot(d, d) + (1.0 - mask))
    return d / r, radius - r


def _radial_np(d: np.ndarray, radius: float):
    r = np.linalg.norm(d, axis=1)
    valid = r > 0.0
    nu = d / np.where(valid, r, 1.0)[:, None]
    return nu, radius - r, valid


@dataclass(frozen=True)
class RigidPlane(RigidObstacle):
    """A rigid plane (a line in 2D) through ``point`` with outward ``normal`` (pointing
    towards the slave body; need not be of unit length), moved by ``motion`` (see
    :mod:`contact_ufl.contact.obstacles`)."""

    point: tuple[float, ...]
    normal: tuple[float, ...]
    motion: Motion | None = None
    _vectors: ClassVar[tuple[str, ...]] = ("point", "normal")

    @property
    def reference_point(self) -> np.ndarray:
        """``point``."""
        return np.asarray(self.point)

    def _check_shape(self, comm: MPI.Comm, gdim: int) -> None:
        self._check_direction(comm, "normal")

    def closest_ufl(self, x, p, Q, mask):
        n = Q * ufl.as_vector(_unit(np.asarray(self.normal)).tolist())
        return n, -ufl.dot(n, x - p)

    def closest(self, x, p, Q):
        n = Q @ _unit(np.asarray(self.normal))
        nu = np.broadcast_to(n, x.shape).copy()
        return nu, -(x - p) @ n, np.ones(len(x), dtype=bool)


@dataclass(frozen=True)
class RigidSphere(RigidObstacle):
    """A rigid ball of ``radius`` about ``centre`` (a disc in 2D), the slave outside it,
    moved by ``motion`` (see :mod:`contact_ufl.contact.obstacles`)."""

    centre: tuple[float, ...]
    radius: float
    motion: Motion | None = None
    _vectors: ClassVar[tuple[str, ...]] = ("centre",)

    @property
    def reference_point(self) -> np.ndarray:
        """``centre``."""
        return np.asarray(self.centre)

    def _check_shape(self, comm: MPI.Comm, gdim: int) -> None:
        self._check_radius(comm)

    def closest_ufl(self, x, p, Q, mask):
        return _radial(x - p, mask, self.radius)

    def closest(self, x, p, Q):
        return _radial_np(x - p, self.radius)


@dataclass(frozen=True)
class RigidCylinder(RigidObstacle):
    """A rigid solid circular cylinder (3D) of ``radius`` about the line through ``point``
    along ``axis`` (unbounded), the slave outside it, moved by ``motion`` (see
    :mod:`contact_ufl.contact.obstacles`)."""

    point: tuple[float, ...]
    axis: tuple[float, ...]
    radius: float
    motion: Motion | None = None
    _vectors: ClassVar[tuple[str, ...]] = ("point", "axis")

    @property
    def reference_point(self) -> np.ndarray:
        """``point``."""
        return np.asarray(self.point)

    def validate(self, comm: MPI.Comm, gdim: int) -> None:
        """As :meth:`RigidObstacle.validate`; a cylinder needs 3D."""
        collective_check(
            comm,
            gdim == 3,
            f"RigidCylinder needs a 3D scene (got {gdim}D); in 2D a circle is a RigidSphere",
        )
        super().validate(comm, gdim)

    def _check_shape(self, comm: MPI.Comm, gdim: int) -> None:
        self._check_direction(comm, "axis")
        self._check_radius(comm)

    def closest_ufl(self, x, p, Q, mask):
        a = Q * ufl.as_vector(_unit(np.asarray(self.axis)).tolist())
        w = x - p
        return _radial(w - ufl.dot(w, a) * a, mask, self.radius)

    def closest(self, x, p, Q):
        a = Q @ _unit(np.asarray(self.axis))
        w = x - p
        return _radial_np(w - np.outer(w @ a, a), self.radius)


class ObstacleKinematics:
    """Gap, normal and projected point of the slave points on a rigid obstacle.

    The master side of a pair whose master is a :class:`RigidObstacle`, with the members
    of :class:`~contact_ufl.contact.kinematics.MeshKinematics`: UFL ``x``, ``y``, ``nu``,
    ``gap`` and ``mask``; no fields of its own (:attr:`fields` and
    :meth:`master_residuals` are empty: the obstacle has no unknowns); :meth:`update`
    computes the closest points (for :attr:`projection`, the results and ``mask``) and
    gathers nothing. :meth:`set_time` moves the obstacle.

    Parameters
    ----------
    u
        The displacement.
    slave
        The slave side of the pair.
    obstacle
        The master side.
    radius
        Search radius: points farther than this from the surface are unpaired.
    """

    def __init__(
        self, u: dolfinx.fem.Function, slave: SlaveSurface, obstacle: RigidObstacle, radius: float
    ):
        self.u, self.slave, self.obstacle, self.radius = u, slave, obstacle, radius
        mesh = u.function_space.mesh
        self.gdim = gdim = mesh.geometry.dim
        #: the pose of the obstacle: its moved reference point and rotation (constants)
        self.p = dolfinx.fem.Constant(mesh, np.zeros(gdim))
        self.Q = dolfinx.fem.Constant(mesh, np.eye(gdim))
        self.mask = dolfinx.fem.Function(slave.point_space(()))
        #: the closest points of the last update
        self.projection: Projection | None = None
        #: seconds spent computing closest points so far
        self.search_time = 0.0
        # the normal and projected point of the last update, as data (frozen_projection)
        self._nu0 = dolfinx.fem.Function(slave.point_space((gdim,)))
        self._y0 = dolfinx.fem.Function(slave.point_space((gdim,)))
        self._frozen = dolfinx.fem.Constant(mesh, 0.0)
        self.x = x = ufl.SpatialCoordinate(mesh) + u
        nu, gap = obstacle.closest_ufl(x, self.p, self.Q, self.mask)
        f = self._frozen
        self.nu = (1.0 - f) * nu + f * self._nu0
        self.gap = (1.0 - f) * gap - f * ufl.dot(self._nu0, x - self._y0)
        self.y = x + self.gap * self.nu
        self.set_time(0.0)

    @property
    def frozen_projection(self) -> bool:
        """Freeze the normal and the projected point inside a Newton iteration (data of the
        last update: the normal's rotation drops out of the tangent, and Newton converges
        only linearly), as :attr:`.MeshKinematics.frozen_projection`. For comparisons."""
        return bool(self._frozen.value)

    @frozen_projection.setter
    def frozen_projection(self, frozen: bool) -> None:
        self._frozen.value = float(frozen)

    def set_time(self, t: float) -> None:
        """Move the obstacle to its pose at pseudo-time ``t``."""
        p, Q = self.obstacle.pose(t, self.gdim)
        self.p.value = p
        self.Q.value = Q

    @property
    def pose(self) -> tuple[np.ndarray, np.ndarray]:
        """The current moved reference point and rotation."""
        return np.array(self.p.value), np.array(self.Q.value)

    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """None: the obstacle has no unknowns."""
        return []

    def master_residuals(self, traction: ufl.core.expr.Expr) -> list[ufl.Form]:
        """None: the reaction of the contact traction acts on the obstacle, which is given."""
        return []

    def closest_points(self, x: np.ndarray) -> Projection:
        """The closest points of the points ``x`` ``(n, gdim)`` on the moved surface; points
        farther than the search radius, or with no unique closest point, are unpaired."""
        return self._projection(x, *self.obstacle.closest(x, *self.pose))

    def _projection(self, x: np.ndarray, nu, gap, valid) -> Projection:
        """The closest points ``x + gap nu``, paired where ``valid`` within the radius."""
        paired = valid & (np.abs(gap) <= self.radius)
        n, fdim = len(x), self.gdim - 1
        return Projection(
            facet=np.where(paired, 0, -1).astype(np.int64),
            xi=np.zeros((n, fdim)),
            y=np.where(paired[:, None], x + gap[:, None] * nu, x),
            normal=np.where(paired[:, None], nu, 0.0),
            gap=np.where(paired, gap, -np.inf),
            distance=np.where(paired, np.abs(gap), np.inf),
            sliding=np.zeros((n, fdim, fdim)),
        )

    def update(self, layout: StackedLayout) -> list:
        """Closest points of the current slave points; nothing is gathered."""
        start = time.perf_counter()
        x = self.slave.positions(self.u).reshape(-1, self.gdim)
        self.projection = proj = self.closest_points(x)
        self.slave.set_at_points(self.mask, (proj.facet >= 0).astype(float))
        self.slave.set_at_points(self._nu0, proj.normal)
        self.slave.set_at_points(self._y0, proj.y)
        self.search_time += time.perf_counter() - start
        return []

    def pattern_gathers(self) -> list:
        """Nothing is gathered (see :meth:`MeshKinematics.pattern_gathers
        <contact_ufl.contact.kinematics.MeshKinematics.pattern_gathers>`)."""
        return []

    def check_facing(self, description: str) -> Projection:
        """Raise (on every rank) if no slave point faces the obstacle in the reference
        configuration at its pose at t = 0: outside it, with opposed outward normals.

        Returns the closest points there, paired where a slave point faces the obstacle
        within the search radius, outside or inside it (an overlap is a positive gap)."""
        x = self.slave.X.reshape(-1, self.gdim)
        nu, gap, valid = self.obstacle.closest(x, *self.obstacle.pose(0.0, self.gdim))
        normals = np.repeat(self.slave.normals, self.slave.num_points, axis=0)
        outside = (gap <= 1e-8 * (1.0 + np.abs(gap))) | (np.abs(gap) <= self.radius)
        opposed = np.einsum("pd,pd->p", nu, normals) < 0.0
        if self.slave.membrane:  # either side of a membrane may face the obstacle
            opposed = True
        total = self.slave.V.mesh.comm.allreduce(int(np.count_nonzero(valid & outside & opposed)))
        collective_check(
            self.slave.V.mesh.comm,
            total > 0,
            f"{description} never faces its obstacle: no slave point lies outside it with "
            "its outward normal towards it (wrong tag, or an obstacle on the wrong side?)",
        )
        return self._projection(x, nu, gap, valid & opposed)

    def slip_reference(self) -> ObstacleSlipReference:
        """The slip reference of the Coulomb law on this master side."""
        return ObstacleSlipReference(self)


class ObstacleSlipReference:
    """The slip reference ``y_n`` of friction on a rigid obstacle.

    The point of the obstacle a slave point was projected onto at the last converged step,
    moved by the rigid motion since: stored in the obstacle's own frame, ``Y = Q_n^T (y_n -
    p_n)``, it is at ``p(t) + Q(t) Y`` now. Data, no unknowns (no fields, nothing
    gathered).
    """

    def __init__(self, kinematics: ObstacleKinematics):
        self.kinematics = k = kinematics
        self.Y_n = dolfinx.fem.Function(k.slave.point_space((k.gdim,)))
        self.mask_n = dolfinx.fem.Function(k.mask.function_space)
        self.y_n = k.p + k.Q * self.Y_n
        self._committed = None

    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """None."""
        return []

    def residuals(self, ds: ufl.Measure) -> list[ufl.Form]:
        """None."""
        return []

    def gathers(self) -> list:
        """None."""
        return []

    def follow(self, x, gathers: list) -> None:
        """Nothing to gather: ``y_n`` follows the pose constants."""

    def commit(self, x) -> None:
        """Remember the converged projected points, in the obstacle's frame."""
        k = self.kinematics
        p, Q = k.pose
        proj = k.projection
        self._committed = ((proj.y - p) @ Q, (proj.facet >= 0).astype(float))

    def begin_step(self) -> None:
        """The last committed points become the slip reference (idempotent)."""
        if self._committed is None:
            return
        Y, mask = self._committed
        self.kinematics.slave.set_at_points(self.Y_n, Y)
        self.kinematics.slave.set_at_points(self.mask_n, mask)
        self._committed = None

    def y_n_at_points(self) -> np.ndarray:
        """``y_n`` at the owned slave points, ``(n, gdim)``."""
        p, Q = self.kinematics.pose
        return p + self.kinematics.slave.at_points(self.Y_n) @ Q.T
