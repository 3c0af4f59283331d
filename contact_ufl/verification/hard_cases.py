"""The hard-case suite: runs that test the numerical stability of the solver, each
reported by its steps, cut-backs, Newton iterations and, where a step failed, why (the SNES
reasons and diagnoses of the failed tries: inverted elements, active-set cycling, a limit
point; at the failed state the inverted elements and the contact points in contact; along
the try the contact-status changes between Newton iterates). A case meant to stop (load
control beyond a limit point) names the diagnosis it should stop with: its stop is recorded
as ``"expected stop"``, not as a failure.

:func:`cases` lists the cases (quick or full), :func:`run_case` runs one and returns its
record (a ``dict`` ready for JSON); ``benchmarks/hard_cases.py`` runs them all.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from contact_ufl.control import VolumeControl
from contact_ufl.errors import ConvergenceError
from contact_ufl.loads import FollowerPressure
from contact_ufl.materials import NeoHookean
from contact_ufl.newton import weak_callback
from contact_ufl.problem import ContactProblem
from contact_ufl.results import inverted_cells
from contact_ufl.scene import Scene
from contact_ufl.verification import scenes
from contact_ufl.verification.analytic import sphere_inflation_neo_hookean

FORCE_2D = 8e7
"""Resultant of the dead traction on the force-driven Hertz half disc (N per unit
thickness; a contact half-width of about 0.07)."""

NOT_IMPLEMENTED: dict[str, str] = {}
"""Planned cases that do not exist yet, reported as ``"not implemented"`` (none left)."""


@dataclass
class Case:
    """One hard case.

    Attributes
    ----------
    name
        Name in the report.
    build
        Makes the problem (not yet solved).
    stages
        Load stepping: ``(num_steps, t_end)`` of each call of :meth:`ContactProblem.solve`.
    max_cutbacks
        Cut-backs of one step before the run stops.
    expected_stop
        For a case meant to stop (e.g. load control beyond a limit point): a text the
        diagnosis of its stop must contain (``None``: the case is meant to run to the end).
    """

    name: str
    build: Callable[[], ContactProblem]
    stages: list[tuple[int, float]]
    max_cutbacks: int = 8
    expected_stop: str | None = None


def _ironing(mu: float, h_punch: float, h_block: float) -> Callable[[], ContactProblem]:
    """The problem of :func:`contact_ufl.verification.runs.ironing_run`."""

    def build() -> ContactProblem:
        scene = scenes.ironing(mu=mu, h_punch=h_punch, h_block=h_block)
        return ContactProblem(scene, verbose=False, petsc_options={"snes_max_it": 40})

    return build


def _problem(make_scene: Callable[[], object]) -> Callable[[], ContactProblem]:
    def build() -> ContactProblem:
        scene = make_scene()
        return ContactProblem(getattr(scene, "scene", scene), verbose=False)

    return build


def force_driven_2d(steps: int = 2) -> Case:
    """The Hertz half disc pushed by a dead traction onto the block (steel)."""
    return Case(
        "force_driven_2d",
        _problem(lambda: scenes.hertz_2d_driven("force", FORCE_2D)),
        [(steps, 1.0)],
    )


def deep_indentation(
    h_contact: float = 0.02,
    steps: int = 10,
    max_cutbacks: int = 8,
    master_normal: str | None = None,
) -> Case:
    """The 2D Hertz half disc pressed down by half its radius. With the library's default
    master normal (``None``: the smoothed normal in 2D) or ``"smoothed"`` it runs to the end;
    with ``"facet"`` asked for it stops where Newton 2-cycles between neighbouring facets'
    normals (a known stop, kept in the suite)."""

    def scene():
        hertz = scenes.hertz_2d(h_contact=h_contact, depth=0.5)
        pair = hertz.scene.contacts[0]
        hertz.scene.contacts[0] = dataclasses.replace(pair, master_normal=master_normal)
        return hertz.scene

    return Case(
        f"deep_indentation_h{h_contact:g}_{master_normal or 'default'}",
        _problem(scene),
        [(steps, 1.0)],
        max_cutbacks,
    )


def deep_indentation_3d(
    h_contact: float = 0.1, steps: int = 10, max_cutbacks: int = 4, master_normal: str = "facet"
) -> Case:
    """The 3D ball (quarter model, Neo-Hookean) pressed into the block by half its radius
    (the geometry of :func:`~contact_ufl.verification.scenes.hertz_3d` with the contact
    surfaces widened to 0.95 R): with the facet normal it stops near depth 0.24 R, where
    Newton cycles between contact states (the facet normals jump at every master edge); the
    smoothed normal (continuous over the edges) runs to the end."""

    def scene():
        hertz = scenes.hertz_3d(
            h_contact=h_contact,
            depth=0.5,
            contact_zone=0.95,
            h_far=0.3,
            refine_radius=0.8,
            growth=0.5,
        )
        scene = hertz.scene
        scene.bodies = [
            dataclasses.replace(b, material=NeoHookean(b.material.E, b.material.nu))
            for b in scene.bodies
        ]
        pair = scene.contacts[0]
        scene.contacts[0] = dataclasses.replace(pair, master_normal=master_normal)
        return scene

    return Case(
        f"deep_indentation_3d_h{h_contact:g}_{master_normal}",
        _problem(scene),
        [(steps, 1.0)],
        max_cutbacks,
    )


def self_contact_ring(steps: int = 10) -> Case:
    """The ring squeezed between two plates until its hole closes on itself
    (:func:`~contact_ufl.verification.scenes.squeezed_ring`)."""
    return Case("self_contact_ring", _problem(scenes.squeezed_ring), [(steps, 1.0)])


BALLOON_STRETCH = 1.6
"""Final stretch of the volume-controlled balloon, beyond the pressure maximum at
``7^(1/6) = 1.383``."""


def _balloon(load: object) -> Callable[[], ContactProblem]:
    """The sphere octant of :func:`~contact_ufl.verification.scenes.inflated_sphere`
    (Neo-Hookean membrane, ``mu = 1``, ``t0 = 0.01``, ``R = 1``) under ``load`` instead of its
    pressure."""

    def build() -> ContactProblem:
        (domain,) = scenes.inflated_sphere(n=32).domains
        scene = Scene(domains=[dataclasses.replace(domain, loads=[load])])
        return ContactProblem(scene, verbose=False)

    return build


def balloon_pressure_maximum() -> float:
    """The pressure maximum of the balloon of :func:`_balloon` (closed form)."""
    return sphere_inflation_neo_hookean(1.0, 0.01, 1.0, 7.0 ** (1.0 / 6.0))


def limit_point_volume_control(steps: int = 12) -> Case:
    """The balloon inflated by its enclosed volume (:class:`~contact_ufl.control.VolumeControl`,
    the pressure an unknown) to the stretch :data:`BALLOON_STRETCH`: through the pressure
    maximum, every step converged."""
    ratio = BALLOON_STRETCH**3 - 1.0
    control = VolumeControl("membrane", lambda t: 1.0 + ratio * t)
    return Case("limit_point_volume_control", _balloon(control), [(steps, 1.0)])


def limit_point_load_control(steps: int = 4, max_cutbacks: int = 3) -> Case:
    """The same balloon under a prescribed pressure 2% above its maximum: load control
    cannot pass the maximum, the run is expected to stop with a "limit point" diagnosis."""
    p_max = balloon_pressure_maximum()
    pressure = FollowerPressure("membrane", lambda t: 1.02 * p_max * t)
    return Case(
        "limit_point_load_control",
        _balloon(pressure),
        [(steps, 1.0)],
        max_cutbacks,
        expected_stop="limit point",
    )


def large_sliding_3d(mu: float, slide_steps: int = 20) -> Case:
    """The 3D ironing of Puso & Laursen 2004 (:func:`~contact_ufl.verification.scenes.
    ironing_3d`) on the quick mesh of ``benchmarks/ironing_3d.py``: the die pressed 1.4 in
    10 steps, then slid 4 along the slab in ``slide_steps`` steps."""

    def build() -> ContactProblem:
        scene = scenes.ironing_3d(mu=mu, h_die=0.6, h_slab=0.75)
        return ContactProblem(scene, verbose=False, petsc_options={"snes_max_it": 40})

    return Case(f"3d_large_sliding_mu{mu:g}", build, [(10, 1.0), (slide_steps, 2.0)])


def cases(quick: bool = False) -> list[Case]:
    """The hard cases (``quick``: the ironing on coarse meshes, with larger sliding steps,
    and the 2D deep indentation on the coarser mesh only; the self-contact ring and the
    balloon past its limit point, fast, are in both)."""
    ironing_mesh = (0.05, 0.2, 100) if quick else (0.025, 0.1, 200)
    out = [
        Case(
            f"ironing_2d_mu{mu:g}",
            _ironing(mu, *ironing_mesh[:2]),
            [(20, 1.0), (ironing_mesh[2], 2.0)],
        )
        for mu in (0.0, 0.3)
    ]
    out += [
        Case(
            f"beams_mu{mu:g}",
            _problem(lambda mu=mu: scenes.beams(mu=mu, divisions=3, load=6.0)),
            [(20, 1.0)],
        )
        for mu in (0.0, 0.3)
    ]
    out += [large_sliding_3d(mu, 20 if quick else 40) for mu in (0.0, 0.3)]
    out.append(force_driven_2d())
    out.append(
        Case(
            "force_driven_patch_3d",
            _problem(lambda: scenes.patch_3d_pressed(1e-4 * scenes.E_STEEL, gap=1e-3)),
            [(2, 1.0)],
        )
    )
    for normal in ("facet", "smoothed"):
        out.append(deep_indentation(0.02, 10, master_normal=normal))
        if not quick:
            out.append(deep_indentation(0.01, 20, master_normal=normal))
            out.append(deep_indentation_3d(0.1, 10, master_normal=normal))
    out.append(self_contact_ring())
    out.append(limit_point_volume_control())
    out.append(limit_point_load_control())
    return out


class _FailureObserver:
    """Records the failed tries of a problem's Newton solver: pseudo-times, SNES reason,
    iterations, inverted cells and points in contact at the failed state (the last iterate
    of the solver's last try, which the solver leaves in the fields until the stepper
    restores the step's start), and the contact-status changes along the way: points whose
    status (open, in contact; with friction stick or slip) differs between consecutive
    Newton iterates, summed over the iterates of every Newton solve of the try (full-step,
    predicted, line-search and closing solves; not from the end of one to the start of
    the next).

    Wraps the solver's ``solve_step`` and adds a monitor to its SNES (held weakly, as the
    solver's own callbacks are).
    """

    def __init__(self, problem: ContactProblem):
        self.problem = problem
        self.failures: list[dict] = []
        self._changes = 0  # this rank's status changes between iterates of the current try
        self._previous: list[np.ndarray] | None = None  # the status at the last iterate
        self._solve_step = problem.solver.solve_step
        problem.solver.solve_step = self._observed
        problem.solver.snes.setMonitor(weak_callback(self._monitor))

    def _status(self) -> list[np.ndarray]:
        """Each pair's status at its owned slave points: 0 open, 1 in contact (in slip,
        with friction), 2 in stick."""
        status = []
        for c in self.problem.contacts:
            if c.projection is None:
                status.append(np.zeros(0, dtype=np.int8))
                continue
            active = c.active().astype(np.int8)
            status.append(active * (1 + c.stick()) if c.friction else active)
        return status

    def _monitor(self, snes, its: int, norm: float) -> None:
        """At each Newton iterate: count the points whose status changed since the last
        iterate of the same solve (``its == 0`` starts a solve)."""
        status = self._status()
        if its > 0 and self._previous is not None:
            self._changes += sum(
                int(np.count_nonzero(a != b))
                for a, b in zip(status, self._previous, strict=True)
                if a.shape == b.shape
            )
        self._previous = status

    def _observed(self, t: float) -> tuple[bool, int, str]:
        problem = self.problem
        t_start = problem.t
        self._changes, self._previous = 0, None
        ok, its, reason = self._solve_step(t)
        if not ok:
            self.failures.append(
                {
                    "from_time": t_start,
                    "time": t,
                    "reason": reason,
                    "newton_iterations": its,
                    "inverted_cells": inverted_cells(problem),
                    "active_points": problem.active_points(),
                    "status_changes": problem.comm.allreduce(self._changes),
                    "why": problem.solver.diagnose(),
                }
            )
        return ok, its, reason


def run_case(case: Case) -> dict:
    """Run one case; a run stopped by :class:`ConvergenceError` is recorded, not raised.

    Returns
    -------
    dict
        ``name``, ``status`` (``"completed"``, ``"stopped"``, or ``"expected stop"``: a
        case with :attr:`Case.expected_stop` stopped with that text in its diagnosis),
        ``expected_stop`` (:attr:`Case.expected_stop`), ``as_expected`` (the run completed
        with every step converged, or stopped as expected), ``diagnosis`` (why the run
        stopped: the ``why`` of its last failed try, or ``None``), ``t_end``, ``t_reached``,
        ``steps``, ``cutbacks``, ``newton_max``, ``newton_mean`` (per accepted step),
        ``all_converged`` (the run completed and every accepted step has a ``CONVERGED_*``
        SNES reason), ``step_reasons`` (the distinct reasons of the accepted steps),
        ``failures`` (one record per failed try: ``from_time``, ``time``, ``reason``, ``why``,
        ``newton_iterations``, ``inverted_cells``, ``active_points``, ``status_changes``:
        the contact-status changes of points between consecutive Newton iterates of the
        try, see :class:`_FailureObserver`), ``error`` (the
        message of the :class:`ConvergenceError`, or ``None``), ``unknowns``, ``wall_s``.
    """
    start = time.perf_counter()
    problem = case.build()
    observer = _FailureObserver(problem)
    error = None
    try:
        for num_steps, t_end in case.stages:
            problem.solve(
                num_steps=num_steps,
                t_end=t_end,
                max_cutbacks=case.max_cutbacks,
            )
    except ConvergenceError as e:
        error = str(e)
    wall = problem.comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    history = problem.history
    its = [r.newton_iterations for r in history.steps]
    reasons = [r.reason for r in history.steps]
    all_converged = error is None and all(r.startswith("CONVERGED") for r in reasons)
    diagnosis = observer.failures[-1]["why"] if error and observer.failures else None
    expected = case.expected_stop is not None and case.expected_stop in (diagnosis or "")
    status = ("expected stop" if expected else "stopped") if error else "completed"
    return {
        "name": case.name,
        "status": status,
        "expected_stop": case.expected_stop,
        "as_expected": expected if case.expected_stop else all_converged,
        "diagnosis": diagnosis,
        "t_end": case.stages[-1][1],
        "t_reached": float(problem.t),
        "steps": len(history.steps),
        "cutbacks": len(history.cutbacks),
        "newton_max": max(its, default=0),
        "newton_mean": sum(its) / len(its) if its else 0.0,
        "all_converged": all_converged,
        "step_reasons": sorted(set(reasons)),
        "failures": observer.failures,
        "error": error,
        "unknowns": problem.layout.global_size,
        "wall_s": wall,
    }
