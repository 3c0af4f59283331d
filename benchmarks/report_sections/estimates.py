"""The sections of the report on the error estimate: its effectivity against a true error
under refinement (``benchmarks/estimate_effectivity.py``), with unit weights and with the
package's per-term weights; adaptive against uniform refinement (``benchmarks/adaptive.py``).
"""

from report_sections.tables import (
    Column,
    Section,
    Table,
    fixed,
    integer,
    percent,
    scientific,
    significant,
)

#: the case of a record as the table shows it
CASES = {
    "hertz_2d": "Hertz 2D",
    "patch": "patch test 2D",
    "cattaneo": "Cattaneo-Mindlin 2D",
    "hertz_3d": "Hertz 3D",
}


def _case(record: dict) -> str:
    return CASES.get(record["case"], record["case"])


def _reference(record: dict) -> str:
    """``exact`` or ``P2, s = 0.125 (341,691)``."""
    reference = record["reference"]
    if reference["kind"] != "P2 solve":
        return "exact"
    return f"P2, s = {reference['s']:g} ({reference['unknowns']:,})"


def _share(term: str):
    """The share of ``term`` in eta^2 (unit weights) as a whole percentage."""

    def value(record: dict) -> float:
        total = sum(v for k, v in record.items() if k.startswith("part_"))
        return record[f"part_{term}"] / total if total > 0 else float("nan")

    return value


def _newton_total_max(record: dict) -> str:
    """``total (largest of a step)``."""
    return f"{record['newton_iterations']} ({record.get('newton_max', '-')})"


def _force_effectivity(record: dict) -> float | None:
    """The force's estimated relative error over its true one (the force-driven loop)."""
    if record.get("goal") != "normal_force" or not record.get("force_error"):
        return None
    return record["relative_estimate"] / abs(record["force_error"])


def _percent(x) -> str:
    return "-" if x is None or x != x else f"{100.0 * x:.0f}%"


def _refinement(record: dict) -> str:
    """``adaptive``, ``uniform`` or ``graded, h 0.0075``."""
    if record["kind"] == "graded":
        return f"graded, h {record['h_contact']:g}"
    return record["kind"]


#: the first and last columns of a table of adaptive levels
LEVEL = (
    Column("refinement", _refinement),
    Column("unknowns", "dofs", integer),
    Column("relative estimate", "relative_estimate", scientific),
)
TIMES = (Column("wall s", "wall_s", significant), Column("loop s", "cumulative_s", significant))

SECTIONS = (
    Section(
        "Effectivity of the error estimate",
        "The residual estimate `eta` of `problem.error_estimate()` against the error in the "
        "energy norm of the linearised elasticity at the reference configuration, "
        "`||e||_E = (int Grad e : C : Grad e dX)^1/2`, `e = u_ref - u_h`: on the patch test "
        "`u_ref` is the exact homogeneous stretch; elsewhere a P2 solve of the same "
        "geometry (curved mesh) on a finer mesh, through the same load steps, and the "
        "integral is taken on its mesh with the coarse gradient sampled at its quadrature "
        "points (body by body; *interpolated*: the norm with `u_h` interpolated into the "
        "reference space instead, which smears its kinks). Each case refines all its mesh "
        "sizes by the factor `s`. *Effectivity* is `eta / ||e||_E` with every term "
        "weighted by 1; *weighted* with the package's weights on the terms' `eta^2` "
        "(`contact_ufl.estimate.WEIGHTS`, fitted to these records: 1/4 on the bulk's "
        "residuals, `bulk`, `jump` and `boundary`, 1/2 on the contact's, `traction`, "
        "`penetration`, `complementarity` and `cone`); "
        "*energy eff.* is `eta` over `(2 |W_h - W_ref|)^1/2`, the error "
        "the stored energy measures. The shares are those of the jump, contact traction and "
        "complementarity terms in the unit-weighted `eta^2`. The 3D Hertz rows (their own "
        "file, `--cases hertz_3d`) start at `s = 2.8`: coarser P1 meshes are not yet "
        "refining (the error at `s = 3.4` is below that at 2.8; at `s = 4` the contact "
        "states cycle), and their reference is P2 at `s = 1` (on the finer P2 meshes tried, "
        "`s` = 0.85 and 0.7, the contact states cycle); that reference moved one step "
        "coarser, to `s = 1.4`, changes the error at `s` = 2.8 and 2 by 0.4%.",
        "python benchmarks/estimate_effectivity.py [--quick] [--cases hertz_2d patch cattaneo "
        "hertz_3d] --json FILE",
        (
            Table(
                "Effectivity under refinement",
                ("estimate_effectivity.json", "estimate_effectivity_3d.json"),
                (
                    Column("case", _case),
                    Column("s", "s"),
                    Column("h contact", "h_contact"),
                    Column("unknowns", "unknowns", integer),
                    Column("eta", "eta", scientific),
                    Column("jump", _share("jump"), _percent),
                    Column("traction", _share("traction"), _percent),
                    Column("compl.", _share("complementarity"), _percent),
                    Column("error", "error", scientific),
                    Column("interpolated", "error_interpolated", scientific),
                    Column("effectivity", "effectivity", fixed(2)),
                    Column("weighted", "effectivity_weighted", fixed(2)),
                    Column("energy eff.", "energy_effectivity", fixed(2)),
                    Column("reference", _reference),
                    Column("wall s", "wall_s", significant),
                    Column("estimate s", "estimate_s", significant),
                ),
            ),
        ),
    ),
    Section(
        "Effectivity of the contact force's error estimate",
        "The signed estimate of `problem.normal_force_error()` (dual-weighted residuals, "
        "the dual solved with the displacement of degree 2 on the same mesh) against the "
        "true error of the P1 normal force `int lambda_N dS_o`, on meshes refined "
        "uniformly (every cell; the disc's new nodes on its circle). *hertz_2d*: the scene "
        "of `tests/test_goal.py` (neo-Hookean, depth 0.02 R in 2 steps); "
        "*hertz_2d_linear*: the Hertz benchmark's scene (linear elastic, depth 0.005 in "
        "one step, graded to `h_contact = 0.01`). The true force is the Richardson limit "
        "of the P2 forces on the three meshes (*effectivity*), or of the P1 forces "
        "(*eff. P1 limit*). *P2 / estimate*: the P2 solve's change of the force on the same "
        "mesh over the estimate, which it predicts to first order. *estimate s*: the "
        "estimate's wall time (the degree-2 problem's set-up, one tangent, one transposed "
        "solve), beside the P1 and P2 solves'.",
        "python benchmarks/goal_estimate.py --json FILE",
        (
            Table(
                "The normal force's error estimate under uniform refinement",
                ("goal_estimate.json",),
                (
                    Column("case", "case"),
                    Column("level", "level"),
                    Column("unknowns", "unknowns", integer),
                    Column("force", "force", scientific),
                    Column("estimate", "estimate", scientific),
                    Column("true error", "true_error", scientific),
                    Column("effectivity", "effectivity", fixed(2)),
                    Column("eff. P1 limit", "effectivity_p1", fixed(2)),
                    Column("P2 / estimate", "ratio", fixed(2)),
                    Column("wall s", "wall_s", significant),
                    Column("estimate s", "estimate_s", significant),
                    Column("P2 wall s", "wall_p2_s", significant),
                ),
            ),
        ),
    ),
    Section(
        "Adaptive refinement",
        "The 2D Hertz scene of the Hertz benchmark (linear elastic, one load step, the "
        "default eps, depth 0.005) from a coarse mesh (`h_contact = 0.04`, a/h = 1.3), "
        "refined by `cu.refine_to_tolerance` (Doerfler, theta = 0.5, the slave kept no "
        "coarser than the master, the arc's new nodes on the circle) and, for comparison, "
        "uniformly (every cell, the same loop). Errors against Hertz's closed form at the "
        "computed force: p0 and a of the profile fitted to the multipliers at the reference "
        "positions (*nominal*, as the small-strain solution compares), p0 of the pressure "
        "recovered from the bulk (`results.recovered_pressure`), the pressure's L2 error. "
        "*wall s*: the level's solve and estimate; *loop s*: the loop so far (solves, "
        "estimates, marking, refinement, the problems' set-up). *start*: the first mesh "
        "runs the load path, later ones start from the moved solution. *graded*: the "
        "hand-graded meshes of the Hertz benchmark's *graded* tables above (the zone of "
        "size h within 0.1 R; P2 on the curved mesh), solved one after another from the "
        "coarsest, as a user who does not know which mesh is fine enough would; their "
        "*loop s* is that sweep's time so far (meshing, set-up, solve). The same "
        "loop on the 3D Hertz scene, on Cattaneo-Mindlin (the stick zone's half-width "
        "and the shear traction against Johnson 7.1 at the last step) and on the plastic "
        "indentation (the imprint's depth: no closed form) follows.",
        "python benchmarks/adaptive.py [--degree 2] [--dim 3] [--case cattaneo|plastic] "
        "[--goal normal_force] [--load-steps N] [--max-unknowns N] --json FILE",
        tuple(
            Table(
                f"P{degree}",
                (f"adaptive_2d_p{degree}.json",),
                (
                    *LEVEL,
                    Column("p0 (nominal)", "p0_error_nominal", percent),
                    Column("p0 (recovered)", "p0_error_recovered", percent),
                    Column("a (nominal)", "a_error_nominal", percent),
                    Column("pressure L2", "pressure_l2_error", fixed(3)),
                    Column("Newton", "newton_iterations", integer),
                    Column("start", "start"),
                    *TIMES,
                ),
            )
            for degree in (1, 2)
        )
        + (
            Table(
                "P1, the normal contact force: the loop driven by the energy estimate "
                "(`goal` energy) and by the force's estimated error (`--goal normal_force`), "
                "against the force's limit measured by `benchmarks/goal_estimate.py` "
                "(*relative estimate*: of the loop's own estimate, the energy norm's or the "
                "force's)",
                ("adaptive_2d_p1.json", "adaptive_2d_p1_force.json"),
                (
                    *LEVEL,
                    Column("goal", "goal"),
                    Column("force", "force_error", percent),
                    Column("force effectivity", _force_effectivity, fixed(2)),
                    *TIMES,
                ),
            ),
            Table(
                "3D, P1 (the quarter ball on a block, depth 0.01, from h_contact = 0.05)",
                ("adaptive_3d_p1.json",),
                (
                    *LEVEL,
                    Column("p0 (nominal)", "p0_error_nominal", percent),
                    Column("a (nominal)", "a_error_nominal", percent),
                    Column("pressure L2", "pressure_l2_error", fixed(3)),
                    Column("Newton", "newton_iterations", integer),
                    Column("start", "start"),
                    *TIMES,
                ),
            ),
            Table(
                "Cattaneo-Mindlin (mu = 0.3, pressed in 4 steps, moved sideways in 4; every "
                "mesh replays them), from h_contact = 0.02",
                ("adaptive_cattaneo.json",),
                (
                    *LEVEL,
                    Column("Q / mu P", "Q_over_muP", fixed(3)),
                    Column("stick zone", "stick_zone_error", percent),
                    Column("shear error", "shear_error", fixed(3)),
                    Column("Newton (max a step)", _newton_total_max),
                    *TIMES,
                ),
            ),
            Table(
                "Cattaneo-Mindlin as above, pressed in 8 steps and moved sideways in 8 "
                "(`--load-steps 8`): the Newton iterations of a step against its size",
                ("adaptive_cattaneo_steps8.json",),
                (
                    *LEVEL,
                    Column("stick zone", "stick_zone_error", percent),
                    Column("Newton (max a step)", _newton_total_max),
                    Column("steps", "load_steps", integer),
                    *TIMES,
                ),
            ),
            Table(
                "Plastic indentation (a stiff disc pressed by 0.02 into a perfectly plastic "
                "block in 8 steps and lifted off in 8; every mesh replays them), from "
                "h_contact = 0.04",
                ("adaptive_plastic.json",),
                (
                    *LEVEL,
                    Column("imprint", "imprint", fixed(5)),
                    Column("Newton (max a step)", _newton_total_max),
                    *TIMES,
                ),
            ),
        ),
    ),
)
