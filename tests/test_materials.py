"""Bulk mechanics: homogeneous plane-strain stretch under a dead traction or a prescribed
displacement, against the analytic first Piola-Kirchhoff stress of each strain energy."""

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

UNIAXIAL = "closed form: homogeneous plane-strain uniaxial stress of the strain energy"
EQUILIBRIUM = "equilibrium of the converged solve"
#: stretches against the closed form, to the Newton tolerance (measured 1.1e-11)
STRETCH_TOL = 3e-11
#: the UFL first Piola-Kirchhoff stress against the closed form, to round-off (measured
#: 4.7e-15)
PIOLA_TOL = 1e-14
#: reactions of the block under its weight, to round-off (measured 5.0e-17)
REACTION_TOL = 1e-16
#: the prescribed displacement met (measured 0: it is set, not solved for), and the reaction
#: against the closed form, to the Newton tolerance (measured 9.0e-15)
PRESCRIBED_TOL, STIFF_TOL = 1e-15, 2e-14


def block(n=4):
    """The unit square, one body (tag 1), sides tagged left 1, right 2, bottom 3, top 4."""
    return tagged_unit_square(n)


def piola_11(material, l1, l2):
    """P_11 of the homogeneous plane-strain deformation F = diag(l1, l2), from UFL."""
    F = ufl.as_matrix([[l1, 0.0], [0.0, l2]])
    return float(ufl.algorithms.expand_derivatives(material.first_piola(F))[0, 0])


def closed_form_piola(material, a: float, b: float) -> tuple[float, float]:
    """``(P_11, P_22)`` of the plane-strain deformation ``F = diag(a, b)``, written out:
    Neo-Hookean ``P = mu (F - F^-T) + lambda ln(J) F^-T``, Saint Venant-Kirchhoff ``P = F
    (lambda tr(E) I + 2 mu E)``."""
    mu, lmbda = material.mu, material.lmbda
    if isinstance(material, NeoHookean):
        return (
            mu * (a - 1 / a) + lmbda * np.log(a * b) / a,
            mu * (b - 1 / b) + lmbda * np.log(a * b) / b,
        )
    e1, e2 = (a * a - 1) / 2, (b * b - 1) / 2
    return a * (lmbda * (e1 + e2) + 2 * mu * e1), b * (lmbda * (e1 + e2) + 2 * mu * e2)


def lateral_stretch(material, a: float) -> float:
    """The stretch ``b`` of the free side (``P_22 = 0``) at the stretch ``a``."""
    return brentq(lambda b: closed_form_piola(material, a, b)[1], 0.5, 1.0 + 1e-9, xtol=1e-15)


def stretches(problem) -> tuple[float, float]:
    """The stretches of the unit square from the displacement of its right and top sides."""
    u = problem.u.x.array.reshape(-1, 2)
    x = problem.V.tabulate_dof_coordinates()[:, :2]
    l1 = 1.0 + np.max(u[:, 0][np.isclose(x[:, 0], 1.0)], initial=-np.inf)
    l2 = 1.0 + np.max(u[:, 1][np.isclose(x[:, 1], 1.0)], initial=-np.inf)
    return problem.comm.allreduce(l1, MPI.MAX), problem.comm.allreduce(l2, MPI.MAX)


@pytest.mark.parametrize("material", [NeoHookean(1.0, 0.3), SaintVenantKirchhoff(1.0, 0.3)])
def test_uniaxial_dead_traction(material, verification):
    t = 0.08
    scene = symmetric_square(material, [DeadTraction(2, lambda s: (t * s, 0.0))])
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=2)
    l1, l2 = stretches(problem)
    # analytic: free lateral side, P_22 = 0 and P_11 = t
    a = brentq(
        lambda a: closed_form_piola(material, a, lateral_stretch(material, a))[0] - t,
        1.0,
        1.5,
        xtol=1e-15,
    )
    b = lateral_stretch(material, a)
    errors = np.abs(np.array([l1 / a, l2 / b]) - 1.0)
    piola_error = abs(piola_11(material, a, b) / t - 1.0)
    case = f"{type(material).__name__} square (E = 1, nu = 0.3) under a dead traction 0.08"
    verification(
        case,
        "relative error of the stretches (l1, l2)",
        errors,
        [a, b],
        f"< {STRETCH_TOL:g}",
        UNIAXIAL,
    )
    verification(
        case,
        "relative error of the UFL P_11 at the closed-form stretches",
        piola_error,
        t,
        f"< {PIOLA_TOL:g}",
        UNIAXIAL,
    )
    assert np.all(errors < STRETCH_TOL), errors
    assert piola_error < PIOLA_TOL


def test_body_force_reaction(verification):
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
    support = np.abs(problem.reaction(3) - [0.0, g]).max()
    free = np.abs(problem.reaction(4)).max()
    case = "Neo-Hookean unit square on its bottom side under its weight g = 0.01"
    verification(
        case,
        "max |bottom reaction - (0, g)|",
        support,
        [0.0, g],
        f"< {REACTION_TOL:g}",
        EQUILIBRIUM,
        kind="consistency",
    )
    verification(
        case,
        "max |reaction of the free top side|",
        free,
        0.0,
        f"< {REACTION_TOL:g}",
        EQUILIBRIUM,
        kind="consistency",
    )
    assert support < REACTION_TOL
    assert free < REACTION_TOL


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


def test_prescribed_displacement_with_a_stiff_material(verification):
    """Prescribed displacements are met whatever the units of the moduli: the support
    equations are scaled to forces, so the absolute tolerance cannot accept a state that
    does not satisfy them (E = 7e9 here). The reaction is the closed-form uniaxial stress
    of the stretch 1.01 (free top side)."""
    material = NeoHookean(6.896e9, 0.32)
    scene = symmetric_square(
        material, [], dirichlet=[Dirichlet(2, lambda s: 0.01 * s, component=0)]
    )
    problem = ContactProblem(scene, verbose=False)
    problem.solve(num_steps=1)
    assert problem.history.steps[0].newton_iterations >= 2
    u = problem.u.x.array.reshape(-1, 2)
    x = problem.V.tabulate_dof_coordinates()[:, :2]
    right = np.isclose(x[:, 0], 1.0)
    met = problem.comm.allreduce(np.abs(u[right, 0] - 0.01).max(initial=0.0), MPI.MAX)
    expected = closed_form_piola(material, 1.01, lateral_stretch(material, 1.01))[0]
    error = abs(problem.reaction(2)[0] / expected - 1.0)
    case = "Neo-Hookean unit square (E = 6.9e9, nu = 0.32), right side moved by 0.01"
    verification(
        case,
        "max |u_x - 0.01| on the moved side",
        met,
        0.0,
        f"< {PRESCRIBED_TOL:g}",
        "the prescribed displacement",
        kind="consistency",
    )
    verification(
        case,
        "relative error of the reaction on the moved side",
        error,
        expected,
        f"< {STIFF_TOL:g}",
        UNIAXIAL,
    )
    assert met < PRESCRIBED_TOL
    assert error < STIFF_TOL
