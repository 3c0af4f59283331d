"""Path following by a volume: the pressure on a membrane as an unknown of the problem.

Load control (the pressure a given function of the pseudo-time) cannot pass a pressure
maximum: an inflating Neo-Hookean balloon has one at the stretch ``7^(1/6)``, beyond which
no larger pressure has a solution nearby and Newton fails. The enclosed volume grows
monotonically through it, and is the natural control: :class:`VolumeControl` makes the
pressure ``p`` on the membrane cells an unknown, and adds the equation

    V(u) = r(t) V_0,        V(u) = 1/3 int x . cof(F) n0 dA

(``V_0`` the volume at ``u = 0``; the integral of ``x . n da / 3`` over the membrane, the
divergence theorem: the enclosed volume when the membrane is closed or closed by symmetry
planes through the origin, on which ``x . n = 0``; in 2D the enclosed area, ``1/2 int x .
a dA``).

How it is assembled, with the package's chain operator (:mod:`contact_ufl.layout`): the
unknown is one number (a space with one dof, on a one-cell mesh), the assembled field is a
cellwise constant ``p_h`` on the membrane mesh whose every dof gathers that one unknown.
The bulk residual has ``-p_h a . v`` (its derivative in ``p_h`` is the load vector), and
the field's residual ``int (dV/dA - r V_0 / A) q dA`` summed by ``T^T`` over the dofs is
the volume equation. The tangent is ``ufl.derivative`` as everywhere; the bordered system
is solved by the same LU.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contact_ufl import jit
from contact_ufl.loads import evaluate
from contact_ufl.membranes import area_vector, pressure_virtual_work


@dataclass(frozen=True)
class VolumeControl:
    """A follower pressure on membrane cells whose magnitude is an unknown, found so that
    the enclosed volume follows ``volume_ratio(t)`` times its reference value.

    Give it among the ``loads`` of a membrane :class:`~contact_ufl.scene.Domain`, as a
    :class:`~contact_ufl.loads.FollowerPressure` would be (it pushes along the membrane's
    oriented normal ``n0``: ``n0`` must point out of the enclosed volume). The pressure is
    :attr:`VolumeConstraint.pressure` of ``problem.controls``.

    Parameters
    ----------
    tag
        Cell tag (or physical group name) of the membrane cells that enclose the volume.
    volume_ratio
        ``V / V_0`` as a function of the pseudo-time (or a constant): 1 at the start.
    """

    tag: int | str
    volume_ratio: float | Callable[[float], float]


class VolumeConstraint:
    """The unknown pressure of a :class:`VolumeControl` and its volume equation, for a
    membrane bulk.

    It provides what a contact interface provides to the problem and the solver: its
    assembled ``fields`` (``p_h``), ``unknowns`` (the one pressure), ``residuals`` (the
    volume equation) and ``bulk_residual(v)`` (the pressure's virtual work),
    ``update(layout)`` (the gathers of ``p_h``), ``set_time(t)``.

    Parameters
    ----------
    control
        The control (integer tag).
    bulk
        The membrane's :class:`~contact_ufl.bulk.Bulk`.
    scale
        A stiffness ``k = E / L`` (force per volume) multiplying the volume equation, so
        that its row is a force like every other.

    Attributes
    ----------
    block
        The block of the pressure unknown in the unknowns of the problem (set by the
        problem).
    """

    def __init__(self, control: VolumeControl, bulk, scale: float):
        self.control, self.bulk = control, bulk
        mesh = bulk.V.mesh
        comm = mesh.comm
        self.gdim = mesh.geometry.dim
        # the unknown: one number, a cellwise constant on a one-cell mesh (on one rank)
        self._line = dolfinx.mesh.create_interval(comm, 1, [0.0, 1.0])
        self.Q = dolfinx.fem.functionspace(self._line, ("DG", 0))
        self.pressure_unknown = dolfinx.fem.Function(self.Q, name="pressure")
        self.P = dolfinx.fem.functionspace(mesh, ("DG", 0))
        #: the pressure on the membrane cells (gathered from the unknown)
        self.p = dolfinx.fem.Function(self.P, name="pressure_field")
        self.target = dolfinx.fem.Constant(mesh, 0.0)
        u, n0, dx = bulk.u, bulk.n0, bulk.dx(control.tag)
        x = ufl.SpatialCoordinate(mesh) + u
        self.volume_density = ufl.dot(x, area_vector(u, n0)) / self.gdim
        self._volume_form = jit.form(self.volume_density * dx)
        self.reference_volume = self.volume()
        one = dolfinx.fem.Constant(mesh, 1.0)
        self.area = comm.allreduce(dolfinx.fem.assemble_scalar(jit.form(one * dx)))
        self.scale = scale
        self.block: int | None = None
        self._value = 0.0
        self._resultant_forms = None
        self._gathers: list = []
        self.set_time(0.0)

    # -- what the problem assembles -------------------------------------------------------
    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """The pressure on the membrane cells (gathered from the unknown)."""
        return [self.p]

    @property
    def unknowns(self) -> list[dolfinx.fem.Function]:
        """The pressure (one number)."""
        return [self.pressure_unknown]

    def bulk_residual(self, v: ufl.Argument) -> ufl.Form:
        """The pressure's virtual work, to subtract from the membrane's residual."""
        dx = self.bulk.dx(self.control.tag)
        return pressure_virtual_work(self.bulk.u, v, self.bulk.n0, self.p) * dx

    def residuals(self) -> list[ufl.Form]:
        """``k int (dV/dA - r V_0 / A) q dA``: summed over the dofs of ``p_h`` by ``T^T``,
        ``k (V(u) - r V_0)``."""
        q = ufl.TestFunction(self.P)
        density = self.volume_density - self.target / self.area
        return [self.scale * density * q * self.bulk.dx(self.control.tag)]

    def update(self, x, layout) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """Set ``p_h`` to the unknown pressure (which the unknowns ``x`` hold); every owned
        dof of ``p_h`` gathers it (:class:`~contact_ufl.coupling.Coupling`)."""
        comm = self.P.mesh.comm
        value = comm.allreduce(float(self.pressure_unknown.x.array[: self._owned_q].sum()))
        self.p.x.array[:] = self._value = value
        column = comm.allreduce(
            int(layout.owned(self.block, np.zeros(1))[0]) if self._owned_q else -1, MPI.MAX
        )
        owned = self.P.dofmap.index_map.size_local
        self._gathers = [(self.p, np.full(owned, column, dtype=np.int64))]
        return self._gathers

    def pattern_gathers(self) -> list[tuple[dolfinx.fem.Function, np.ndarray]]:
        """The gathers of the last :meth:`update` (none wider)."""
        return self._gathers

    @property
    def _owned_q(self) -> int:
        return self.Q.dofmap.index_map.size_local

    def set_time(self, t: float) -> None:
        """The target volume at pseudo-time ``t``."""
        self.target.value = float(evaluate(self.control.volume_ratio, t)) * self.reference_volume

    # -- results --------------------------------------------------------------------------
    def volume(self) -> float:
        """The enclosed volume ``V(u)`` at the current displacement (all ranks)."""
        comm = self.P.mesh.comm
        return comm.allreduce(dolfinx.fem.assemble_scalar(self._volume_form))

    @property
    def pressure(self) -> float:
        """The current pressure (the unknown; the same on all ranks)."""
        return self._value

    def load_resultant(self) -> np.ndarray:
        """Resultant ``int p a dA`` of the pressure (all ranks; its forms compiled once)."""
        if self._resultant_forms is None:
            u, n0, dx = self.bulk.u, self.bulk.n0, self.bulk.dx(self.control.tag)
            e = np.eye(self.gdim)
            self._resultant_forms = [
                jit.form(pressure_virtual_work(u, ufl.as_vector(e[i]), n0, self.p) * dx)
                for i in range(self.gdim)
            ]
        local = [dolfinx.fem.assemble_scalar(f) for f in self._resultant_forms]
        return self.P.mesh.comm.allreduce(np.asarray(local), MPI.SUM)
