"""Adaptive refinement (:mod:`contact_ufl.adapt`): tags carried over as DOLFINx carries
them, Doerfler's marking, curved boundaries kept, the loop's rate against theory and uniform
refinement, the same meshes on any number of ranks, history replayed, bad input refused."""

from __future__ import annotations

import dolfinx
import numpy as np
import pytest
import ufl
from conftest import CENTRE, across_ranks, onto_circle
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl import adapt, refinement
from contact_ufl.errors import ContactInputError
from contact_ufl.verification import scenes


def _hertz(comm=MPI.COMM_WORLD, mu: float = 0.0):
    return scenes.hertz_2d(h_contact=0.04, h_far=0.2, depth=0.02, mu=mu, comm=comm).scene


def _every_other_cell(scene) -> list[np.ndarray]:
    mesh = scene.parts[0].mesh
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    return [np.arange(0, owned, 2, dtype=np.int32)]


def _group_measures(domain) -> dict[int, float]:
    """The length (area) of every facet group and the area (volume) of every body."""
    mesh = domain.mesh
    one = dolfinx.fem.Constant(mesh, 1.0)
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=domain.facet_tags)
    dx = ufl.Measure("dx", domain=mesh, subdomain_data=domain.cell_tags)
    out = {}
    for measure, tags in ((ds, domain.facet_tags), (dx, domain.cell_tags)):
        for tag in sorted(set(mesh.comm.allreduce(set(tags.values.tolist()), MPI.BOR))):
            value = dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * measure(tag)))
            out[(tags.dim, tag)] = mesh.comm.allreduce(value, MPI.SUM)
    return out


@pytest.mark.serial
def test_tags_are_carried_over_as_dolfinx_carries_them():
    """On one rank (no ghosts, where :func:`dolfinx.mesh.transfer_meshtag` works) the cell
    and facet tags of a refined scene are those DOLFINx's own transfer gives."""
    scene = _hertz()
    cells = _every_other_cell(scene)
    domain = scene.parts[0]
    fine = refinement.refine_scene(scene, cells).parts[0]
    tdim = domain.mesh.topology.dim
    edges = dolfinx.mesh.compute_incident_entities(domain.mesh.topology, cells[0], tdim, 1)
    option = dolfinx.mesh.RefinementOption.parent_cell_and_facet
    mesh, parent_cell, parent_facet = dolfinx.mesh.refine(domain.mesh, edges, option=option)
    mesh.topology.create_connectivity(tdim - 1, tdim)
    theirs = (
        dolfinx.mesh.transfer_meshtag(domain.cell_tags, mesh, parent_cell),
        dolfinx.mesh.transfer_meshtag(domain.facet_tags, mesh, parent_cell, parent_facet),
    )
    for ours, reference in zip((fine.cell_tags, fine.facet_tags), theirs, strict=True):
        assert np.array_equal(ours.indices, reference.indices)
        assert np.array_equal(ours.values, reference.values)


def test_tags_are_carried_over_on_any_number_of_ranks():
    """Every body keeps its area and every facet group its length (ghosted meshes, which
    DOLFINx's transfer refuses), and the arc's nodes are put back on the circle."""
    scene = _hertz()
    before = _group_measures(scene.parts[0])
    fine = refinement.refine_scene(scene, _every_other_cell(scene)).parts[0]
    after = _group_measures(fine)
    assert before.keys() == after.keys()
    for key, value in before.items():
        assert after[key] == pytest.approx(value, rel=1e-12), key
    snapped = refinement.refine_scene(
        scene, _every_other_cell(scene), {"cylinder_contact": onto_circle}
    ).parts[0]
    arc = snapped.facet_tags.find(snapped.tags["cylinder_contact"])
    nodes = dolfinx.mesh.entities_to_geometry(snapped.mesh, 1, arc).ravel()
    radius = np.linalg.norm(snapped.mesh.geometry.x[nodes] - CENTRE, axis=1)
    assert len(nodes) == 0 or np.abs(radius - 1.0).max() < 1e-14
    chords = dolfinx.mesh.entities_to_geometry(fine.mesh, 1, arc).ravel()
    inside = np.linalg.norm(fine.mesh.geometry.x[chords] - CENTRE, axis=1)
    assert MPI.COMM_WORLD.allreduce(float(np.min(inside, initial=1.0)), MPI.MIN) < 1.0 - 1e-5


def test_each_body_takes_its_own_displacement_onto_the_refined_mesh():
    """The disc and the block of the Hertz mesh touch at the origin. A field that is (0, 1)
    on the disc and (0, -1) on the block, moved onto a refined mesh body by body, is
    exactly that again on every node of each body (moved over the whole mesh, the disc's
    nodes at the block may take the block's value)."""
    scene = _hertz()
    domain = scene.parts[0]
    V = dolfinx.fem.functionspace(domain.mesh, ("Lagrange", 1, (2,)))
    old = dolfinx.fem.Function(V)
    values = {domain.tags["cylinder"]: 1.0, domain.tags["block"]: -1.0}
    for tag, value in values.items():
        old.interpolate(
            lambda x, v=value: np.vstack([np.zeros(x.shape[1]), np.full(x.shape[1], v)]),
            cells0=domain.cell_tags.find(tag),
        )
    fine = refinement.refine_scene(scene, _every_other_cell(scene)).parts[0]
    new = dolfinx.fem.Function(dolfinx.fem.functionspace(fine.mesh, ("Lagrange", 1, (2,))))
    refinement.interpolate_by_body(new, fine, old, domain, padding=1e-8)
    for tag, value in values.items():
        cells = fine.cell_tags.find(tag)
        dofs = np.unique(new.function_space.dofmap.list[cells])
        taken = new.x.array.reshape(-1, 2)[dofs]
        assert np.abs(taken - [0.0, value]).max() < 1e-12, tag


def test_doerfler_marks_the_fewest_cells_that_carry_theta():
    """The marked cells carry at least theta of the sum of the indicators, and without the
    smallest of them less than theta (the definition), over all ranks."""
    comm = MPI.COMM_WORLD
    mesh = dolfinx.mesh.create_unit_square(comm, 12, 12)
    eta = dolfinx.fem.Function(dolfinx.fem.functionspace(mesh, ("DG", 0)))
    eta.interpolate(lambda x: np.exp(-20.0 * ((x[0] - 0.3) ** 2 + x[1] ** 2)) + 1e-3 * x[0])
    values = adapt._cell_values(eta)
    total = comm.allreduce(values.sum(), MPI.SUM)
    for theta in (0.3, 0.5, 0.8):
        (marked,) = adapt.doerfler_marking([eta], theta, comm)
        carried = comm.allreduce(values[marked].sum(), MPI.SUM)
        smallest = comm.allreduce(values[marked].min(initial=np.inf), MPI.MIN)
        assert carried >= theta * total
        assert carried - smallest < theta * total


@pytest.fixture(scope="module")
def adaptive_hertz():
    """The 2D Hertz scene from h_contact = 0.04 to a relative estimate of 0.1."""
    return adapt.refine_to_tolerance(
        _hertz(),
        lambda p: p.solve(num_steps=2),
        tolerance=0.1,
        max_unknowns=100_000,
        boundaries={"cylinder_contact": onto_circle},
        problem_options={"verbose": False},
    )


@pytest.mark.serial
def test_the_loop_reaches_its_tolerance_at_the_optimal_rate(adaptive_hertz, verification):
    """The estimate falls with every level, as N^-1/2 in the unknowns (the optimal rate of
    P1 in 2D, which Doerfler marking attains: Cascon, Kreuzer, Nochetto and Siebert, SIAM J.
    Numer. Anal. 46 (2008)); later meshes start from the moved solution and converge in a
    few Newton iterations; the finest cells are at the contact."""
    result = adaptive_hertz
    levels = result.levels
    assert result.reached and result.stopped_by == "tolerance"
    assert levels[-1].relative <= 0.1 < levels[-2].relative
    estimates = [lv.estimate for lv in levels]
    assert all(b < a for a, b in zip(estimates, estimates[1:], strict=False))
    n = np.array([lv.unknowns for lv in levels], dtype=float)
    rate = np.polyfit(np.log(n), np.log(estimates), 1)[0]
    verification(
        "Hertz 2D adaptive, from h_contact = 0.04",
        "rate of the estimate in the unknowns",
        rate,
        -0.5,
        "<= -0.45",
        "optimal rate of P1 in 2D (Cascon et al. 2008)",
    )
    assert rate <= -0.45  # measured -0.54
    assert [lv.start for lv in levels[1:]] == ["moved state"] * (len(levels) - 1)
    assert max(lv.newton_iterations for lv in levels[1:]) <= 4  # measured 2 to 3
    mesh = result.problem.bulks[0].V.mesh
    h = mesh.h(2, np.arange(mesh.topology.index_map(2).size_local, dtype=np.int32))
    finest = dolfinx.mesh.compute_midpoints(mesh, 2, np.argsort(h)[:20].astype(np.int32))
    assert np.abs(finest[:, :2]).max() < 0.2  # the contact half-width is 0.15


@pytest.mark.serial
def test_adaptive_meshes_beat_uniform_refinement(adaptive_hertz):
    """The adaptive meshes reach the estimate of one uniform refinement of the (graded)
    starting mesh with a third fewer unknowns (log-log interpolation between levels)."""
    scene = _hertz()
    mesh = scene.parts[0].mesh
    every = [np.arange(mesh.topology.index_map(2).size_local, dtype=np.int32)]
    uniform = cu.ContactProblem(
        refinement.refine_scene(scene, every, {"cylinder_contact": onto_circle}), verbose=False
    )
    uniform.solve(num_steps=2)
    reference = uniform.error_estimate()
    n = uniform.layout.global_size
    levels = adaptive_hertz.levels
    log_n = np.log([lv.unknowns for lv in levels])
    log_eta = np.log([lv.estimate for lv in levels])
    # the estimate falls with the levels: interpolate log N in log eta, increasing
    needed = np.exp(np.interp(np.log(reference.estimate), log_eta[::-1], log_n[::-1]))
    assert needed < 0.8 * n  # measured 0.67


@across_ranks
def test_the_loop_makes_the_same_meshes_on_any_number_of_ranks(verification):
    """Two meshes on two ranks: the same unknowns, cells and estimates as on one rank."""

    def run(comm):
        return adapt.refine_to_tolerance(
            _hertz(comm),
            lambda p: p.solve(num_steps=2),
            tolerance=1e-6,
            max_unknowns=100_000,
            max_levels=2,
            boundaries={"cylinder_contact": onto_circle},
            problem_options={"verbose": False},
        ).levels

    world, alone = run(MPI.COMM_WORLD), run(MPI.COMM_SELF)
    assert [lv.unknowns for lv in world] == [lv.unknowns for lv in alone]
    assert [lv.cells for lv in world] == [lv.cells for lv in alone]
    difference = max(abs(a.estimate / b.estimate - 1.0) for a, b in zip(world, alone, strict=True))
    verification(
        "Hertz 2D adaptive, from h_contact = 0.04, two levels",
        "relative difference of the estimates",
        difference,
        0.0,
        "< 1e-8",
        "the same loop on one rank",
        kind="consistency",
    )
    assert difference < 1e-8


@pytest.mark.serial
def test_a_scene_with_friction_replays_its_load_path():
    """With friction the state depends on the path: every mesh is solved along it."""
    result = adapt.refine_to_tolerance(
        _hertz(mu=0.3),
        lambda p: p.solve(num_steps=1),
        tolerance=1e-6,
        max_unknowns=100_000,
        max_levels=2,
        problem_options={"verbose": False},
    )
    assert result.stopped_by == "levels"
    assert [lv.start for lv in result.levels] == ["load path", "load path"]
    assert len(result.problem.history.steps) == 1
    assert result.levels[1].estimate < result.levels[0].estimate


@pytest.mark.serial
def test_an_elastoplastic_scene_replays_its_load_path():
    """A disc pressed into a perfectly plastic block and lifted off: every mesh replays the
    press and the lift, and the estimate of the imprint falls (measured 0.62, 0.48)."""
    scene = scenes.plastic_indentation(h_contact=0.04)

    def solve(problem):
        problem.solve(num_steps=4, t_end=1.0)
        problem.solve(num_steps=4, t_end=2.0)

    result = adapt.refine_to_tolerance(
        scene,
        solve,
        tolerance=1e-6,
        max_unknowns=100_000,
        max_levels=2,
        boundaries={"cylinder_contact": onto_circle},
        problem_options={"verbose": False},
    )
    assert [lv.start for lv in result.levels] == ["load path", "load path"]
    assert len(result.problem.history.steps) == 8
    assert result.levels[1].relative < 0.9 * result.levels[0].relative
    (history,) = result.problem.bulks[0].histories.values()
    assert history.update_plastic_strain().x.array.max() > 0.0  # it yielded


@pytest.mark.serial  # global numbers, the same on every rank (the next tests run on 2 ranks)
@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"tolerance": 0.0}, "tolerance must be a number > 0"),
        ({"tolerance": float("nan")}, "tolerance must be a number > 0"),
        ({"max_unknowns": 100}, "the starting meshes have"),
        ({"max_unknowns": 1.5e5}, "max_unknowns must be a whole number"),
        ({"theta": 0.0}, "theta"),
        ({"theta": 1.5}, "theta"),
        ({"max_levels": 0}, "max_levels"),
    ],
)
def test_bad_input_of_the_loop_is_refused_before_any_solve(options, message):
    calls = []
    arguments = {"tolerance": 0.1, "max_unknowns": 10_000} | options
    with pytest.raises(ContactInputError, match=message):
        adapt.refine_to_tolerance(_hertz(), calls.append, **arguments)
    assert calls == []


def test_quadrilaterals_are_refused_before_any_solve():
    calls = []
    scene = scenes.patch(cell="quadrilateral")
    with pytest.raises(ContactInputError, match="quadrilateral cells"):
        adapt.refine_to_tolerance(scene, calls.append, tolerance=0.1, max_unknowns=10_000)
    assert calls == []


def test_an_unknown_boundary_is_refused_before_any_solve():
    calls = []
    with pytest.raises(ContactInputError, match="'arc' is not a facet group"):
        adapt.refine_to_tolerance(
            _hertz(), calls.append, 0.1, 10_000, boundaries={"arc": onto_circle}
        )
    assert calls == []


@pytest.mark.serial
def test_tetrahedra_are_refined_where_the_estimate_says():
    """3D Hertz (quarter sphere on a block): the estimate falls with the level, the new
    mesh starts from the moved solution, and the sphere's nodes stay on the sphere."""
    centre = np.array([0.0, 0.0, 1.0])

    def onto_sphere(x):
        d = x - centre
        return centre + d / np.linalg.norm(d, axis=1)[:, None]

    scene = scenes.hertz_3d(h_contact=0.06, h_far=0.3, depth=0.01).scene
    result = adapt.refine_to_tolerance(
        scene,
        lambda p: p.solve(num_steps=2),
        tolerance=1e-6,
        max_unknowns=100_000,
        max_levels=2,
        boundaries={"sphere_contact": onto_sphere},
        problem_options={"verbose": False},
    )
    first, second = result.levels
    assert second.estimate < 0.8 * first.estimate  # measured 0.61
    assert second.start == "moved state" and second.newton_iterations <= 6  # measured 4
    domain = result.problem.scene.parts[0]
    surface = domain.facet_tags.find(domain.tags["sphere_contact"])
    nodes = dolfinx.mesh.entities_to_geometry(domain.mesh, 2, surface).ravel()
    radius = np.linalg.norm(domain.mesh.geometry.x[nodes] - centre, axis=1)
    assert np.abs(radius - 1.0).max() < 1e-14
