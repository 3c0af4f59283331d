"""Bulk mechanics: homogeneous plane-strain stretch under a dead traction, against the
analytic first Piola-Kirchhoff stress of each strain energy."""

import basix.ufl
import dolfinx
import numpy as np
import pytest
import ufl
from conftest import symmetric_square, tagged_unit_square
from mpi4py import MPI
from scipy.optimize import brentq

from contact_ufl.errors import ContactInputError
from contact_ufl.loads import BodyForce, DeadTraction, Dirichlet
from contact_ufl.materials import NeoHookean, SaintVenantKirchhoff
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Body, Scene


def block(n=4):
    """The unit square, one body (tag 1), sides tagged left 1, right 2, bottom 3, top 4."""
    return tagged_unit_square(n)


def piola_11(material, l1, l2):
    """P_11 of the homogeneous plane-strain deformation F = diag(l1, l2), from UFL."""
    F = ufl.as_matrix([[l1, 0.0], [0.0, l2]])
    return float(ufl.algorithms.expand_derivatives(material.first_piola(F))[0, 0])


@pytest.mark.parametrize("material", [NeoHookean(1.0, 0.3), SaintVenantKirchhoff(1.0, 0.3)])
def test_uniaxial_dead_traction(material):
    t = 0.08
    scene = symmetric_square(material, [DeadTraction(2, lambda s: (t * s, 0.0))])
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=2)
    u = problem.u.x.array.reshape(-1, 2)
    x = problem.V.tabulate_dof_coordinates()[:, :2]
    l1 = 1.0 + np.max(u[:, 0][np.isclose(x[:, 0], 1.0)])
    l2 = 1.0 + np.max(u[:, 1][np.isclose(x[:, 1], 1.0)], initial=-np.inf)
    l1 = problem.comm.allreduce(l1, MPI.MAX)
    l2 = problem.comm.allreduce(l2, MPI.MAX)
    # analytic: free lateral side, P_22 = 0 and P_11 = t
    mu, lmbda = material.mu, material.lmbda
    if isinstance(material, NeoHookean):

        def p22(b, a):
            return mu * (b - 1 / b) + lmbda * np.log(a * b) / b

        def p11(a, b):
            return mu * (a - 1 / a) + lmbda * np.log(a * b) / a
    else:

        def p22(b, a):
            e1, e2 = (a * a - 1) / 2, (b * b - 1) / 2
            return b * (lmbda * (e1 + e2) + 2 * mu * e2)

        def p11(a, b):
            e1, e2 = (a * a - 1) / 2, (b * b - 1) / 2
            return a * (lmbda * (e1 + e2) + 2 * mu * e1)

    lat = lambda a: brentq(p22, 0.5, 1.0 + 1e-9, args=(a,))  # noqa: E731
    a = brentq(lambda a: p11(a, lat(a)) - t, 1.0, 1.5)
    assert l1 == pytest.approx(a, rel=1e-9)
    assert l2 == pytest.approx(lat(a), rel=1e-9)
    assert piola_11(material, a, lat(a)) == pytest.approx(t, rel=1e-12)


def test_body_force_reaction():
    """The support reaction of a block under its weight balances the weight."""
    mesh, cells, facets = block()
    g = 0.01
    scene = Scene(
        mesh,
        cells,
        facets,
        [Body(1, NeoHookean(1.0, 0.3))],
        dirichlet=[Dirichlet(3, (0.0, 0.0))],
        loads=[BodyForce(1, lambda s: (0.0, -g * s))],
    )
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=1)
    assert problem.reaction(3) == pytest.approx([0.0, g], abs=1e-12)
    assert problem.reaction(4) == pytest.approx([0.0, 0.0], abs=1e-12)  # free side


def test_manifold_mesh_is_rejected():
    """A surface mesh in 3D is not a solid of full dimension."""
    comm = MPI.COMM_WORLD
    domain = ufl.Mesh(basix.ufl.element("Lagrange", "triangle", 1, shape=(3,)))
    x = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.2]], dtype=float)
    cells = np.array([[0, 1, 2]], dtype=np.int64)
    if comm.rank > 0:
        x, cells = x[:0], cells[:0]
    mesh = dolfinx.mesh.create_mesh(comm, cells, domain, x)
    tdim = mesh.topology.dim
    ncells = mesh.topology.index_map(tdim).size_local
    cell_tags = dolfinx.mesh.meshtags(
        mesh, tdim, np.arange(ncells, dtype=np.int32), np.ones(ncells, dtype=np.int32)
    )
    facet_tags = dolfinx.mesh.meshtags(mesh, tdim - 1, np.zeros(0, np.int32), np.zeros(0, np.int32))
    scene = Scene(mesh, cell_tags, facet_tags, [Body(1, NeoHookean(1.0, 0.3))])
    with pytest.raises(ContactInputError, match="topological dimension 2 in 3D"):
        ContactProblem(scene, verbose=False)


def test_prescribed_displacement_with_a_stiff_material():
    """Prescribed displacements are met whatever the units of the moduli: the support
    equations are scaled to forces, so the absolute tolerance cannot accept a state that
    does not satisfy them (E = 7e9 here)."""
    scene = symmetric_square(
        NeoHookean(6.896e9, 0.32), [], dirichlet=[Dirichlet(2, lambda s: 0.01 * s, component=0)]
    )
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=1)
    assert problem.history.steps[0].newton_iterations >= 2
    u = problem.u.x.array.reshape(-1, 2)
    x = problem.V.tabulate_dof_coordinates()[:, :2]
    right = np.isclose(x[:, 0], 1.0)
    assert np.allclose(u[right, 0], 0.01, rtol=0, atol=1e-12)
    assert abs(problem.reaction(2)[0]) > 1e7  # a real force, of the order E * strain
