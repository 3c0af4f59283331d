"""The bulk of one mesh: its displacement field and the weak form of its bodies and loads.

A :class:`Bulk` holds, for one :class:`~contact_ufl.scene.Domain` (a mesh and its bodies,
supports and loads), the displacement ``u``, the measures, the virtual work of the bodies'
stresses and of the loads in UFL, the plastic histories of elastoplastic bodies, and the
prescribed-displacement dofs. On a membrane (string) mesh the bodies' work is the
derivative of the membrane energy (:mod:`contact_ufl.membranes`) and a follower pressure
acts on the membrane cells along the oriented reference normal ``n0``. The problem
(:mod:`contact_ufl.problem`) composes one bulk per mesh with the contact interfaces between
them.
"""

from __future__ import annotations

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contact_ufl import jit, membranes
from contact_ufl.control import VolumeControl
from contact_ufl.loads import (
    BodyForce,
    FollowerPressure,
    deformation_gradient,
    evaluate,
    load_constant,
)
from contact_ufl.plasticity import J2Plasticity, PlasticHistory
from contact_ufl.scene import Body, Domain


class Bulk:
    """The displacement field of one mesh and the bulk weak form of its bodies and loads.

    Parameters
    ----------
    domain
        The mesh with its bodies, supports and loads (integer tags).
    degree
        Polynomial degree of the displacement.
    quadrature_degree
        Quadrature degree of the bulk integrals (default: exact for P1 simplices, ``2 p``
        otherwise; ``2 p`` on a membrane).

    Attributes
    ----------
    V, u
        The displacement space and the displacement.
    dx, ds
        Measures over the cells (subdomain data: the cell tags) and exterior facets (the
        facet tags).
    histories
        The :class:`~contact_ufl.plasticity.PlasticHistory` of each elastoplastic body, by
        cell tag.
    dirichlet_dofs
        Local (owned) indices of the prescribed displacement dofs (unrolled).
    membrane
        Whether the mesh is a membrane (string): topological dimension ``gdim - 1``.
    n0
        (membrane) The oriented unit reference normal (UFL), from :attr:`orientation`, the
        sign per cell of :func:`contact_ufl.membranes.cell_orientation`.
    """

    def __init__(self, domain: Domain, degree: int = 1, quadrature_degree: int | None = None):
        self.domain = domain
        mesh = domain.mesh
        self.comm = mesh.comm
        gdim = mesh.geometry.dim
        self.V = dolfinx.fem.functionspace(mesh, ("Lagrange", degree, (gdim,)))
        name = "displacement" + (f" ({domain.name})" if domain.name else "")
        self.u = dolfinx.fem.Function(self.V, name=name)
        simplex = mesh.topology.cell_type in (
            dolfinx.mesh.CellType.triangle,
            dolfinx.mesh.CellType.tetrahedron,
        )
        self.membrane = mesh.topology.dim < gdim
        self.orientation, self.n0 = None, None
        if self.membrane:
            membranes.check_manifold(mesh)
            self.orientation = membranes.cell_orientation(
                mesh, outward=domain.outward, direction=domain.direction
            )
            self.n0 = membranes.reference_normal(mesh, orientation=self.orientation)
        exact = 2 * degree - 1 if simplex and not self.membrane else 2 * degree
        qdeg = quadrature_degree or exact
        self.dx = ufl.Measure(
            "dx", domain=mesh, subdomain_data=domain.cell_tags, metadata={"quadrature_degree": qdeg}
        )
        self.ds = ufl.Measure("ds", domain=mesh, subdomain_data=domain.facet_tags)
        self.histories = {
            b.tag: PlasticHistory(b.material, self.u, qdeg, domain.cell_tags.find(b.tag))
            for b in domain.bodies
            if isinstance(b.material, J2Plasticity)
        }
        self.load_constants = [
            (load, load_constant(mesh, load))
            for load in domain.loads
            if not isinstance(load, VolumeControl)  # (its pressure is an unknown)
        ]
        self._energy_form = None
        self._load_resultant_forms = None
        self._locate_dirichlet()

    @property
    def bodies(self) -> list[Body]:
        """The bodies of this mesh."""
        return self.domain.bodies

    def first_piola(self, body: Body) -> ufl.core.expr.Expr:
        """First Piola-Kirchhoff stress of ``body`` at the current displacement (and, for an
        elastoplastic body, the history of the last converged step)."""
        if body.tag in self.histories:
            return self.histories[body.tag].first_piola()
        return body.material.first_piola(deformation_gradient(self.u))

    def residual(self, v: ufl.Argument) -> ufl.Form:
        """``int P : Grad v dV - (external virtual work)``: the bulk residual of this mesh (a
        membrane's: the derivative of its energy)."""
        if self.membrane:
            F = ufl.derivative(self.energy(), self.u, v)
        else:
            F = sum(
                ufl.inner(self.first_piola(b), ufl.grad(v)) * self.dx(b.tag) for b in self.bodies
            )
        for load, c in self.load_constants:
            F -= self.virtual_work(load, v, c)
        return F

    def energy(self) -> ufl.Form:
        """The stored energy ``sum_b int psi_b dV`` (per unit reference area on a
        membrane) of the bodies: of an elastoplastic one its elastic part, at the committed
        history."""
        if self.membrane:
            return sum(
                b.material.strain_energy(self.u, self.n0) * self.dx(b.tag) for b in self.bodies
            )
        F = deformation_gradient(self.u)
        return sum(
            (
                self.histories[b.tag].elastic_energy_density()
                if b.tag in self.histories
                else b.material.strain_energy(F)
            )
            * self.dx(b.tag)
            for b in self.bodies
        )

    def virtual_work(self, load, v, constant: dolfinx.fem.Constant) -> ufl.Form:
        """External virtual work of ``load`` (its value in ``constant``) on ``v``."""
        if self.membrane and isinstance(load, FollowerPressure):
            work = membranes.pressure_virtual_work(self.u, v, self.n0, constant)
            return work * self.dx(load.tag)
        return load.virtual_work(self.u, v, self.measure(load), constant)

    def measure(self, load) -> ufl.Measure:
        """The measure a load acts on: cells for a body force and for a pressure on a
        membrane, facets otherwise."""
        on_cells = isinstance(load, BodyForce) or (
            self.membrane and isinstance(load, FollowerPressure)
        )
        return self.dx if on_cells else self.ds

    def set_time(self, t: float) -> None:
        """Set the load constants to their values at pseudo-time ``t``."""
        for load, c in self.load_constants:
            c.value = evaluate(load.value, t)

    # -- supports -----------------------------------------------------------------------
    def _locate_dirichlet(self) -> None:
        fdim, gdim = self.V.mesh.topology.dim - 1, self.V.mesh.geometry.dim
        self._bc_dofs, self._bc_values, self._bc_points = [], [], []
        owned = self.V.dofmap.index_map.size_local * gdim
        nodes = self.V.tabulate_dof_coordinates()[:, :gdim]
        for bc in self.domain.dirichlet:
            facets = self.domain.facet_tags.find(bc.tag)
            comps = range(gdim) if bc.component is None else [bc.component]
            for i in comps:
                dofs = dolfinx.fem.locate_dofs_topological(self.V.sub(i), fdim, facets)
                dofs = dofs[dofs < owned]  # unrolled: node * gdim + i
                self._bc_dofs.append(dofs)
                self._bc_values.append((bc, i))
                self._bc_points.append(nodes[dofs // gdim])
        self.dirichlet_dofs = (
            np.concatenate(self._bc_dofs).astype(np.int64)
            if self._bc_dofs
            else np.zeros(0, np.int64)
        )
        #: which components of each local (owned and ghost) dof block are prescribed
        imap = self.V.dofmap.index_map
        self.prescribed_components = np.zeros((imap.size_local + imap.num_ghosts, gdim), bool)
        for bc in self.domain.dirichlet:
            facets = self.domain.facet_tags.find(bc.tag)
            blocks = dolfinx.fem.locate_dofs_topological(self.V, fdim, facets)
            comps = range(gdim) if bc.component is None else [bc.component]
            self.prescribed_components[np.ix_(blocks, list(comps))] = True

    def prescribed(self, t: float) -> np.ndarray:
        """The prescribed displacements ``g(t)`` of :attr:`dirichlet_dofs`."""
        values = []
        for x, (bc, i) in zip(self._bc_points, self._bc_values, strict=True):
            if bc.varies_along_facets:
                value = bc.values_at(t, x)
                values.append(value if bc.component is not None else value[:, i])
                continue
            value = evaluate(bc.value, t)
            value = value if bc.component is not None or value.ndim == 0 else value[i]
            values.append(np.full(len(x), float(value)))
        return np.concatenate(values) if values else np.zeros(0)

    def facet_dofs(self, tag: int) -> np.ndarray:
        """Owned dof blocks (nodes) of the facets ``tag``."""
        facets = self.domain.facet_tags.find(tag)
        blocks = dolfinx.fem.locate_dofs_topological(self.V, self.V.mesh.topology.dim - 1, facets)
        return blocks[blocks < self.V.dofmap.index_map.size_local]

    # -- what a state says ------------------------------------------------------------
    def load_resultant(self) -> np.ndarray:
        """Resultant of the loads of this mesh at the current state (all ranks)."""
        if self._load_resultant_forms is None:
            mesh = self.V.mesh
            gdim = mesh.geometry.dim
            self._load_resultant_forms = []
            for i in range(gdim):
                e_i = dolfinx.fem.Constant(mesh, np.eye(gdim)[i])
                work = sum(self.virtual_work(load, e_i, c) for load, c in self.load_constants)
                self._load_resultant_forms.append(jit.form(work) if work else None)
        local = [
            dolfinx.fem.assemble_scalar(f) if f is not None else 0.0
            for f in self._load_resultant_forms
        ]
        return self.comm.allreduce(np.asarray(local, dtype=float), MPI.SUM)

    def stored_energy(self) -> float:
        """Stored energy ``sum_b int psi_b dV`` of the bodies (:meth:`energy`)."""
        if self._energy_form is None:
            self._energy_form = jit.form(self.energy())
        return self.comm.allreduce(dolfinx.fem.assemble_scalar(self._energy_form))
