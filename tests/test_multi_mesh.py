"""Bodies on meshes of their own: one displacement field per mesh, one SNES.

Each scene is solved twice: on one mesh (one displacement field over all bodies) and with
each body on a mesh of its own (a submesh with the same geometry: one field per body, the
master nodes gathered from the master's field by the chain operator). The two are the same
discrete problem, so they must give the same answer to solver tolerance; and the exact
properties hold across meshes: the patch test's uniform multiplier, action and reaction
(property (e): the contact resultant on the master body is minus the slave's, to round-off),
a consistent tangent (Taylor slope 2).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import assert_taylor_slopes
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.results import body_resultants, equilibrium_error
from contact_ufl.verification import scenes
from contact_ufl.verification.taylor_cases import curved_case

COMM = MPI.COMM_WORLD
PRESSURE = 0.01
TIGHT = {"snes_rtol": 1e-12, "snes_atol": 1e-13}


def _solved(scene: cu.Scene, num_steps: int = 1, **options) -> cu.ContactProblem:
    problem = cu.ContactProblem(scene, verbose=False, petsc_options={**TIGHT, **options})
    problem.solve(num_steps=num_steps)
    return problem


@pytest.fixture(scope="module")
def patch_pair() -> tuple[cu.ContactProblem, cu.ContactProblem]:
    # the composite rule of tests/test_patch.py: uniform multipliers to 1e-3
    one = _solved(scenes.patch(pressure=PRESSURE, quadrature_degree=3, subdivisions=8))
    scene = scenes.patch(pressure=PRESSURE, quadrature_degree=3, subdivisions=8)
    two = _solved(scenes.on_meshes_of_their_own(scene))
    return one, two


def test_two_meshes_have_their_own_fields(patch_pair):
    _, two = patch_pair
    assert len(two.bulks) == 2
    assert two.unknowns[:2] == [b.u for b in two.bulks]
    meshes = {id(b.V.mesh) for b in two.bulks}
    assert len(meshes) == 2
    with pytest.raises(AttributeError, match="2 meshes"):
        _ = two.u


def test_patch_test_across_meshes(patch_pair):
    """The uniform multiplier of the patch test, with slave and master on two meshes."""
    _, two = patch_pair
    (c,) = two.contacts
    lam = c.multiplier_at_points()
    active = c.active()
    assert COMM.allreduce(int(active.sum())) == COMM.allreduce(len(active))
    error = COMM.allreduce(float(np.abs(lam / PRESSURE - 1.0).max(initial=0.0)), MPI.MAX)
    assert error < 1e-3  # as on one mesh (tests/test_patch.py)


def test_same_answer_as_one_mesh(patch_pair):
    one, two = patch_pair
    assert np.allclose(two.contact_force(), one.contact_force(), rtol=1e-10, atol=1e-14)
    for k, name in enumerate(("upper", "lower")):
        bulk = two.bulks[k]
        top = one.reaction(f"{name}_left")
        assert np.allclose(two.reaction(f"{name}_left"), top, rtol=1e-8, atol=1e-12)
        assert bulk.domain.name == name
    assert np.isclose(two.stored_energy(), one.stored_energy(), rtol=1e-10)


def test_action_and_reaction_across_meshes(patch_pair):
    """Property (e): the contact residual's resultant on the master mesh is minus the
    slave's, which is minus the contact force on the slave surface."""
    _, two = patch_pair
    resultants = body_resultants(two, two.contact_residual())
    slave, master = (resultants[b.bodies[0].tag] for b in two.bulks)
    force = two.contact_force()
    scale = np.abs(force).max()
    assert np.abs(slave + force).max() < 1e-12 * scale
    assert np.abs(master + slave).max() < 1e-12 * scale


def test_hertz_on_two_meshes_matches_one_mesh():
    """A curved master, large sliding of the projections: the same p0 and force."""
    hertz = scenes.hertz_2d(h_contact=0.05)
    one = _solved(hertz.scene, num_steps=2)
    hertz = scenes.hertz_2d(h_contact=0.05)
    two = _solved(scenes.on_meshes_of_their_own(hertz.scene), num_steps=2)
    f1, f2 = one.contact_force(), two.contact_force()
    assert np.allclose(f2, f1, rtol=1e-8, atol=1e-10 * np.abs(f1).max())
    p1 = COMM.allreduce(one.contacts[0].multiplier_at_points().max(initial=0.0), MPI.MAX)
    p2 = COMM.allreduce(two.contacts[0].multiplier_at_points().max(initial=0.0), MPI.MAX)
    assert abs(p2 - p1) < 1e-8 * p1


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("mu", [0.0, 0.05])
def test_taylor_across_meshes(dim, mu):
    """The tangent chained through a master on another mesh: Taylor slope 2 (frictionless
    and in slip), as on one mesh."""
    problem, dz, steps = curved_case(dim, mu=mu, own_meshes=True)
    assert len(problem.bulks) == 2 and problem.active_points() > 10
    assert_taylor_slopes(problem, dz, steps)


def test_integer_tag_needs_its_domain():
    scene = scenes.on_meshes_of_their_own(scenes.patch())
    pair = dataclasses.replace(scene.contacts[0], slave_domain=None)
    with pytest.raises(cu.ContactInputError, match="needs its domain"):
        dataclasses.replace(scene, contacts=[pair])


def test_equilibrium_across_meshes(patch_pair):
    """Supports (on both meshes) and the load balance; the contact forces are internal."""
    _, two = patch_pair
    supports = ["upper_left", "lower_left", "lower_bottom"]
    assert equilibrium_error(two, supports) < 1e-10


def test_name_in_two_domains_is_ambiguous():
    scene = scenes.on_meshes_of_their_own(scenes.patch())
    upper, lower = scene.domains
    groups = {**upper.groups, "interface": upper.groups["upper_contact"]}
    upper = dataclasses.replace(upper, groups=groups, tags={})
    lower = dataclasses.replace(
        lower, groups={**lower.groups, "interface": lower.groups["lower_contact"]}, tags={}
    )
    pair = cu.ContactPair("interface", "lower_contact")
    with pytest.raises(cu.ContactInputError, match="several domains"):
        cu.Scene(domains=[upper, lower], contacts=[pair])
    pair = cu.ContactPair("interface", "interface", slave_domain="upper", master_domain=1)
    resolved = cu.Scene(domains=[upper, lower], contacts=[pair]).contacts[0]
    assert (resolved.slave_domain, resolved.master_domain) == (0, 1)
    assert (resolved.slave, resolved.master) == tuple(
        d.groups["interface"][1] for d in (upper, lower)
    )
    pair = cu.ContactPair("interface", "lower_contact", slave_domain="middle")
    with pytest.raises(cu.ContactInputError, match="no domain of the scene is named 'middle'"):
        cu.Scene(domains=[upper, lower], contacts=[pair])
