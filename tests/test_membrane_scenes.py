"""Membranes in scenes: a membrane mesh as a Domain, solved by ContactProblem.

The membrane mechanics of :mod:`contact_ufl.membranes` are verified on their own in
``tests/test_membranes.py``; here the same closed forms check that the problem wires them in
(energy, follower pressure along the oriented normal, supports on membrane edges), and that
a wrong mesh for a body is refused.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import assert_taylor_slopes
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.membranes import MembraneNeoHookean
from contact_ufl.results import equilibrium_error
from contact_ufl.verification import analytic, scenes
from contact_ufl.verification.taylor_cases import membrane_pressure_case

COMM = MPI.COMM_WORLD
MU, T0, R = 1.0, 0.01, 1.0
P_MAX = analytic.sphere_inflation_neo_hookean(MU, T0, R, 7.0 ** (1.0 / 6.0))
SPHERE = "free inflation through the problem, Neo-Hookean sphere octant, 32 cells per arc"
EQUILIBRIUM = "the equilibrium of a converged solve: the P1 test functions sum to one"
#: the inflation pressure against the closed form, 32 cells per arc (measured 0.15%)
INFLATION = 3e-3
#: the octant's balance and the symmetry of its load: round-off (measured at most 6e-15 on 1
#: or 2 ranks; the partition changes the last digits)
ROUND_OFF = 2e-14


def mean_stretch(bulk) -> float:
    """Mean current distance of the nodes from the origin, over R (all ranks)."""
    owned = bulk.V.dofmap.index_map.size_local
    X = bulk.V.tabulate_dof_coordinates()[:owned]
    x = X + bulk.u.x.array.reshape(-1, 3)[:owned]
    return COMM.allreduce(np.linalg.norm(x, axis=1).sum()) / COMM.allreduce(owned) / R


@pytest.fixture(scope="module")
def sphere():
    """The Neo-Hookean sphere octant inflated to 95% of its pressure maximum."""
    scene = scenes.inflated_sphere(n=32, law=MembraneNeoHookean(MU, T0), pressure=0.95 * P_MAX)
    problem = cu.ContactProblem(scene, verbose=False)
    stretches = []
    problem.solve(num_steps=5, callback=lambda p, r: stretches.append(mean_stretch(p.bulks[0])))
    return problem, np.array(stretches)


def test_sphere_inflation_through_the_problem(sphere, verification):
    """Pressure against stretch within 0.3% of ``2 mu t0/R (1/l - 1/l^7)`` at every step
    (the P1 facets' O(h^2) error, as in tests/test_membranes.py)."""
    problem, stretches = sphere
    assert problem.bulks[0].membrane
    assert len(problem.history.steps) == 5 and not problem.history.cutbacks
    pressures = 0.95 * P_MAX * np.linspace(0.2, 1.0, 5)
    exact = analytic.sphere_inflation_neo_hookean(MU, T0, R, stretches)
    assert np.all(stretches > 1.0) and stretches[-1] > 1.15
    error = np.abs(pressures / exact - 1.0).max()
    quantity = "largest |p / p_exact(l) - 1| over the steps, to 95% of the pressure maximum"
    source = "closed form of the homogeneous inflation, p = 2 mu t0 / R (1/l - 1/l^7)"
    verification(SPHERE, quantity, error, 0.0, INFLATION, source)
    assert error < INFLATION


def test_sphere_equilibrium(sphere, verification):
    """Consistency: the supports on the three symmetry edges balance the follower pressure,
    which pushes the octant out along +x, +y, +z alike (its mesh is symmetric)."""
    problem, _ = sphere
    load = problem.load_resultant()
    spread = (load.max() - load.min()) / load.max()
    quantity = "(largest - smallest) / largest component of the pressure's resultant"
    source = "the octant's symmetry under the permutations of the axes"
    verification(SPHERE, quantity, spread, 0.0, ROUND_OFF, source, kind="consistency")
    assert spread < ROUND_OFF and load[0] > 0.0
    error = equilibrium_error(problem, ["x0", "y0", "z0"])
    quantity = "|supports + pressure| / |pressure|"
    verification(SPHERE, quantity, error, 0.0, ROUND_OFF, EQUILIBRIUM, kind="consistency")
    assert error < ROUND_OFF


def test_membrane_law_on_a_solid_mesh_is_refused():
    scene = scenes.patch()
    law = MembraneNeoHookean(1.0, 0.01)
    bodies = [dataclasses.replace(b, material=law) for b in scene.bodies]
    with pytest.raises(cu.ContactInputError, match="membrane bodies need a membrane mesh"):
        cu.ContactProblem(dataclasses.replace(scene, bodies=bodies), verbose=False)
    mixed = [bodies[0], scene.bodies[1]]
    with pytest.raises(cu.ContactInputError, match="solids or membranes, not both"):
        cu.ContactProblem(dataclasses.replace(scene, bodies=mixed), verbose=False)


def test_solid_material_on_a_membrane_mesh_is_refused():
    scene = scenes.inflated_sphere(n=4)
    (domain,) = scene.domains
    bodies = [dataclasses.replace(domain.bodies[0], material=cu.NeoHookean(1.0, 0.3))]
    bad = cu.Scene(domains=[dataclasses.replace(domain, bodies=bodies)])
    with pytest.raises(cu.ContactInputError, match="solid bodies need"):
        cu.ContactProblem(bad, verbose=False)


def test_pressure_on_membrane_edges_is_refused():
    """A pressure on a membrane acts on its cells: an edge group is the wrong dimension."""
    scene = scenes.inflated_sphere(n=4)
    (domain,) = scene.domains
    with pytest.raises(cu.ContactInputError, match="has dimension 1"):
        dataclasses.replace(domain, loads=[cu.FollowerPressure("x0", 1.0)])


@pytest.mark.parametrize("dim", [2, 3])
def test_taylor_membrane_under_follower_pressure(dim, verification):
    """The tangent of the membrane energy and of the follower pressure's load stiffness
    (``ufl.derivative`` through the oriented normal), in the problem: Taylor slope 2."""
    problem, dz, steps = membrane_pressure_case(dim)
    result = assert_taylor_slopes(problem, dz, steps, tol=3e-3, unchanged=False)  # 1e-3 measured
    case = f"Taylor test {dim}D, membrane under a follower pressure, no contact"
    quantity = "slopes of the Taylor remainder |R1(h)|"
    source = "Taylor's theorem: the remainder of an exact derivative is O(h^2)"
    verification(case, quantity, result.slopes, 2.0, "|slope - reference| < 3e-3", source)


def test_non_orientable_membrane_is_refused():
    """A Moebius strip has no consistent normal: the problem refuses it on every rank."""
    from contact_ufl.verification import membrane_meshes

    data = membrane_meshes.with_tags(membrane_meshes.moebius_strip(COMM), {})
    domain = cu.Domain.from_mesh_data(
        data, bodies=[cu.Body("membrane", MembraneNeoHookean(1.0, 0.01))]
    )
    with pytest.raises(cu.ContactInputError, match="orient"):
        cu.ContactProblem(cu.Scene(domains=[domain]), verbose=False)


def test_pressure_on_solid_cells_is_refused():
    """A follower pressure on a solid acts on its boundary facets, not on its cells."""
    scene = scenes.patch()
    with pytest.raises(cu.ContactInputError, match="facet group"):
        dataclasses.replace(scene, loads=[cu.FollowerPressure("upper", 1.0)])


def test_membrane_domain_from_a_gmsh_file(tmp_path):
    """A membrane meshed with gmsh (a square surface in 3D, named groups) read in one call:
    its cells are the body, its boundary edges a support group."""
    import gmsh

    from contact_ufl.gmshio import gmsh_session

    path = tmp_path / "membrane.msh"
    if COMM.rank == 0:
        with gmsh_session("membrane"):
            square = gmsh.model.occ.addRectangle(0.0, 0.0, 0.0, 1.0, 1.0)
            gmsh.model.occ.synchronize()
            edges = [tag for _, tag in gmsh.model.getBoundary([(2, square)], oriented=False)]
            gmsh.model.addPhysicalGroup(2, [square], 1, name="membrane")
            gmsh.model.addPhysicalGroup(1, edges, 2, name="frame")
            gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
            gmsh.model.mesh.generate(2)
            gmsh.write(str(path))
    COMM.barrier()
    path = COMM.bcast(str(path))
    domain = cu.Domain.from_gmsh(
        path,
        bodies=[cu.Body("membrane", MembraneNeoHookean(1.0, 0.01))],
        dirichlet=[cu.Dirichlet("frame", 0.0)],
        gdim=3,
        comm=COMM,
        direction=(0.0, 0.0, 1.0),
    )
    assert domain.membrane and domain.mesh.geometry.dim == 3
    bulk = cu.ContactProblem(cu.Scene(domains=[domain]), verbose=False).bulks[0]
    held = COMM.allreduce(len(bulk.dirichlet_dofs))
    assert bulk.membrane and held > 0
