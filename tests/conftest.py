"""Shared fixtures: solved verification problems, built once per session."""

import gc
import json
import math
from collections.abc import Sequence
from numbers import Real

import numpy as np
import pytest
from mpi4py import MPI
from verification_report import KINDS, PROPERTY

from contact_ufl.problem import ContactProblem
from contact_ufl.taylor import taylor_test
from contact_ufl.verification import scenes

#: the disc of the 2D Hertz scene (``scenes.hertz_2d``): radius 1, centre (0, 1)
CENTRE = np.array([0.0, 1.0, 0.0])


def onto_circle(x: np.ndarray) -> np.ndarray:
    """Points moved radially onto the 2D Hertz disc's circle (a refined arc's new nodes)."""
    d = x - CENTRE
    return CENTRE + d / np.linalg.norm(d, axis=1)[:, None]


#: A comparison of a run on all ranks with the same run on one rank: skipped on one rank,
#: where it would compare a run with itself.
across_ranks = pytest.mark.skipif(
    MPI.COMM_WORLD.size == 1, reason="compares a run on all ranks with one on a single rank"
)


def solve_hertz(h_contact: float, depth: float = 0.005, comm=MPI.COMM_WORLD, steps: int = 4):
    """Solve the 2D Hertz scene; return the problem and the scene's analytic data."""
    hertz = scenes.hertz_2d(h_contact=h_contact, depth=depth, comm=comm)
    problem = ContactProblem(hertz.scene, verbose=False)
    problem.solve(num_steps=steps)
    return problem, hertz


@pytest.fixture(scope="session")
def hertz_sequence():
    """Hertz on three meshes (a/h ~ 2.5, 5, 10), for refinement studies."""
    return [solve_hertz(h) for h in (0.02, 0.01, 0.005)]


@pytest.fixture(scope="session")
def hertz_moderate(hertz_sequence):
    """Hertz at a/h ~ 10 (the accuracy target mesh)."""
    return hertz_sequence[-1]


def assert_taylor_slopes(
    problem,
    dz,
    steps,
    slope: float = 2.0,
    tol: float = 0.01,
    unchanged: bool = True,
    zeroth: bool = False,
):
    """Run the Taylor test of ``problem`` along ``dz`` with the ``steps``; assert that every
    slope of the remainder is ``slope`` within ``tol``, with ``unchanged`` that no point
    changed facet or contact status over the steps, and with ``zeroth`` that the zeroth-order
    remainder falls with slope 1 (within 0.05). Returns the result."""
    result = taylor_test(problem, dz, steps)
    if unchanged:
        assert not result.facets_changed and not result.active_changed
    if zeroth:
        zeroth_slopes = np.diff(np.log(result.zeroth)) / np.diff(np.log(result.h))
        assert np.all(np.abs(zeroth_slopes - 1.0) < 0.05)
    assert np.all(np.abs(result.slopes - slope) < tol), result.slopes
    return result


def tagged_unit_square(n: int = 4, cell_type=None):
    """The unit square as one body (cell tag 1), sides tagged left 1, right 2, bottom 3, top 4."""
    import dolfinx
    import numpy as np

    from contact_ufl.verification.geometries import tag_single_body

    cell_type = cell_type or dolfinx.mesh.CellType.triangle
    mesh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, n, n, cell_type)
    sides = [lambda x, k=k, v=v: np.isclose(x[k], v) for k, v in ((0, 0), (0, 1), (1, 0), (1, 1))]
    return (mesh, *tag_single_body(mesh, sides))


def symmetric_square(material, loads, n: int = 4, cell_type=None, dirichlet=()):
    """One body on the unit square, held normally on its left and bottom sides (symmetry),
    with ``loads`` (and extra ``dirichlet`` conditions) on the tags of
    :func:`tagged_unit_square`."""
    from contact_ufl.loads import Dirichlet
    from contact_ufl.scene import Body, Scene

    mesh, cells, facets = tagged_unit_square(n, cell_type)
    supports = [Dirichlet(1, 0.0, component=0), Dirichlet(3, 0.0, component=1), *dirichlet]
    return Scene(mesh, cells, facets, [Body(1, material)], dirichlet=supports, loads=list(loads))


@pytest.fixture(autouse=True)
def _free_finished_problems():
    """Collect the garbage of every test on all ranks at the same point: meshes, spaces
    and solvers each hold MPI communicators, and MPICH runs out of them (a few thousand)
    when finished problems linger in reference cycles until a later collection."""
    yield
    gc.collect()


def _number(x) -> bool:
    return isinstance(x, Real) and not isinstance(x, bool) and math.isfinite(x)


def _numbers(x) -> bool:
    """A finite number, or a non-empty sequence of them."""
    if isinstance(x, Sequence | np.ndarray) and not isinstance(x, str):
        return len(x) > 0 and all(_number(v) for v in np.asarray(x, dtype=object).ravel())
    return _number(x)


def _plain(x):
    """``x`` as JSON can hold it: numbers as floats, arrays and tuples as lists."""
    if isinstance(x, str):
        return x
    if isinstance(x, Sequence | np.ndarray):
        return [float(v) for v in np.asarray(x, dtype=float).ravel()]
    return float(x)


@pytest.fixture
def verification(request, record_property):
    """Record a checked quantity of the test for the verification report.

    The record is a user property ``verification`` of the test (a JSON object of the fields
    below and the test's node id), which ``pytest --junitxml`` writes to the test's
    ``testcase`` element; ``tests/verification_report.py`` makes ``docs/verification.md`` of
    them. It asserts nothing: the test keeps its own asserts, and the record reports the
    value the test asserts on and the tolerance the test enforces.

    Returns
    -------
    callable
        ``verification(case, quantity, measured, reference, tolerance, source,
        kind="verification")``: ``case`` names the problem and ``quantity`` what is
        compared (non-empty strings); ``measured`` is the value asserted on (a finite number
        or a sequence of them); ``reference`` what it is compared to (numbers or a text);
        ``tolerance`` the test's bound (a number or a text such as ``"|error| < 0.01"``);
        ``source`` where the reference comes from; ``kind`` one of
        :data:`verification_report.KINDS`. A wrong argument raises ``TypeError`` or
        ``ValueError``.
    """

    def record(case, quantity, measured, reference, tolerance, source, kind="verification"):
        for name, value in (("case", case), ("quantity", quantity), ("source", source)):
            if not isinstance(value, str) or not value.strip():
                raise TypeError(f"verification: {name} must be a non-empty string, not {value!r}")
        if kind not in KINDS:
            raise ValueError(f"verification: kind must be one of {sorted(KINDS)}, not {kind!r}")
        if not _numbers(measured):
            raise TypeError(f"verification: measured must be finite numbers, not {measured!r}")
        if not (isinstance(reference, str) and reference.strip()) and not _numbers(reference):
            raise TypeError(f"verification: reference must be numbers or text, not {reference!r}")
        if not (isinstance(tolerance, str) and tolerance.strip()) and not _number(tolerance):
            raise TypeError(f"verification: tolerance must be a number or text, not {tolerance!r}")
        fields = {
            "case": case,
            "quantity": quantity,
            "measured": _plain(measured),
            "reference": _plain(reference),
            "tolerance": _plain(tolerance),
            "source": source,
            "kind": kind,
            "nodeid": request.node.nodeid,
        }
        record_property(PROPERTY, json.dumps(fields, sort_keys=True))

    return record
