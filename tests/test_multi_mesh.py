"""Bodies on meshes of their own: one displacement field per mesh, one SNES.

A scene with each body on a mesh of its own (a submesh with the same geometry: one field per
body, the master nodes gathered from the master's field by the chain operator) is the same
discrete problem as on one mesh: the two answers agree to solver tolerance (a consistency
check). Verified against what holds independently of the code: the patch test's uniform
multiplier and Hertz's closed form across the two meshes, a consistent tangent (Taylor
slope 2). Action and reaction (property (e): the contact resultant on the master body is
minus the slave's) and the equilibrium of the supports hold by construction (consistency).
The Hertz scene on two meshes is solved on one rank and on two, to the same answer.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import across_ranks, assert_taylor_slopes
from mpi4py import MPI
from test_hertz import BOUNDS, hertz_errors, record_hertz_errors
from test_taylor import SLOPE_TOL, record_slopes

import contact_ufl as cu
from contact_ufl.results import body_resultants, contact_samples, equilibrium_error
from contact_ufl.verification import scenes
from contact_ufl.verification.taylor_cases import curved_case

COMM = MPI.COMM_WORLD
PRESSURE = 0.01
TIGHT = {"snes_rtol": 1e-12, "snes_atol": 1e-13}
PATCH = "patch test 2D on two meshes, 2-point Gauss rule on 8 sub-segments"
HERTZ = "Hertz 2D on two meshes, Neo-Hookean, 4 load steps, a/h = 10"
ONE_MESH = "the same scene on one mesh (one displacement field)"
#: the bound on differences of round-off: the same discrete problem assembled in another
#: order (another mesh layout, another partition), solved to the same iterations
ROUND_OFF = 1e-12


def _solved(scene: cu.Scene, num_steps: int = 1, **options) -> cu.ContactProblem:
    problem = cu.ContactProblem(scene, verbose=False, petsc_options={**TIGHT, **options})
    problem.solve(num_steps=num_steps)
    return problem


def _hertz_on_own_meshes(comm: MPI.Comm = COMM):
    """The Hertz scene of tests/test_hertz.py (a/h = 10, 4 steps, the default solver
    tolerances), the disc and the block each on a mesh of its own."""
    hertz = scenes.hertz_2d(h_contact=0.005, depth=0.005, comm=comm)
    problem = cu.ContactProblem(scenes.on_meshes_of_their_own(hertz.scene), verbose=False)
    problem.solve(num_steps=4)
    return problem, hertz


@pytest.fixture(scope="module")
def patch_pair() -> tuple[cu.ContactProblem, cu.ContactProblem]:
    # the composite rule of tests/test_patch.py: uniform multipliers to 1e-3
    one = _solved(scenes.patch(pressure=PRESSURE, quadrature_degree=3, subdivisions=8))
    scene = scenes.patch(pressure=PRESSURE, quadrature_degree=3, subdivisions=8)
    two = _solved(scenes.on_meshes_of_their_own(scene))
    return one, two


@pytest.fixture(scope="module")
def hertz_own_meshes():
    return _hertz_on_own_meshes()


@pytest.mark.serial  # on 2 ranks: this file's rank comparisons
def test_two_meshes_have_their_own_fields(patch_pair):
    _, two = patch_pair
    assert len(two.bulks) == 2
    assert two.unknowns[:2] == [b.u for b in two.bulks]
    meshes = {id(b.V.mesh) for b in two.bulks}
    assert len(meshes) == 2
    with pytest.raises(AttributeError, match="2 meshes"):
        _ = two.u


def test_patch_test_across_meshes(patch_pair, verification):
    """The uniform multiplier of the patch test, with slave and master on two meshes: within
    1e-3 of the applied pressure, as on one mesh (tests/test_patch.py; 4.8e-4 measured)."""
    _, two = patch_pair
    (c,) = two.contacts
    lam = c.multiplier_at_points()
    active = c.active()
    assert COMM.allreduce(int(active.sum())) == COMM.allreduce(len(active))
    error = COMM.allreduce(float(np.abs(lam / PRESSURE - 1.0).max(initial=0.0)), MPI.MAX)
    source = "the applied pressure: the patch test's exact solution is uniform"
    verification(PATCH, "largest |lambda_N / p - 1|", error, "lambda_N = p", "< 1e-3", source)
    assert error < 1e-3


def test_same_answer_as_one_mesh(patch_pair, verification):
    """The contact force, the side supports' reactions and the stored energy of one mesh,
    relative to the load: identical on one rank, to round-off on two (the meshes are then
    partitioned apart; 1e-14 measured), bounded by ROUND_OFF."""
    one, two = patch_pair
    force = np.abs(two.contact_force() - one.contact_force()).max() / PRESSURE
    reaction = 0.0
    for k, name in enumerate(("upper", "lower")):
        r1, r2 = one.reaction(f"{name}_left"), two.reaction(f"{name}_left")
        reaction = max(reaction, np.abs(r2 - r1).max() / PRESSURE)
        assert two.bulks[k].domain.name == name
    energy = abs(two.stored_energy() / one.stored_energy() - 1.0)
    for quantity, value in (
        ("largest contact force difference, over the load", force),
        ("largest side support reaction difference, over the load", reaction),
        ("relative stored energy difference", energy),
    ):
        verification(PATCH, quantity, value, 0.0, f"< {ROUND_OFF:g}", ONE_MESH, kind="consistency")
    assert force < ROUND_OFF
    assert reaction < ROUND_OFF
    assert energy < ROUND_OFF


def test_action_and_reaction_across_meshes(patch_pair, verification):
    """Property (e): the contact residual's resultant on the master mesh is minus the
    slave's, which is minus the contact force on the slave surface. Both hold by
    construction (the master shape functions sum to one; the contact force is the slave
    side of the contact residual), whatever the solution."""
    _, two = patch_pair
    resultants = body_resultants(two, two.contact_residual())
    slave, master = (resultants[b.bodies[0].tag] for b in two.bulks)
    force = two.contact_force()
    scale = np.abs(force).max()
    source = "action = reaction: the master shape functions sum to one"
    for quantity, value in (
        ("largest |F_slave + contact force| / |contact force|", np.abs(slave + force).max()),
        ("largest |F_slave + F_master| / |contact force|", np.abs(master + slave).max()),
    ):
        verification(PATCH, quantity, value / scale, 0.0, "< 1e-14", source, "consistency")
    assert np.abs(slave + force).max() < 1e-14 * scale
    assert np.abs(master + slave).max() < 1e-14 * scale


@pytest.mark.serial  # 2 ranks: test_hertz_on_own_meshes_on_any_number_of_ranks
def test_hertz_across_meshes(hertz_own_meshes, verification):
    """Hertz's closed form with the disc and the block on meshes of their own: the bounds of
    tests/test_hertz.py at a/h = 10 (a within 0.5%, p0 within 1%, profile within 3% of p0)."""
    problem, hertz = hertz_own_meshes
    assert len(problem.bulks) == 2
    a_err, p0_err, profile_err, exact = hertz_errors(problem, hertz)
    record_hertz_errors(verification, HERTZ, a_err, p0_err, profile_err, BOUNDS)
    assert exact.a / hertz.h_contact > 8
    assert abs(a_err) < BOUNDS[0]
    assert abs(p0_err) < BOUNDS[1]
    assert profile_err < BOUNDS[2]


@pytest.mark.serial  # 2 ranks: test_hertz_on_own_meshes_on_any_number_of_ranks
def test_hertz_on_two_meshes_matches_one_mesh(hertz_own_meshes, hertz_moderate, verification):
    """A curved slave sliding over the master facets: the contact force, the multipliers and
    the block's support reaction of one mesh (identical on one rank: the same dofs in the
    same order; bounded by ROUND_OFF)."""
    two, _ = hertz_own_meshes
    one, _ = hertz_moderate
    f1, f2 = one.contact_force(), two.contact_force()
    force = np.abs(f2 - f1).max() / np.abs(f1).max()
    s1, s2 = contact_samples(one), contact_samples(two)
    o1, o2 = np.lexsort(s1.X.T), np.lexsort(s2.X.T)
    np.testing.assert_allclose(s2.X[o2], s1.X[o1], rtol=0, atol=1e-14)
    multiplier = np.abs(s2.lambda_N[o2] - s1.lambda_N[o1]).max() / s1.lambda_N.max()
    r1, r2 = one.reaction("block_bottom"), two.reaction("block_bottom")
    reaction = np.abs(r2 - r1).max() / np.abs(r1).max()
    for quantity, value in (
        ("largest contact force difference, relative", force),
        ("largest multiplier difference, over the largest", multiplier),
        ("largest block support reaction difference, relative", reaction),
    ):
        verification(HERTZ, quantity, value, 0.0, f"< {ROUND_OFF:g}", ONE_MESH, "consistency")
    assert force < ROUND_OFF
    assert multiplier < ROUND_OFF
    assert reaction < ROUND_OFF


@across_ranks
def test_hertz_on_own_meshes_on_any_number_of_ranks(hertz_own_meshes, verification):
    """The two-mesh Hertz scene on all ranks gives the answer of one rank: the contact force,
    the multiplier at every slave point, the block's support reaction and the Newton
    iterations, to round-off (5e-14 measured; bound ROUND_OFF, the summation order differs
    between partitions). A master node gathered from the wrong rank or dof would move a
    master facet under the slave points by the displacement difference of two nodes (up to
    3% of the depth next to the contact) and change the multipliers far beyond the bound."""
    world, _ = hertz_own_meshes
    alone, _ = _hertz_on_own_meshes(MPI.COMM_SELF)
    case = "Hertz 2D on two meshes, a/h = 10, all ranks against one"
    f1, f2 = alone.contact_force(), world.contact_force()
    force = np.abs(f2 - f1).max() / np.abs(f1).max()
    s1, s2 = contact_samples(alone), contact_samples(world)
    o1, o2 = np.lexsort(s1.X.T), np.lexsort(s2.X.T)
    np.testing.assert_allclose(s2.X[o2], s1.X[o1], rtol=0, atol=1e-14)
    multiplier = np.abs(s2.lambda_N[o2] - s1.lambda_N[o1]).max() / s1.lambda_N.max()
    r1, r2 = alone.reaction("block_bottom"), world.reaction("block_bottom")
    reaction = np.abs(r2 - r1).max() / np.abs(r1).max()
    source = "the same scene solved on one rank"
    for quantity, value in (
        ("largest contact force difference, relative", force),
        ("largest multiplier difference, over the largest", multiplier),
        ("largest block support reaction difference, relative", reaction),
    ):
        verification(case, quantity, value, 0.0, f"< {ROUND_OFF:g}", source, "consistency")
    assert force < ROUND_OFF
    assert multiplier < ROUND_OFF
    assert reaction < ROUND_OFF
    assert [s.newton_iterations for s in world.history.steps] == [
        s.newton_iterations for s in alone.history.steps
    ]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("mu", [0.0, 0.05])
def test_taylor_across_meshes(dim, mu, verification):
    """The tangent chained through a master on another mesh: Taylor slope 2 (frictionless
    and in slip), as on one mesh."""
    problem, dz, steps = curved_case(dim, mu=mu, own_meshes=True)
    assert len(problem.bulks) == 2 and problem.active_points() > 10
    result = assert_taylor_slopes(problem, dz, steps, tol=SLOPE_TOL)
    case = f"Taylor test {dim}D on two meshes, curved surfaces, mu = {mu:g}"
    record_slopes(verification, case, result, tol=SLOPE_TOL)


def test_integer_tag_needs_its_domain():
    scene = scenes.on_meshes_of_their_own(scenes.patch())
    pair = dataclasses.replace(scene.contacts[0], slave_domain=None)
    with pytest.raises(cu.ContactInputError, match="needs its domain"):
        dataclasses.replace(scene, contacts=[pair])


def test_equilibrium_across_meshes(patch_pair, verification):
    """Supports (on both meshes) and the load balance; the contact forces are internal. This
    holds for any converged solve (consistency), to the solver's tolerance: an absolute
    residual of 1e-13 against a load of 0.01 allows 1e-11, whatever round-off gives (5e-15
    measured)."""
    _, two = patch_pair
    error = equilibrium_error(two, ["upper_left", "lower_left", "lower_bottom"])
    quantity = "|reactions + load resultant| / |load resultant|"
    source = "the equilibrium of a converged solve"
    verification(PATCH, quantity, error, 0.0, "< 1e-10", source, kind="consistency")
    assert error < 1e-10


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
