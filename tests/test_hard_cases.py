"""The hard-case suite's runner on its fastest members: the records say what happened
(steps, cut-backs, SNES reasons, why a case stopped)."""

import pytest

from contact_ufl.verification import hard_cases

pytestmark = pytest.mark.serial


def test_force_driven_record():
    """The force-driven Hertz half disc converges every step without cut-backs."""
    record = hard_cases.run_case(hard_cases.force_driven_2d(steps=2))
    assert record["status"] == "completed" and record["error"] is None
    assert record["t_reached"] == pytest.approx(1.0)
    assert record["steps"] == 2 and record["cutbacks"] == 0
    assert record["all_converged"] and not record["failures"]
    assert all(r.startswith("CONVERGED") for r in record["step_reasons"])
    # at most 9 Newton iterations per step (6 measured; test_force_driven.py counts them)
    assert 1 <= record["newton_mean"] <= record["newton_max"] <= 9


def test_deep_indentation_record():
    """The Hertz half disc pressed down by half its radius with the facet master normal
    asked for (coarse mesh, 4 steps, 3 cut-backs) stops before the end: the record keeps the
    accepted steps, names the step and the DIVERGED_* reasons of the failed tries, and has
    one failure per cut-back; the diagnosis points to the smoothed normal."""
    case = hard_cases.deep_indentation(0.05, steps=4, max_cutbacks=3, master_normal="facet")
    record = hard_cases.run_case(case)
    assert record["status"] == "stopped" and not record["all_converged"]
    assert 0.0 < record["t_reached"] < 1.0
    assert "did not converge" in record["error"]
    assert 'master_normal="smoothed"' in record["diagnosis"]
    assert f"from t = {record['t_reached']:.6g}" in record["error"]
    assert record["steps"] >= 1 and record["cutbacks"] == len(record["failures"]) >= 4
    assert all(f["reason"].startswith("DIVERGED") for f in record["failures"])
    assert all(f["time"] > f["from_time"] for f in record["failures"])
    assert all(f["active_points"] > 0 for f in record["failures"])
    # the facet normal's cycling: points change contact status between the Newton iterates
    # of the tries (counted along each try, not at its end), and at the end of a try the
    # pairing alone cycles across facet edges, the status settled
    cycling = [f for f in record["failures"] if "cycling)" in f["why"]]
    assert cycling and sum(f["status_changes"] > 0 for f in cycling) >= 2
    assert any("(pairing cycling)" in f["why"] for f in cycling)


def _converged_without_cutbacks(record: dict, steps: int) -> None:
    assert record["status"] == "completed" and record["as_expected"]
    assert record["error"] is None and record["diagnosis"] is None
    assert record["t_reached"] == pytest.approx(1.0)
    assert record["steps"] == steps and record["cutbacks"] == 0 and not record["failures"]
    assert record["all_converged"]
    assert all(r.startswith("CONVERGED") for r in record["step_reasons"])


def test_self_contact_ring_record():
    """The ring squeezed until its hole closes on itself: every step converges, no cut-back
    (at most 25 Newton iterations per step; 14 measured)."""
    record = hard_cases.run_case(hard_cases.self_contact_ring())
    _converged_without_cutbacks(record, 10)
    assert 1 <= record["newton_mean"] <= record["newton_max"] <= 25


def test_volume_control_record():
    """The balloon under volume control, through its pressure maximum: every step
    converges, no cut-back (at most 10 Newton iterations per step; 7 measured)."""
    record = hard_cases.run_case(hard_cases.limit_point_volume_control())
    _converged_without_cutbacks(record, 12)
    assert 1 <= record["newton_mean"] <= record["newton_max"] <= 10


def test_load_control_record_is_an_expected_limit_point_stop(verification):
    """The balloon under a pressure 2% above its maximum stops below the maximum, as
    expected: every failed try, and the stop, diagnosed as a limit point (no inverted
    element, no change of contact state)."""
    record = hard_cases.run_case(hard_cases.limit_point_load_control(steps=4, max_cutbacks=3))
    assert record["status"] == "expected stop" and record["as_expected"]
    assert record["expected_stop"] == "limit point" and not record["all_converged"]
    assert "limit point" in record["diagnosis"] and "limit point" in record["error"]
    assert "did not converge" in record["error"] and "after 3 cut-backs" in record["error"]
    verification(
        "hard case limit_point_load_control: Neo-Hookean balloon, pressure to 1.02 p_max",
        "largest converged pressure over the closed-form maximum p_max",
        record["t_reached"] * 1.02,
        1.0,
        "< 1",
        "closed form: p = 2 mu t0 / R (1/l - 1/l^7) of the inflated sphere has no "
        "equilibrium above its maximum",
    )
    assert 0.0 < record["t_reached"] * 1.02 < 1.0  # stopped below the maximum
    assert record["cutbacks"] == len(record["failures"]) >= 4
    assert all("limit point" in f["why"] for f in record["failures"])
    assert all(f["inverted_cells"] == 0 and f["status_changes"] == 0 for f in record["failures"])


def test_case_expected_to_stop_that_stops_otherwise_is_not_as_expected():
    """A case whose stop is expected with another diagnosis is recorded as ``stopped``."""
    case = hard_cases.limit_point_load_control(steps=4, max_cutbacks=1)
    case.expected_stop = "inverted elements"
    record = hard_cases.run_case(case)
    assert record["status"] == "stopped" and not record["as_expected"]
    assert "limit point" in record["diagnosis"]


def test_case_lists():
    """The implemented cases are in the suite (the fast ones in the quick suite too), the
    planned ones not yet, and no case is listed as both."""
    quick = {c.name for c in hard_cases.cases(quick=True)}
    full = {c.name for c in hard_cases.cases()}
    fast = {"self_contact_ring", "limit_point_volume_control", "limit_point_load_control"}
    assert fast | {"force_driven_2d", "ironing_2d_mu0", "beams_mu0.3"} <= quick <= full
    assert {"deep_indentation_3d_h0.1_facet", "deep_indentation_3d_h0.1_smoothed"} <= full
    assert not [(k, n) for k in hard_cases.NOT_IMPLEMENTED for n in full if n.startswith(k)]
    expected = {c.name: c.expected_stop for c in hard_cases.cases()}
    assert expected["limit_point_load_control"] == "limit point"
    assert {n for n, e in expected.items() if e} == {"limit_point_load_control"}


def test_large_sliding_3d_cases_exist():
    """The 3D ironing is a case of the suite, no longer a planned one."""
    names = {case.name for case in hard_cases.cases(quick=True)}
    assert {"3d_large_sliding_mu0", "3d_large_sliding_mu0.3"} <= names
    assert not any(name.startswith("3d_large_sliding") for name in hard_cases.NOT_IMPLEMENTED)


def test_inverted_cells_counts_cells_turned_inside_out():
    """No cell is inverted at the start; mirroring the half x > 0.5 of the Hertz scene
    (u_x = -2 (x - 0.5) there, det F = -1) inverts the cells in it and no others."""
    import numpy as np

    from contact_ufl.problem import ContactProblem
    from contact_ufl.results import inverted_cells
    from contact_ufl.verification import scenes

    problem = ContactProblem(scenes.hertz_2d_driven("force", 1.0, h_contact=0.1), verbose=False)
    assert inverted_cells(problem) == 0
    mesh = problem.V.mesh
    x = problem.V.tabulate_dof_coordinates()[:, 0]
    problem.u.x.array.reshape(-1, 2)[:, 0] = np.where(x > 0.5, -2.0 * (x - 0.5), 0.0)
    owned = mesh.topology.index_map(2).size_local
    vertices = mesh.geometry.x[mesh.geometry.dofmaps[0][:owned], 0]
    inside = int((vertices.min(axis=1) >= 0.5).sum())
    straddling = int(((vertices.min(axis=1) < 0.5) & (vertices.max(axis=1) > 0.5)).sum())
    count = inverted_cells(problem)
    assert inside > 0 and inside <= count <= inside + straddling


@pytest.mark.parametrize(
    "iterates, expected",
    [
        ([(1e3, 1), (1e2, 2), (50.0, 3)], "fell from 1e+03 to 50 in 2 iterates, the contact "),
        ([(1e3, 1), (1e2, 1)], "fell from 1e+03 to 100 in 1 iterates, no change of contact"),
        ([(1.0, 4), (1.0, 4), (1.0, 4)], "a limit point"),
        ([(1.0, 1), (1.0, 2), (1.0, 1)], "(active-set cycling)"),
    ],
)
def test_diagnosis_of_the_iterates(iterates, expected):
    """From the residual norms and contact-state signatures of a failed solve's iterates:
    a return to an earlier state is cycling, no change at all a limit point, otherwise how
    far the residual fell and in how many iterates the contact state changed."""
    from contact_ufl.problem import ContactProblem
    from contact_ufl.verification import scenes

    problem = ContactProblem(scenes.hertz_2d_driven("force", 1.0, h_contact=0.1), verbose=False)
    diagnosis = problem.solver.diagnosis
    diagnosis.signatures = [signature for _, signature in iterates]
    assert expected in diagnosis.diagnose([norm for norm, _ in iterates])


def test_diagnosis_of_a_pairing_that_cycles_alone():
    """Iterates that return to an earlier pairing while every point keeps its contact status
    (a point's master facet alternating across a facet edge): the pairing cycles, and the
    diagnosis gives the residual's stall relative to the first, which a snes_rtol above it
    accepts (a 3D P2 Hertz at h_contact = 0.06 that stalls at 3.7e-6 converges with
    snes_rtol 1e-5 in 3 and 2 iterations a step). With a status that changes, it is
    active-set cycling."""
    from contact_ufl.problem import ContactProblem
    from contact_ufl.verification import scenes

    problem = ContactProblem(scenes.hertz_2d_driven("force", 1.0, h_contact=0.1), verbose=False)
    diagnosis = problem.solver.diagnosis
    norms = [1.0, 1e-3, 4.04e-6, 4.05e-6, 4.04e-6]
    diagnosis.signatures = [1, 2, 3, 4, 3]
    diagnosis.statuses = [5, 7, 7, 7, 7]
    message = diagnosis.diagnose(norms)
    assert "(pairing cycling)" in message and "4.04e-06, 4e-06 of the first" in message
    assert "snes_rtol above 4e-06" in message
    diagnosis.statuses = [5, 7, 8, 7, 8]
    assert "(active-set cycling)" in diagnosis.diagnose(norms)


@pytest.mark.slow
def test_quick_suite():
    """The whole quick suite: every case runs as expected but the deep indentation with the
    facet normal (a known stop, by active-set cycling), and every failed try says why."""
    records = [hard_cases.run_case(case) for case in hard_cases.cases(quick=True)]
    known = {"deep_indentation_h0.02_facet"}
    assert all(r["as_expected"] for r in records if r["name"] not in known)
    assert all(
        not r["as_expected"] and r["status"] == "stopped" for r in records if r["name"] in known
    )
    failures = [f for r in records for f in r["failures"]]
    assert all(f["why"] and f["reason"].startswith("DIVERGED") for f in failures)
    assert all(r["cutbacks"] == len(r["failures"]) for r in records)
