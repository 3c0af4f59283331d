"""The hard-case suite's runner (issue 13, item 7) on its fastest members: the records say
what happened (steps, cut-backs, SNES reasons, why a case stopped)."""

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
    assert 1 <= record["newton_mean"] <= record["newton_max"] <= 50
    assert record["wall_s"] > 0.0


def test_deep_indentation_record():
    """The Hertz half disc pressed down by half its radius (coarse mesh, 4 steps, 3
    cut-backs) stops before the end: the record keeps the accepted steps, names the step
    and the DIVERGED_* reasons of the failed tries, and has one failure per cut-back."""
    record = hard_cases.run_case(hard_cases.deep_indentation(0.05, steps=4, max_cutbacks=3))
    assert record["status"] == "stopped" and not record["all_converged"]
    assert 0.0 < record["t_reached"] < 1.0
    assert "did not converge" in record["error"]
    assert f"from t = {record['t_reached']:.6g}" in record["error"]
    assert record["steps"] >= 1 and record["cutbacks"] == len(record["failures"]) >= 4
    assert all(f["reason"].startswith("DIVERGED") for f in record["failures"])
    assert all(f["time"] > f["from_time"] for f in record["failures"])
    assert all(f["inverted_cells"] >= 0 and f["active_points"] > 0 for f in record["failures"])
    assert all(f["status_changes"] is not None for f in record["failures"])  # after step 1
    assert all(f["status_changes"] >= 0 for f in record["failures"])


def test_planned_cases_are_listed():
    assert {"self_contact", "limit_point"} <= set(hard_cases.NOT_IMPLEMENTED)


def test_large_sliding_3d_cases_exist():
    """The 3D ironing (issue 13, item 2) is a case of the suite, no longer a planned one."""
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
