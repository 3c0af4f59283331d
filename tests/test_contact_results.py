"""The contact samples' flags and arc lengths, the contact surfaces' .pvd time series and the
pictures of contact_ufl.output, on small 2D scenes."""

import numpy as np
import pytest
from conftest import across_ranks, solve_hertz
from mpi4py import MPI

from contact_ufl import output
from contact_ufl.problem import ContactProblem
from contact_ufl.results import (
    ContactSamples,
    _walk_curves,
    contact_samples,
    nodal_pressure,
    recovered_pressure,
)
from contact_ufl.verification import scenes
from contact_ufl.verification.analytic import CattaneoMindlin2D, Hertz2D

HERTZ = "Johnson, Contact Mechanics (1985), 4.2: closed form at the computed force"
CATTANEO = "Johnson, Contact Mechanics (1985), 7.1: closed form at the computed forces"
CIRCLE = (
    "R * angle, the arc length of a circle; an inscribed polygon of sides h is shorter by at"
    " most L h^2 / (24 R^2) over a length L"
)
POLYGON = "perimeter of the regular polygon, 2 N R sin(pi / N)"


@pytest.fixture(scope="module")
def hertz():
    """Hertz at a/h ~ 5 (4 load steps)."""
    return solve_hertz(0.01)


def nodal_profile(f, comm=MPI.COMM_WORLD) -> tuple[np.ndarray, np.ndarray]:
    """The reference x of the owned nodes of a P1 function on the slave surface and its
    values there, of all ranks, sorted along x."""
    space = f.function_space
    n = space.dofmap.index_map.size_local
    x = np.concatenate(comm.allgather(space.tabulate_dof_coordinates()[:n, 0]))
    values = np.concatenate(comm.allgather(f.x.array[:n]))
    order = np.argsort(x)
    return x[order], values[order]


def pressure_errors(problem, scene, fields) -> tuple[dict, dict]:
    """For each nodal pressure field (name: P1 function on the slave surface) its rms
    node-to-node oscillation (the second difference of the nodes' error against Hertz, over
    |x| < 0.8 a) and its L2 error over |x| < 1.5 a, both over p0 (L2 over p0 a^1/2)."""
    exact = Hertz2D(problem.contact_force()[1], scene.radius, scene.E_star)
    oscillation, l2 = {}, {}
    for name, f in fields.items():
        x, p = nodal_profile(f)
        error = p - exact.p0 * np.sqrt(np.clip(1.0 - (x / exact.a) ** 2, 0.0, None))
        core = error[np.abs(x) < 0.8 * exact.a]
        second = core[1:-1] - 0.5 * (core[:-2] + core[2:])
        oscillation[name] = float(np.sqrt(np.mean(second**2)) / exact.p0)
        near = np.abs(x) < 1.5 * exact.a
        l2[name] = float(np.sqrt(np.trapezoid(error[near] ** 2, x[near]) / (exact.p0**2 * exact.a)))
    return oscillation, l2


@pytest.mark.serial
def test_the_recovered_pressure_is_smooth_where_the_multipliers_zig_zag(hertz, verification):
    """On the non-matching meshes of Hertz (a/h = 5) the nodal multipliers oscillate about
    the closed form from node to node; the pressure recovered from the bulk's traction does
    not, and is closer to it; the nodal forces over the nodal areas lie between. Oscillation:
    the rms of the second difference of the nodes' error over |x| < 0.8 a (measured 0.15 p0
    for lambda, 0.011 for the recovered pressure, 0.041 for the nodal one); L2 error over
    |x| < 1.5 a, over p0 a^1/2 (measured 0.23, 0.035 and 0.075)."""
    problem, scene = hertz
    fields = {
        "lambda": problem.contacts[0].lambda_N,
        "recovered": recovered_pressure(problem),
        "nodal": nodal_pressure(problem),
    }
    oscillation, l2 = pressure_errors(problem, scene, fields)
    case = "Hertz 2D, Neo-Hookean, a/h = 5"
    verification(
        case,
        "recovered pressure: rms node-to-node oscillation over p0",
        oscillation["recovered"],
        0.0,
        "< 0.02",
        HERTZ,
    )
    verification(
        case, "recovered pressure: L2 error over p0 a^1/2", l2["recovered"], 0.0, "< 0.07", HERTZ
    )
    verification(
        case,
        "nodal pressure: rms node-to-node oscillation over p0",
        oscillation["nodal"],
        0.0,
        "< 0.06",
        HERTZ,
    )
    assert oscillation["recovered"] < 0.02 < 0.05 < oscillation["lambda"]
    assert l2["recovered"] < 0.07 and l2["recovered"] < l2["lambda"]
    verification(case, "nodal pressure: L2 error over p0 a^1/2", l2["nodal"], 0.0, "< 0.15", HERTZ)
    assert oscillation["nodal"] < 0.06 and l2["nodal"] < 0.15


@pytest.mark.serial
def test_the_nodal_pressure_is_the_smooth_reading_with_p2(verification):
    """With P2 displacements (curved mesh, a/h = 2.5) the bulk's traction follows the
    multipliers' zig-zag: the recovered pressure oscillates more than they do (measured
    0.085 p0 against 0.060), the nodal forces over the nodal areas less (0.029)."""
    scene = scenes.hertz_2d(h_contact=0.02, depth=0.005, order=2)
    problem = ContactProblem(scene.scene, degree=2, verbose=False)
    problem.solve(num_steps=1)
    fields = {
        "lambda": problem.contacts[0].lambda_N,
        "recovered": recovered_pressure(problem),
        "nodal": nodal_pressure(problem),
    }
    oscillation, _ = pressure_errors(problem, scene, fields)
    verification(
        "Hertz 2D, Neo-Hookean, P2, a/h = 2.5",
        "nodal pressure: rms node-to-node oscillation over p0",
        oscillation["nodal"],
        0.0,
        "< 0.04",
        HERTZ,
    )
    assert oscillation["nodal"] < 0.04 < oscillation["lambda"] < oscillation["recovered"]


def zone_edges(x: np.ndarray, inside: np.ndarray, outside: np.ndarray) -> tuple[float, float]:
    """The edges of the zone of the samples ``inside``, each half-way between the outermost
    sample inside and the next one ``outside`` (along ``x``)."""
    xi, xo = x[inside], x[outside]
    left, right = xi.min(), xi.max()
    left = 0.5 * (left + xo[xo < left].max())
    right = 0.5 * (right + xo[xo > right].min())
    return left, right


@pytest.mark.serial  # the flags on 2 ranks: test_surface_time_series_is_written_once
def test_in_contact_flag_is_the_hertz_zone(hertz, verification):
    """The in-contact flag marks Hertz's zone |x| < a: its edges (half-way between the
    outermost sample in contact and the next open one) are 0.15 of an element inside +-a
    (measured), and every sample farther than 0.3 of an element from +-a is flagged as the
    closed form says (none is flagged against it: measured). The multiplier alone would not
    do: open samples beyond a + h carry lambda_N > 0."""
    problem, scene = hertz
    s = contact_samples(problem)
    exact = Hertz2D(problem.contact_force()[1], scene.radius, scene.E_star)
    h, x = scene.h_contact, s.x[:, 0]
    left, right = zone_edges(x, s.in_contact, ~s.in_contact)
    edge_error = max(abs(left + exact.a), abs(right - exact.a)) / h
    inside = np.abs(x) < exact.a
    wrong = s.in_contact != inside
    band = np.abs(np.abs(x[wrong]) - exact.a).max(initial=0.0) / h
    case = "Hertz 2D, Neo-Hookean, a/h = 5"
    verification(
        case,
        "contact edges from the in-contact flag, distance from +-a in elements",
        edge_error,
        "a = sqrt(4 P R / (pi E*))",
        "< 0.3",
        HERTZ,
    )
    verification(
        case,
        "largest distance from +-a of a sample flagged against |x| < a, in elements",
        band,
        "in contact where |x| < a",
        "< 0.3",
        HERTZ,
    )
    assert edge_error < 0.3
    assert band < 0.3
    assert np.any((s.lambda_N > 0.0) & (np.abs(x) > exact.a + h))
    assert s.stick is None and s.slip is None  # frictionless


@pytest.fixture(scope="module")
def cattaneo():
    """Hertz (a/h ~ 10, mu = 0.3) in 2 normal steps, then one tangential step to
    Q / (mu P) ~ 0.35: the problem and its Cattaneo-Mindlin solution at the computed
    forces."""
    mu = 0.3
    scene = scenes.hertz_2d(h_contact=0.005, depth=0.005, mu=mu, shift=0.0015, refine_radius=0.12)
    problem = ContactProblem(scene.scene, verbose=False)
    problem.solve(num_steps=2, t_end=1.0)
    problem.solve(num_steps=1, t_end=1.5)
    force = problem.contact_force()
    exact = CattaneoMindlin2D(Hertz2D(force[1], scene.radius, scene.E_star), abs(force[0]), mu)
    return problem, exact, scene.h_contact


@pytest.mark.serial  # the flags on 2 ranks: test_surface_time_series_is_written_once
def test_stick_and_slip_flags_are_the_cattaneo_zones(cattaneo, verification):
    """The stick flag marks Cattaneo's stick zone |x - xc| < c (c = a sqrt(1 - Q / (mu P))),
    the slip flag the slip zones c < |x - xc| < a (xc the centre of the samples in contact):
    every sample farther than 0.3 of an element from +-c and +-a is flagged as the closed
    form says (measured: one sample, 0.155 of an element from c, is flagged against it).
    The half-width of the stick zone is checked in test_cattaneo.py."""
    problem, exact, h = cattaneo
    s = contact_samples(problem)
    assert s.stick is not None
    assert np.all(s.in_contact[s.stick]) and np.all(s.in_contact[s.slip])
    assert not np.any(s.stick & s.slip)
    x = s.x[:, 0]
    xc = 0.5 * (x[s.in_contact].min() + x[s.in_contact].max())
    r = np.abs(x - xc)
    expected_stick = r < exact.c
    expected_slip = (r > exact.c) & (r < exact.hertz.a)
    wrong_stick = s.stick != expected_stick
    wrong_slip = s.slip != expected_slip
    band = max(
        np.abs(r[wrong_stick] - exact.c).max(initial=0.0),
        np.min(np.abs(r[wrong_slip, None] - [exact.c, exact.hertz.a]), axis=1).max(initial=0.0),
    )
    band /= h
    case = f"Cattaneo-Mindlin 2D, a/h ~ 10, Q / (mu P) = {exact.Q / (exact.mu * exact.hertz.P):.2f}"
    verification(
        case,
        "largest distance from +-c, +-a of a sample flagged against the zones, in elements",
        band,
        "stick where |x - xc| < c, slip where c < |x - xc| < a",
        "< 0.3",
        CATTANEO,
    )
    assert band < 0.3


@pytest.mark.serial  # the arc lengths on 2 ranks: test_arc_length_on_any_number_of_ranks
def test_arc_length_of_the_disc_is_r_times_angle(hertz, verification):
    """The reference arc length along the disc's arc (R = 1, from its end of smallest x,
    (-1, 1)) is R times the angle turned from that end, up to the inscribed polygon's
    shortfall: at most pi R h_max^2 / (24 R^2) over the whole arc (h_max = 0.2 far from the
    contact), and between two samples within 0.2 of the contact point (h <= 0.02) at most
    0.4 h^2 / (24 R^2). The measured errors are 0.4 and 0.5 of these bounds. Sorted by arc
    length the samples run along the arc."""
    problem, _ = hertz
    s = contact_samples(problem)
    R, centre = 1.0, np.array([0.0, 1.0])
    c = problem.contacts[0]
    nodes = c.slave.submesh.geometry.dofmaps[0][: c.slave.num_cells, :2]
    ends = c.slave.submesh.geometry.x[nodes, :2]
    local = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    lengths = np.concatenate(problem.comm.allgather(local))
    angle = np.mod(np.arctan2(*(s.X - centre).T[::-1]), 2.0 * np.pi) - np.pi
    assert np.all(s.curve == 0)
    error = np.abs(s.arc_length - R * angle).max()
    bound = np.pi * R * (lengths.max() / R) ** 2 / 24.0
    near = np.abs(s.X[:, 0]) < 0.2
    bottom = np.argmin(np.abs(s.X[:, 0]))
    near_error = np.abs(
        (s.arc_length[near] - s.arc_length[bottom]) - R * (angle[near] - angle[bottom])
    ).max()
    # the largest facet with a sample within 0.2 of the contact point
    near_facets = np.abs(ends[:, :, 0]).min(axis=1) < 0.2
    h_near = max(problem.comm.allgather(local[near_facets].max(initial=0.0)))
    near_bound = 0.4 * R * (h_near / R) ** 2 / 24.0
    case = "Hertz 2D disc's arc, R = 1, h = 0.01 to 0.2"
    verification(
        case,
        "largest |s - R angle| over the arc, over pi R h_max^2 / (24 R^2)",
        error / bound,
        "s = R angle",
        "< 1",
        CIRCLE,
    )
    verification(
        case,
        "largest |s - R angle| within 0.2 of the contact, over 0.4 h^2 / (24 R^2)",
        near_error / near_bound,
        "s = R angle",
        "< 1",
        CIRCLE,
    )
    assert error < bound
    assert near_error < near_bound
    order = s.order("arc length")
    assert np.all(np.diff(angle[order]) > 0.0)
    assert np.array_equal(s.ordered().arc_length, s.arc_length[order])


@pytest.mark.serial  # the arc lengths on 2 ranks: test_arc_length_on_any_number_of_ranks
def test_current_arc_length_follows_the_deformed_facets(hertz, verification):
    """Along the current arc length, two samples of one facet are as far apart as their
    current positions (a degree-1 displacement keeps the facets straight): the facet's
    current length, the integral of da/dA, agrees with the positions x = X + u. Between
    samples of two facets the arc is longer than the chord."""
    problem, _ = hertz
    s = contact_samples(problem)
    nq = problem.contacts[0].slave.num_points
    facet = np.arange(len(s.x)) // nq  # each rank's points come facet by facet
    order = s.order("current arc length")
    ds = np.diff(s.arc_length_current[order])
    chord = np.linalg.norm(np.diff(s.x[order], axis=0), axis=1)
    same = facet[order][1:] == facet[order][:-1]
    mismatch = np.abs(ds[same] - chord[same]).max() / chord[same].max()
    verification(
        "Hertz 2D disc's arc, R = 1, h = 0.01 to 0.2",
        "largest |ds - |dx|| within a facet, over the largest |dx|",
        mismatch,
        0.0,
        "< 1e-14",
        "the current positions x = X + u of the samples",
        kind="consistency",
    )
    assert mismatch < 1e-14
    assert np.all(ds[~same] >= chord[~same] * (1.0 - 1e-12))
    assert np.abs(s.arc_length_current - s.arc_length).max() > 1e-4  # deformed


def test_walk_of_closed_open_and_branched_curves(verification):
    """The chaining of facets into curves, on shuffled and randomly oriented segments: a
    regular 16-gon inscribed in the unit circle (closed: from its vertex of smallest x,
    counter-clockwise, the samples at the sides' midpoints at (k + 1/2) 2 sin(pi / 16)),
    an open polyline starting at its end of smallest x, and a T (a branch: no arc length).
    Current lengths twice the reference ones give twice the arc lengths."""
    rng = np.random.default_rng(1)
    N = 16
    angles = np.pi + 2.0 * np.pi * np.arange(N + 1) / N  # from (-1, 0) counter-clockwise
    ring = np.column_stack([np.cos(angles), np.sin(angles)])
    ring_keys = np.arange(N + 1) % N
    line = np.array([[6.0, 0.0], [5.0, 1.0], [4.0, 0.0], [3.0, 0.5]])  # starts at x = 3
    tee = np.array([[10.0, 0.0], [11.0, 0.0], [12.0, 0.0], [11.0, 1.0]])
    segments = [(ring_keys[k], ring_keys[k + 1], ring[k], ring[k + 1]) for k in range(N)]
    segments += [(100 + k, 101 + k, line[k], line[k + 1]) for k in range(3)]
    segments += [(200 + a, 200 + b, tee[a], tee[b]) for a, b in ((0, 1), (1, 2), (1, 3))]
    order = rng.permutation(len(segments))
    flip = rng.random(len(segments)) < 0.5
    keys, ends = [], []
    for k in order:
        a, b, pa, pb = segments[k]
        keys.append((b, a) if flip[k] else (a, b))
        ends.append((pb, pa) if flip[k] else (pa, pb))
    keys, ends = np.array(keys), np.array(ends)
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    place = np.full((len(keys), 1), 0.5)
    s_ref, s_cur, curve = _walk_curves(keys, ends, length, 2.0 * length, place)
    ring_side = 2.0 * np.sin(np.pi / N)
    on_ring = order < N
    expected = (order[on_ring] + 0.5) * ring_side
    error = np.abs(s_ref[on_ring] - expected).max()
    verification(
        "regular 16-gon in the unit circle, shuffled segments",
        "largest |s - (k + 1/2) 2 sin(pi / 16)| at the sides' midpoints",
        error,
        0.0,
        "< 2e-15",
        POLYGON,
    )
    assert error < 2e-15
    assert np.all(curve[on_ring] == 0)
    on_line = (order >= N) & (order < N + 3)
    line_sides = np.linalg.norm(np.diff(line[::-1], axis=0), axis=1)  # from x = 3
    line_order = 2 - (order[on_line] - N)  # side index from the end x = 3
    starts = np.concatenate([[0.0], np.cumsum(line_sides)])
    assert np.allclose(s_ref[on_line], starts[line_order] + 0.5 * line_sides[line_order])
    assert np.all(curve[on_line] == 1)
    on_tee = order >= N + 3
    assert np.all(curve[on_tee] == -1) and np.all(np.isnan(s_ref[on_tee]))
    assert np.array_equal(s_cur[~on_tee], 2.0 * s_ref[~on_tee])  # doubling is exact


def test_samples_refuse_an_unknown_abscissa():
    """A profile along the arc length needs a 2D slave surface, and ``along`` is a name."""
    samples = ContactSamples(np.zeros((2, 3)), np.zeros(2), np.zeros(2), np.zeros(2))
    with pytest.raises(ValueError, match="needs a 2D slave surface"):
        samples.abscissa("arc length")
    with pytest.raises(ValueError, match="along must be one of"):
        samples.abscissa("y")
    assert samples.slip is None


@across_ranks
def test_arc_length_on_any_number_of_ranks():
    """The arc lengths of the slave points are those of one rank (each rank solves the
    problem alone): the reference ones exactly (the chaining of the facets does not depend
    on the partition), the current ones to the solver's tolerance."""
    world, _ = solve_hertz(0.02, steps=1)
    alone, _ = solve_hertz(0.02, comm=MPI.COMM_SELF, steps=1)
    sw, sa = contact_samples(world), contact_samples(alone)
    ow, oa = np.lexsort(sw.X.T), np.lexsort(sa.X.T)
    assert np.array_equal(sw.X[ow], sa.X[oa])
    assert np.array_equal(sw.curve[ow], sa.curve[oa])
    assert np.array_equal(sw.arc_length[ow], sa.arc_length[oa])  # the same operations
    # the displacements agree to the solver's tolerance, as the positions in
    # test_properties.py (4e-16 measured; MUMPS's round-off on 2 ranks varies between runs)
    current = np.abs(sw.arc_length_current[ow] - sa.arc_length_current[oa]).max()
    assert current < 1e-10


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """Hertz (a/h ~ 2.5) in 2 load steps, written by a ResultWriter (with the error
    indicators) at t = 0 (before any contact search) and after each step: the problem and
    the folder."""
    folder = tmp_path_factory.mktemp("written") if MPI.COMM_WORLD.rank == 0 else None
    folder = MPI.COMM_WORLD.bcast(folder)
    scene = scenes.hertz_2d(h_contact=0.02, depth=0.005)
    problem = ContactProblem(scene.scene, verbose=False)
    writer = output.ResultWriter(problem, folder, error_indicators=True)
    writer.write(0.0)
    problem.solve(num_steps=2, callback=writer)
    writer.close()
    return problem, folder


def test_surface_time_series_is_written_once(written, verification):
    """The .pvd series of the contact surface opens in pyvista with one step per write (the
    initial state, with no point paired, and each load step); each step holds every slave
    point of all ranks once (gathered, written by rank 0: no file per rank) with the
    samples' fields; its number of points in contact is the step's record of the solve, and
    the last step's fields are the samples of the converged state."""
    import pyvista

    problem, folder = written
    s = contact_samples(problem)
    if MPI.COMM_WORLD.rank != 0:
        return
    path = folder / "contact_surface_0.pvd"
    steps = problem.history.steps
    files = sorted(p.name for p in (folder / "contact_surface_0").iterdir())
    assert files == [f"step_{k:05d}.vtu" for k in range(1 + len(steps))]
    reader = pyvista.get_reader(str(path))
    assert reader.time_values == pytest.approx([0.0] + [r.t for r in steps], rel=1e-15)
    counts = []
    for k, t in enumerate(reader.time_values):
        reader.set_active_time_value(t)
        surface = reader.read()[0]
        assert surface.n_points == len(s.x)
        for name in ("lambda_N", "pressure", "gap", "in_contact", "arc_length", "t_N"):
            assert name in surface.point_data, name
        if k == 0:  # not searched yet
            assert np.all(np.isnan(surface["gap"])) and not np.any(surface["in_contact"])
            continue
        counts.append(int(surface["in_contact"].sum()))
    verification(
        "Hertz 2D, Neo-Hookean, a/h = 2.5, 2 load steps",
        "points in contact per step in the .pvd series",
        counts,
        [float(r.active_points) for r in steps],
        "equal",
        "the step records of the solve (problem.history)",
        kind="consistency",
    )
    assert counts == [r.active_points for r in steps]
    assert np.array_equal(surface["pressure"], s.pressure)
    assert np.array_equal(surface["in_contact"], s.in_contact.astype(np.uint8))
    assert np.array_equal(surface["arc_length"], s.arc_length)
    assert np.array_equal(surface.points[:, :2], s.x)
    gap = surface["gap"]
    assert np.array_equal(np.isnan(gap), ~np.isfinite(s.gap))
    assert np.array_equal(gap[~np.isnan(gap)], s.gap[np.isfinite(s.gap)])
    text = path.read_text()
    assert text.count("<DataSet ") == 1 + len(steps)


def test_the_error_estimate_is_written_with_every_step(written, verification):
    """``error_estimate.csv`` has a line for each write, its last the estimate of the
    converged state to the file's 10 digits (a consistency check: the same computation);
    the indicators' VTX file
    exists beside the displacement's."""
    problem, folder = written
    estimate = problem.error_estimate()
    if MPI.COMM_WORLD.rank != 0:
        return
    lines = (folder / "error_estimate.csv").read_text().splitlines()
    header = lines[0].split(",")
    assert header[:3] == ["t", "estimate", "relative"]
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    steps = problem.history.steps
    assert rows[:, 0] == pytest.approx([0.0] + [r.t for r in steps], rel=1e-12)
    difference = abs(rows[-1, 1] / estimate.estimate - 1.0)
    verification(
        "Hertz 2D, Neo-Hookean, a/h ~ 2.5",
        "written estimate of the last step, relative difference",
        difference,
        0.0,
        "< 1e-9",
        "problem.error_estimate() of the converged state",
        kind="consistency",
    )
    assert difference < 1e-9  # measured 2e-11: the file's 10 significant digits
    parts = dict(zip(header[3:], rows[-1, 3:], strict=True))
    assert parts == pytest.approx(estimate.parts, rel=1e-9)
    assert rows[0, 1] == 0.0  # the reference configuration: no load, no error
    assert (folder / "error_indicators.bp").is_dir()


def test_pictures_are_written_by_rank_0_in_the_plane(written, monkeypatch):
    """Every picture is written once, by rank 0, and a 2D scene is seen in its plane (from
    +z, parallel projection); the pressure profile is drawn from the gathered samples along
    the arc length."""
    problem, folder = written
    saved = []
    save = output._save

    def record(plotter, path):
        camera = plotter.camera
        saved.append((str(path), tuple(camera.direction), bool(camera.parallel_projection)))
        save(plotter, path)

    monkeypatch.setattr(output, "_save", record)
    s = contact_samples(problem)
    output.plot_reference(problem, folder / "reference.png")
    output.plot_contact_state(problem, folder / "state.png", zoom=4.0)
    output.plot_deformed(problem, folder / "deformed.png")
    output.plot_pressure_profile(s, folder / "arc.png", along="arc length")
    output.plot_pressure_profile(s.x[:, 0], s.pressure, folder / "x.png")
    output.plot_curves({"p": (s.arc_length, s.pressure)}, folder / "curves.png", "s", "p")
    counts = MPI.COMM_WORLD.allgather(len(saved))
    assert counts == [6] + [0] * (MPI.COMM_WORLD.size - 1)
    if MPI.COMM_WORLD.rank != 0:
        return
    for path, direction, parallel in saved[:3]:  # the scenes
        assert np.allclose(direction, (0.0, 0.0, -1.0)), path
        assert parallel, path
    for name in ("reference", "state", "deformed", "arc", "x", "curves"):
        assert (folder / f"{name}.png").stat().st_size > 10_000, name


def test_profile_of_arrays_gathered_over_ranks(tmp_path, monkeypatch):
    """With ``comm`` the arrays of the ranks are parts of one profile, gathered to rank 0,
    which draws them all."""
    drawn = []

    class Chart:
        def __init__(self, **kwargs):
            self.title = ""

        def scatter(self, x, y, **kwargs):
            drawn.append(len(x))

    monkeypatch.setattr(output, "_save", lambda plotter, path: plotter.close())
    pv = output._pyvista()
    monkeypatch.setattr(pv, "Chart2D", Chart)
    monkeypatch.setattr(pv.Plotter, "add_chart", lambda self, chart: None)
    comm = MPI.COMM_WORLD
    x = np.arange(3.0) + 3 * comm.rank
    output.plot_pressure_profile(x, x**2, tmp_path / "p.png", comm=comm)
    assert comm.allgather(drawn) == [[3 * comm.size]] + [[]] * (comm.size - 1)


def test_the_nodal_pressure_refuses_multipliers_without_nodal_areas():
    """Shape functions that integrate to zero (P2 multipliers on triangles: the vertex
    ones) have no nodal area: refused, on every rank, before any assembly."""
    from types import SimpleNamespace

    from contact_ufl.errors import ContactInputError

    area = np.array([1.0, 0.0]) if MPI.COMM_WORLD.rank == 0 else np.array([1.0])
    contact = SimpleNamespace(slave=SimpleNamespace(nodal_mass=area))
    problem = SimpleNamespace(contacts=[contact], comm=MPI.COMM_WORLD)
    with pytest.raises(ContactInputError, match="no nodal area"):
        nodal_pressure(problem)
