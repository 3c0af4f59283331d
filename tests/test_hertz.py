"""2D Hertz: the multiplier against p(x) = p0 sqrt(1 - x^2/a^2) (Johnson 1985, 4.2)."""

import numpy as np
import pytest

from contact_ufl.results import contact_samples, weak_contact_law
from contact_ufl.verification.analytic import Hertz2D, fit_elliptic_profile

JOHNSON = "Johnson, Contact Mechanics (1985), 4.2: closed form at the computed force"
PROFILE = "p(x) = p0 sqrt(1 - x^2 / a^2)"
SIGNORINI = "the contact law: gap >= 0, pressure >= 0, their product 0"
#: the bounds at a/h = 10 on |a error|, |p0 error| and the RMS profile error over p0
BOUNDS = (0.005, 0.01, 0.03)


def record_hertz_errors(verification, case, a_err, p0_err, profile_err, bounds=(0.01, 0.01, 0.03)):
    """Record the three errors that a Hertz test asserts on, with the ``bounds`` it enforces
    (on |a error|, |p0 error| and the RMS profile error over p0)."""
    a_tol, p0_tol, profile_tol = bounds
    for quantity, error, reference, tolerance in (
        ("relative error of the half-width", a_err, "a = sqrt(4 P R / (pi E*))", a_tol),
        ("relative error of the peak pressure", p0_err, "p0 = 2 P / (pi a)", p0_tol),
    ):
        verification(case, quantity, error, reference, f"|error| < {tolerance:g}", JOHNSON)
    quantity = "RMS pressure error in |x| < 0.8 a, over p0"
    verification(case, quantity, profile_err, PROFILE, f"< {profile_tol:g}", JOHNSON)


def hertz_errors(problem, hertz):
    """Relative errors of a and p0 (fitted to the Cauchy pressure), and the RMS error of the
    pressure profile inside the contact zone (|x| < 0.8 a, away from the edges where a finite
    element profile is smeared over an element), relative to p0."""
    samples = contact_samples(problem)
    P = problem.contact_force()[1]
    exact = Hertz2D(P, hertz.radius, hertz.E_star)
    a, p0, xc = fit_elliptic_profile(samples.x[:, 0], samples.pressure)
    near = np.abs(samples.x[:, 0] - xc) < 0.8 * exact.a
    profile = samples.pressure[near] - exact.pressure(samples.x[near, 0] - xc)
    return (a / exact.a - 1.0, p0 / exact.p0 - 1.0, np.sqrt(np.mean(profile**2)) / exact.p0, exact)


@pytest.mark.serial  # 2 ranks: test_properties' comparison with one rank
def test_hertz_half_width_and_peak_pressure(hertz_moderate, verification):
    """At a/h = 10 the half-width is within 0.5% and the peak pressure within 1% of Hertz
    (0.2% and 0.7% measured; finer meshes level off at about 0.5%,
    benchmarks/results/hertz.json), the pressure profile within 3% of p0 (2.0%)."""
    problem, hertz = hertz_moderate
    a_err, p0_err, profile_err, exact = hertz_errors(problem, hertz)
    case = "Hertz 2D, Neo-Hookean, 4 load steps, a/h = 10"
    record_hertz_errors(verification, case, a_err, p0_err, profile_err, BOUNDS)
    assert exact.a / hertz.h_contact > 8  # the contact zone is resolved
    assert abs(a_err) < BOUNDS[0]
    assert abs(p0_err) < BOUNDS[1]
    assert profile_err < BOUNDS[2]


@pytest.mark.serial  # 2 ranks: test_properties' comparison with one rank
def test_hertz_errors_fall_under_refinement(hertz_sequence, verification):
    """From a/h = 2.5 to 5 to 10 the errors of a and p0 fall (from 6-8% to below 1%)."""
    errors = np.array([np.abs(hertz_errors(p, h)[:2]) for p, h in hertz_sequence])
    case = "Hertz 2D, Neo-Hookean, a/h = 2.5, 5, 10"
    tolerance = "falls with h; > 0.05 at a/h = 2.5, < 0.01 at a/h = 10"
    for k, (name, reference) in enumerate(
        (("half-width", "a = sqrt(4 P R / (pi E*))"), ("peak pressure", "p0 = 2 P / (pi a)"))
    ):
        quantity = f"|relative error| of the {name}"
        verification(case, quantity, errors[:, k], reference, tolerance, JOHNSON)
    assert np.all(np.diff(errors, axis=0) < 0), errors
    assert np.all(errors[0] > 0.05) and np.all(errors[-1] < 0.01), errors


@pytest.mark.serial  # 2 ranks: test_properties' comparison with one rank
def test_hertz_contact_law(hertz_moderate, verification):
    """(d): closed gap where the pressure is positive, zero pressure where the gap is open.

    The multiplier equation imposes the law node by node in the weak sense: int g phi_i = 0
    where the whole support of phi_i is in contact, int lambda_N phi_i = 0 where it is open;
    both hold to solver tolerance. Pointwise, the continuous P1 multiplier has a tail next to
    the contact edge that alternates in sign and decays by ~0.27 per element (the consistent
    mass matrix): zero pressure is checked pointwise beyond 20 elements from the edge, and
    the tail's first, negative, node is above -1% of p0 (-0.47% measured).

    The weak gap, the weak multiplier where open and the multiplier far from the edge are
    zero to the solver's tolerance (relative residual 1e-9): they are bounded by 1e-8, not by
    their measured values (1e-12 and below), which a last quadratic Newton step puts
    anywhere below it.
    """
    problem, hertz = hertz_moderate
    s = contact_samples(problem)
    P = problem.contact_force()[1]
    exact = Hertz2D(P, hertz.radius, hertz.E_star)
    a, p0, xc = fit_elliptic_profile(s.x[:, 0], s.pressure)
    eps_N = float(problem.contacts[0].normal.eps_N.value)
    weak_gap, weak_lambda = weak_contact_law(problem)
    pressed = s.lambda_N > 0.05 * p0
    far = (s.gap < 0.0) & (np.abs(s.x[:, 0] - xc) > exact.a + 20 * hertz.h_contact)
    case = "Hertz 2D, Neo-Hookean, a/h = 10"
    equations = "the multiplier equation of the converged solve"
    verification(
        case,
        "weak gap in contact, times eps_N / p0",
        weak_gap * eps_N / p0,
        0.0,
        "< 1e-8",
        equations,
        kind="consistency",
    )
    verification(
        case,
        "weak multiplier where open, over p0",
        weak_lambda / p0,
        0.0,
        "< 1e-8",
        equations,
        kind="consistency",
    )
    verification(
        case,
        "smallest nodal multiplier, over p0",
        s.lambda_N.min() / p0,
        "lambda_N >= 0",
        "> -0.01",
        SIGNORINI,
    )
    if far.any():
        verification(
            case,
            "largest |multiplier| beyond 20 h from the edge, over p0",
            np.abs(s.lambda_N[far]).max() / p0,
            "lambda_N = 0 where open",
            "< 1e-8",
            SIGNORINI,
        )
    if pressed.any():
        verification(
            case,
            "largest |gap| where pressed, times eps_N / largest multiplier",
            np.abs(s.gap[pressed]).max() * eps_N / s.lambda_N.max(),
            "g = 0 where pressed",
            "< 0.05",
            SIGNORINI,
        )
    assert weak_gap < 1e-8 * p0 / eps_N
    assert weak_lambda < 1e-8 * p0
    assert np.all(s.lambda_N > -0.01 * p0)
    assert np.abs(s.lambda_N[far]).max() < 1e-8 * p0
    # pointwise, the closed gap is the O(h^2) mismatch of the two discrete surfaces, far
    # below the lambda / eps_N a penalty method would penetrate
    assert np.abs(s.gap[pressed]).max() < 0.05 * s.lambda_N.max() / eps_N
    assert pressed.sum() > 20 and far.sum() > 20
