"""Bad input gets a clear error naming the problem, on every rank (no MPI hang)."""

import dataclasses
import time
import warnings

import dolfinx
import numpy as np
import pytest
from conftest import symmetric_square
from mpi4py import MPI

from contact_ufl import mpi
from contact_ufl.contact import ContactPair
from contact_ufl.errors import ContactInputError, NonUniqueSolutionWarning
from contact_ufl.loads import DeadTraction, Dirichlet
from contact_ufl.materials import NearlyIncompressibleWarning, NeoHookean
from contact_ufl.mpi import CollectiveCallError
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Body, Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.geometries import tag_single_body
from contact_ufl.verification.scenes import E_STEEL, curved_pair


@pytest.fixture(scope="module")
def scene():
    return curved_pair(2)


def with_pair(scene, **changes):
    pair = dataclasses.replace(scene.contacts[0], **changes)
    return dataclasses.replace(scene, contacts=[pair])


@pytest.mark.parametrize(
    "changes, message",
    [
        (dict(slave=99), "facet tag 99 is empty or does not exist"),
        (dict(master=98), "facet tag 98 is empty or does not exist"),
        (dict(eps_N=0.0), "eps_N must be positive"),
        (dict(eps_N=-1.0), "eps_N must be positive"),
        (dict(mu=-0.1), "mu must be >= 0"),
        (dict(search_radius=-1.0), "search_radius must be positive"),
        (dict(quadrature_subdivisions=0), "quadrature_subdivisions must be >= 1"),
        (dict(quadrature_rule="simpson"), "quadrature_rule must be one of"),
    ],
)
def test_bad_contact_pair(scene, changes, message):
    with pytest.raises(ContactInputError, match=message):
        ContactProblem(with_pair(scene, **changes), verbose=False)


def test_slave_not_facing_master(scene):
    """The flat top of the half disc faces away from the block."""
    pair = scene.contacts[0]
    swapped = with_pair(scene, slave=pair.master, master=pair.slave)
    with warnings.catch_warnings():  # the pair has no supports (a scene for Taylor tests)
        warnings.simplefilter("ignore", NonUniqueSolutionWarning)
        ContactProblem(swapped, verbose=False)  # swapped roles face each other: fine
    with pytest.raises(ContactInputError, match="never faces") as error:
        ContactProblem(with_pair(scene, slave="cylinder_top"), verbose=False)
    # the message names the surfaces by their physical groups
    assert "slave surface 'cylinder_top' (tag" in str(error.value), error.value


def test_empty_body_tag(scene):
    bad = dataclasses.replace(
        scene, bodies=[Body(42, NeoHookean(1.0, 0.3), "ghost"), *scene.bodies]
    )
    with pytest.raises(ContactInputError, match="cell tag 42 has no cells"):
        ContactProblem(bad, verbose=False)


def test_dirichlet_on_missing_tag(scene):
    bad = dataclasses.replace(scene, dirichlet=[Dirichlet(77, (0.0, 0.0))])
    with pytest.raises(ContactInputError, match="facet tag 77 does not exist"):
        ContactProblem(bad, verbose=False)


@pytest.mark.parametrize("E, nu, message", [(-1.0, 0.3, "Young"), (1.0, 0.5, "Poisson")])
def test_bad_material(E, nu, message):
    with pytest.raises(ValueError, match=message):
        NeoHookean(E, nu)


def test_a_nearly_incompressible_solid_warns_of_locking():
    with pytest.warns(NearlyIncompressibleWarning, match="nu = 0.499 is nearly incompressible"):
        NeoHookean(1.0, 0.499)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        NeoHookean(1.0, 0.45)


def test_higher_order_displacement_is_rejected(scene):
    """Degree 3 is not supported (degree 2 is: tests/test_quadratic.py)."""
    with pytest.raises(ContactInputError, match="degree-3 displacement.*degree-2 displacement"):
        ContactProblem(scene, degree=3, verbose=False)


@pytest.mark.parametrize(
    "dirichlet, message",
    [
        (
            Dirichlet("cylinder_top", (0.0, 0.0, 0.0)),
            r"'cylinder_top' \(tag \d+\): the value must be a scalar or 2 components in 2D, "
            r"got shape \(3,\)",
        ),
        (Dirichlet("cylinder_top", (0.0, 0.0), component=1), "must be a scalar in 2D"),
        (Dirichlet("cylinder_top", 0.0, component=2), r"component must be one of \[0, 1\]"),
        (Dirichlet("cylinder_top", lambda t: (float("nan"), 0.0)), "is not finite"),
    ],
)
def test_dirichlet_value_is_checked_against_the_dimension(scene, dirichlet, message):
    """A prescribed displacement of the wrong shape for the mesh, or not finite, is refused
    when the problem is made, naming its physical group."""
    with pytest.raises(ContactInputError, match=message):
        ContactProblem(dataclasses.replace(scene, dirichlet=[dirichlet]), verbose=False)


def test_a_2d_dirichlet_value_in_3d_is_refused():
    mesh = dolfinx.mesh.create_unit_cube(MPI.COMM_WORLD, 2, 2, 2)
    cells, facets = tag_single_body(mesh, [lambda x: np.isclose(x[2], 0.0)])
    scene = Scene(mesh, cells, facets, [Body(1, NeoHookean(1.0, 0.3))])
    bad = dataclasses.replace(scene, dirichlet=[Dirichlet(1, (0.0, 0.0))])
    with pytest.raises(ContactInputError, match=r"scalar or 3 components in 3D, got shape \(2,\)"):
        ContactProblem(bad, verbose=False)


def test_a_solve_that_does_not_advance_is_refused():
    """solve(t_end=...) at or before the current pseudo-time, or with no steps, is refused
    with a message saying how to unload; the problem stays usable."""
    pulled = Dirichlet(4, lambda t: 0.01 * t, component=1)
    problem = ContactProblem(symmetric_square(NeoHookean(1.0, 0.3), [], dirichlet=[pulled]))
    problem.solve(num_steps=1, t_end=0.5)
    for t_end in (0.5, 0.25):
        with pytest.raises(ContactInputError, match="does not advance the pseudo-time beyond"):
            problem.solve(num_steps=1, t_end=t_end)
    with pytest.raises(ContactInputError, match="num_steps must be a whole number >= 1"):
        problem.solve(num_steps=0, t_end=1.0)
    problem.solve(num_steps=1, t_end=1.0)
    assert problem.t == pytest.approx(1.0)


def disc_on_block(supports, contacts=True):
    """The Hertz half disc pushed down by a force onto a block, held by ``supports`` (the
    block's bottom always)."""
    mesh = geometries.hertz_2d(h_contact=0.05, h_far=0.2, gap=0.0, axis=True)
    steel = NeoHookean(E_STEEL, 0.3)
    return Scene.from_mesh_data(
        mesh,
        bodies=[Body("cylinder", steel), Body("block", steel)],
        contacts=[ContactPair("cylinder_contact", "block_contact")] if contacts else [],
        dirichlet=[Dirichlet("block_bottom", (0.0, 0.0)), *supports],
        loads=[DeadTraction("cylinder_top", lambda t: (0.0, -1e-3 * E_STEEL * t))],
    )


def test_a_body_slid_freely_over_a_flat_master_warns():
    """A disc pushed onto a flat block with no support along x and no friction can slide
    along x at no cost: the problem warns when it is made, naming the body, the motion, the
    surface and the support that would hold it; the disc's axis held along x silences it."""
    with pytest.warns(NonUniqueSolutionWarning) as caught:
        ContactProblem(disc_on_block([]), verbose=False)
    (message,) = [str(w.message) for w in caught]
    for words in ("'cylinder'", "translation along x", "'cylinder_contact'", "component=0"):
        assert words in message, message
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ContactProblem(disc_on_block([Dirichlet("cylinder_axis", 0.0, component=0)]))


def test_friction_holds_the_slide():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = disc_on_block([])
        pair = dataclasses.replace(scene.contacts[0], mu=0.3)
        ContactProblem(dataclasses.replace(scene, contacts=[pair]), verbose=False)


def test_a_body_held_by_nothing_warns():
    """With no contact pair, nothing holds the pushed disc: a warning naming its motions."""
    with pytest.warns(NonUniqueSolutionWarning, match=r"'cylinder' is held by no support and"):
        ContactProblem(disc_on_block([], contacts=False), verbose=False)


two_ranks = pytest.mark.skipif(MPI.COMM_WORLD.size < 2, reason="needs several ranks")


@two_ranks
def test_a_collective_call_on_one_rank_raises_instead_of_hanging(monkeypatch):
    """problem.load_resultant() inside `if rank == 0:` raises on rank 0, naming the call,
    after the collective timeout (here 1 s) instead of waiting forever."""
    problem = ContactProblem(symmetric_square(NeoHookean(1.0, 0.3), []), verbose=False)
    comm = problem.comm
    if comm.rank == 0:
        with pytest.raises(CollectiveCallError, match="ContactProblem.load_resultant is coll"):
            monkeypatch.setattr(mpi, "COLLECTIVE_TIMEOUT", 1.0)
            problem.load_resultant()
    else:
        time.sleep(2.0)
        comm.Ibarrier().Wait()  # meets rank 0's barrier given up on: the ranks are in step
    comm.barrier()
    assert np.all(np.isfinite(problem.load_resultant()))  # every rank: fine


@two_ranks
def test_different_collective_calls_at_once_raise_on_every_rank():
    problem = ContactProblem(symmetric_square(NeoHookean(1.0, 0.3), []), verbose=False)
    call = problem.load_resultant if problem.comm.rank == 0 else problem.stored_energy
    with pytest.raises(CollectiveCallError, match="different collective calls"):
        call()
