"""Prescribed loads and displacements, scaled by the pseudo-time (load factor) t.

Values are given either as constants or as callables of the pseudo-time ``t``; they are
refreshed into DOLFINx constants at every load step, so forms are compiled once. A
prescribed displacement may also vary along its facets: a callable of ``(t, x)``, such as a
:class:`RigidMotion` (a hub turned, a ball rolled).

Dead loads (:class:`DeadTraction`, :class:`BodyForce`) keep their direction and magnitude per
unit reference area or volume. Follower loads (:class:`FollowerPressure`,
:class:`FollowerForce`) depend on the deformation ``F = I + grad u``: their virtual work is
a function of ``u``, so the Jacobian of the problem (``ufl.derivative`` of the whole
residual) contains their load stiffness, which is not symmetric.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contact_ufl import jit
from contact_ufl.errors import ContactInputError

Value = float | Sequence[float] | Callable[[float], float | Sequence[float]]


def evaluate(value: Value, t: float) -> np.ndarray:
    """The value at pseudo-time ``t`` as an array."""
    return np.asarray(value(t) if callable(value) else value, dtype=float)


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement on tagged facets.

    Parameters
    ----------
    tag
        Facet tag, or the name of its physical group.
    value
        Displacement vector (or, with ``component``, one component), or a callable of ``t``
        returning one; or a callable of ``(t, x)``, ``x`` the reference coordinates
        ``(n, gdim)`` of the facets' nodes, returning their displacements ``(n, gdim)``
        (``(n,)`` with ``component``), such as a :class:`RigidMotion`.
    component
        Constrain only this component.
    """

    tag: int | str
    value: Value | Callable[[float, np.ndarray], np.ndarray]
    component: int | None = None

    @property
    def varies_along_facets(self) -> bool:
        """Whether the value is a callable of ``(t, x)`` (two positional parameters)."""
        return takes_position(self.value)

    def values_at(self, t: float, x: np.ndarray) -> np.ndarray:
        """The prescribed displacements at the points ``x (n, gdim)`` at pseudo-time ``t``:
        ``(n, gdim)``, or ``(n,)`` with :attr:`component`."""
        n, gdim = x.shape
        shape = (n,) if self.component is not None else (n, gdim)
        if self.varies_along_facets:
            value = np.asarray(self.value(t, x), dtype=float)
            if value.shape != shape:
                raise ValueError(f"value(t, x) must return shape {shape}, got {value.shape}")
            return value
        value = evaluate(self.value, t)
        if self.component is None and value.ndim == 1:
            return np.broadcast_to(value, shape)
        return np.broadcast_to(value, shape if value.ndim == 0 else value.shape)


def takes_position(value) -> bool:
    """Whether ``value`` is a callable of ``(t, x)``: two positional parameters."""
    if not callable(value):
        return False
    try:
        parameters = inspect.signature(value).parameters.values()
    except (TypeError, ValueError):
        return False
    positional = [
        p
        for p in parameters
        if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) and p.default is p.empty
    ]
    return len(positional) == 2


def _is_translation(value, gdim: int) -> bool:
    """Whether a motion's value is a translation (``gdim`` numbers), not a pair."""
    try:
        return np.asarray(value, dtype=float).shape == (gdim,)
    except (TypeError, ValueError):  # a (translation, rotation) pair
        return False


@dataclass(frozen=True)
class RigidMotion:
    """A rigid motion of a support's facets, for :class:`Dirichlet`'s ``value``: the
    displacement ``u(x) = c(t) + (Q(t) - I)(x - centre)`` of a translation ``c`` and a
    rotation ``Q`` about ``centre``.

    Parameters
    ----------
    motion
        A callable of ``t`` returning a translation ``c(t)`` or a pair ``(c(t), Q(t))`` with
        ``Q`` a rotation matrix: the motion of the rigid obstacles
        (:mod:`contact_ufl.contact.obstacles`).
    centre
        The point the rotation is about (reference coordinates).

    Examples
    --------
    A hub turned by half a radian about the origin::

        def turn(t):
            a = 0.5 * t
            return (0.0, 0.0), [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]

        Dirichlet("hub", RigidMotion(turn, centre=(0.0, 0.0)))
    """

    motion: Callable
    centre: Sequence[float]

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        gdim = x.shape[1]
        value = self.motion(t)
        c, Q = (value, np.eye(gdim)) if _is_translation(value, gdim) else value
        c, Q = np.asarray(c, dtype=float), np.asarray(Q, dtype=float)
        if c.shape != (gdim,) or Q.shape != (gdim, gdim):
            raise ValueError(
                f"RigidMotion: motion(t) must return a translation of {gdim} components, or a "
                f"pair (translation, {gdim}x{gdim} rotation) in {gdim}D; got shapes "
                f"{c.shape} and {Q.shape}"
            )
        return c + (x - np.asarray(self.centre, dtype=float)) @ (Q - np.eye(gdim)).T


@dataclass(frozen=True)
class _DeadLoad:
    """A load of fixed direction and magnitude per unit reference measure (area or volume)
    on the entities ``tag``: its ``value`` (or a callable of ``t``)."""

    tag: int | str
    value: Value

    def virtual_work(self, u, v, measure, constant):
        """External virtual work ``int value . v`` over the tagged entities of ``measure``."""
        return ufl.dot(constant, v) * measure(self.tag)


@dataclass(frozen=True)
class DeadTraction(_DeadLoad):
    """Nominal (first Piola) traction per unit reference area, fixed in direction (dead).

    Parameters
    ----------
    tag
        Facet tag of the loaded surface, or the name of its physical group.
    value
        Traction vector ``T`` (force per unit reference area), or a callable of ``t``. A
        resultant ``P`` spread over the reference area ``A0`` is :class:`DeadForce`.

    Notes
    -----
    Its external virtual work is ``int T . v dS_o``.
    """


@dataclass(frozen=True)
class DeadForce(_DeadLoad):
    """A resultant force of fixed direction spread uniformly over the reference area of the
    facets ``tag``: the dead traction ``T = P / A0``, ``A0 = int_{tag} dS_o``.

    Parameters
    ----------
    tag
        Facet tag of the loaded surface, or the name of its physical group.
    value
        The resultant force vector ``P`` (force units; per unit thickness in plane strain),
        or a callable of ``t``.

    Notes
    -----
    Its external virtual work is ``int (P / A0) . v dS_o``, its resultant exactly ``P``;
    ``A0`` is assembled once when the problem is made (collectively).
    """

    def virtual_work(self, u, v, measure, constant):
        """External virtual work ``int (P / A0) . v dS_o`` (``constant`` holds ``P``)."""
        mesh = u.function_space.mesh
        area = reference_area(measure, mesh, self.tag)
        if not area > 0.0:
            raise ContactInputError(f"DeadForce: facet tag {self.tag} has zero reference area")
        return ufl.dot(constant, v) * dolfinx.fem.Constant(mesh, 1.0 / area) * measure(self.tag)


def reference_area(measure: ufl.Measure, mesh: dolfinx.mesh.Mesh, tag: int) -> float:
    """``A0 = int_{tag} d(measure)``, summed over all ranks (collective)."""
    one = dolfinx.fem.Constant(mesh, 1.0)
    local = dolfinx.fem.assemble_scalar(jit.form(one * measure(tag)))
    return mesh.comm.allreduce(local, MPI.SUM)


@dataclass(frozen=True)
class BodyForce(_DeadLoad):
    """Dead body force per unit reference volume (``rho_0 f``, ``f`` per unit mass).

    Parameters
    ----------
    tag
        Cell tag of the loaded body, or the name of its physical group.
    value
        Force vector per unit reference volume, or a callable of ``t``.

    Notes
    -----
    Its external virtual work is ``int rho_0 f . v dOmega_o``.
    """


def deformation_gradient(u: dolfinx.fem.Function) -> ufl.core.expr.Expr:
    """``F = I + grad u`` of the displacement ``u`` (gradient in the reference frame)."""
    return ufl.Identity(u.ufl_shape[0]) + ufl.grad(u)


@dataclass(frozen=True)
class FollowerPressure:
    """Pressure normal to the deformed surface (a follower load).

    A pressure ``p`` (force per unit *current* area, positive pushing into the body) on the
    facets ``tag``. Pulled back to the reference surface by Nanson's formula
    ``n da = J F^-T N dA`` it is the nominal (first Piola) traction per unit reference area

    ``T = -p J F^-T N = -p cof(F) N``,

    with ``N`` the outward unit normal of the reference surface (``ufl.FacetNormal``) and
    ``F = I + grad u``. Its external virtual work is ``int T . v dS_o`` over the reference
    facets. ``T`` depends on ``u``: the load stiffness ``-p d(cof F)/du N`` is in the Jacobian
    through ``ufl.derivative`` of the residual; it is not symmetric in general.

    Parameters
    ----------
    tag
        Facet tag of the loaded surface, or the name of its physical group.
    value
        Pressure ``p`` (stress units: force per unit current area), a scalar or a callable of
        the pseudo-time ``t`` returning one.
    """

    tag: int | str
    value: float | Callable[[float], float]

    def traction(self, u: dolfinx.fem.Function, p: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """The nominal traction ``T = -p J F^-T N`` per unit reference area."""
        N = ufl.FacetNormal(u.function_space.mesh)
        return -p * ufl.dot(ufl.cofac(deformation_gradient(u)), N)

    def virtual_work(self, u, v, ds, constant):
        """External virtual work ``int -p J F^-T N . v dS_o`` (``constant`` holds ``p``)."""
        return ufl.dot(self.traction(u, constant), v) * ds(self.tag)


@dataclass(frozen=True)
class FollowerForce:
    """A resultant force whose direction follows the deformation (e.g. a follower tip force).

    The magnitude ``P`` is spread uniformly over the reference area ``A0 = int_{tag} dS_o``
    of the facets ``tag``; its direction at each point is the reference direction ``d0``
    carried by the deformation and normalised, ``F d0 / |F d0|``. The nominal (first Piola)
    traction per unit reference area is

    ``T = (P / A0) F d0 / |F d0|``,    ``F = I + grad u``,

    and the external virtual work ``int T . v dS_o``. With ``d0`` tangent to the loaded
    section (e.g. ``(0, -1)`` on the end section ``x = L`` of a beam along x), ``F d0`` is
    the deformed section's tangent: the force stays perpendicular to the deformed beam axis
    (the classical follower tip load). Its resultant is ``P`` times the mean direction, i.e.
    exactly ``P`` while the section stays straight. The load stiffness (``ufl.derivative``
    of ``T . v`` through ``F``) is non-symmetric.

    Parameters
    ----------
    tag
        Facet tag of the loaded surface, or the name of its physical group.
    value
        Magnitude ``P`` of the resultant force (force units; per unit thickness in plane
        strain), a scalar or a callable of the pseudo-time ``t`` returning one.
    direction
        Reference direction ``d0`` (any nonzero length: only its direction counts), of the
        dimension of the mesh.
    """

    tag: int | str
    value: float | Callable[[float], float]
    direction: Sequence[float]

    def reference_area(self, ds: ufl.Measure, mesh: dolfinx.mesh.Mesh) -> float:
        """``A0 = int_{tag} dS_o``, summed over all ranks."""
        return reference_area(ds, mesh, self.tag)

    def traction(
        self, u: dolfinx.fem.Function, magnitude: ufl.core.expr.Expr
    ) -> ufl.core.expr.Expr:
        """The nominal traction ``T = magnitude F d0 / |F d0|`` per unit reference area."""
        d0 = np.asarray(self.direction, dtype=float)
        gdim = u.ufl_shape[0]
        if d0.shape != (gdim,) or not np.linalg.norm(d0) > 0.0:
            raise ContactInputError(
                f"FollowerForce on facet tag {self.tag}: direction must be a nonzero vector of "
                f"dimension {gdim}, got {tuple(d0.tolist())}"
            )
        d = ufl.dot(deformation_gradient(u), ufl.as_vector(d0.tolist()))
        return magnitude * d / ufl.sqrt(ufl.dot(d, d))

    def virtual_work(self, u, v, ds, constant):
        """External virtual work ``int (P / A0) F d0 / |F d0| . v dS_o`` (``constant``: P).

        ``A0`` is assembled here once (collectively) and enters the form as a constant.
        """
        mesh = u.function_space.mesh
        area = self.reference_area(ds, mesh)
        if not area > 0.0:
            raise ContactInputError(f"FollowerForce: facet tag {self.tag} has zero reference area")
        inverse_area = dolfinx.fem.Constant(mesh, 1.0 / area)
        return ufl.dot(self.traction(u, constant * inverse_area), v) * ds(self.tag)


#: Loads applied on tagged facets (all but :class:`BodyForce`, whose tag is a cell tag).
SurfaceLoad = DeadTraction | DeadForce | FollowerPressure | FollowerForce
#: Any load of a scene.
Load = SurfaceLoad | BodyForce


def load_constant(mesh: dolfinx.mesh.Mesh, load: Load) -> dolfinx.fem.Constant:
    """A constant of the right shape for ``load``, initialised at t = 0.

    A vector for dead tractions and body forces, a scalar (the pressure or force magnitude)
    for follower loads.
    """
    shape = evaluate(load.value, 0.0).shape
    return dolfinx.fem.Constant(mesh, np.zeros(shape))
