"""The sections of the report on the choice of eps and on the other references: Cattaneo-
Mindlin, the Taylor test of the tangent, and the membrane tube between rigid plates.
"""

from report_sections.tables import (
    Column,
    Section,
    Table,
    _newton_max_mean,
    _range,
    fixed,
    integer,
    percent,
    scientific,
    significant,
)


def _cattaneo_rows(results) -> list[dict]:
    return [
        {"h": run["h"], "dofs": run["dofs"], **level} for run in results for level in run["levels"]
    ]


EPS_COLUMNS = (
    Column("h", "h_contact"),
    Column("unknowns", "dofs", integer),
    Column("eps", "eps"),
    Column("eps_N", "eps_N", significant),
    Column("Newton max/mean", _newton_max_mean),
    Column("cut-backs", "cutbacks", integer),
    Column("p0 error", "p0_error", percent),
    Column("force change", "force_change", scientific),
    Column("p0 change", "p0_change", scientific),
    Column("peak change", "peak_change", scientific),
    Column("wall s", "wall_s", significant),
)


SECTIONS = (
    Section(
        "Choosing eps",
        "The package's default `eps_N = E / L` (L the diameter of the slave surface; "
        "`eps_T = eps_N`) under refinement: the Newton iterations of the load step, and how "
        "much the answer moves when eps is 10 times larger or smaller, against the scenes' "
        "`E / h`. Hertz (linear elastic, one load step) in 2D and 3D, P1 and P2; *changes* "
        "are relative to the default on the same mesh. Friction: the Cattaneo-Mindlin scene "
        "(pressed in four steps, then slid in four, mu = 0.3) with `eps_T` 10 times larger "
        "and smaller; *c* is the stick zone's half-width against Johnson's solution, *shear* "
        "the RMS error of the shear traction in |x| < 0.8 a relative to mu p0.",
        "python benchmarks/eps_default.py [--dim 3] [--degree 2] [--h ...] --json FILE\n"
        "python benchmarks/eps_friction.py --json FILE",
        (
            Table("2D, P1", ("eps_default_2d.json",), EPS_COLUMNS),
            Table("2D, P2", ("eps_default_2d_p2.json",), EPS_COLUMNS),
            Table("3D, P1", ("eps_default_3d.json",), EPS_COLUMNS),
            Table(
                "3D, P2 (the finest mesh with the default and `E / h` only)",
                ("eps_default_3d_p2.json", "eps_default_3d_p2_fine.json"),
                EPS_COLUMNS,
            ),
            Table(
                "Friction, Cattaneo-Mindlin",
                ("eps_friction.json",),
                (
                    Column("h", "h_contact"),
                    Column("unknowns", "dofs", integer),
                    Column("case", "case"),
                    Column("Newton pressing", lambda r: _range(r["newton_press"])),
                    Column("Newton sliding", lambda r: _range(r["newton_slide"])),
                    Column("cut-backs", "cutbacks", integer),
                    Column("Q / (mu P)", "Q_over_muP", fixed(3)),
                    Column("c", "c_error", percent),
                    Column("shear", "shear_error", fixed(3)),
                    Column("Q change", "Q_change", scientific),
                    Column("c change", "c_change", scientific),
                    Column("wall s", "wall_s", significant),
                ),
            ),
        ),
    ),
    Section(
        "Cattaneo-Mindlin",
        "A Neo-Hookean half disc pressed on an identical block, then its top moved sideways "
        "in steps (Q < mu P): at each tangential load, the stick zone's half-width c against "
        "Johnson's `c = a sqrt(1 - Q / (mu P))` and the RMS error of the shear traction in "
        "|x| < 0.8 a relative to mu p0.",
        "python benchmarks/cattaneo_mindlin.py [--h ...] --json FILE",
        (
            Table(
                "Stick zone and shear traction",
                ("cattaneo_mindlin.json",),
                (
                    Column("h", "h"),
                    Column("unknowns", "dofs", integer),
                    Column("Q / (mu P)", "Q_over_muP", fixed(3)),
                    Column("c", "c", fixed(5)),
                    Column("c exact", "c_exact", fixed(5)),
                    Column("c error", "stick_zone_error", percent),
                    Column("shear error", "shear_error", fixed(3)),
                    Column("Newton", "newton_iterations", integer),
                ),
                rows=_cattaneo_rows,
            ),
        ),
    ),
    Section(
        "Taylor test of the tangent",
        "The observed convergence slopes of the full residual (bulk and contact, both "
        "bodies, the multipliers) along a direction: 2 for a consistent tangent, 1 with the "
        "projected point frozen (`--frozen`).",
        "python benchmarks/taylor.py [--frozen] --json FILE",
        (
            Table(
                "Slopes",
                ("taylor.json",),
                (
                    Column("dim", "dim"),
                    Column("frozen projection", "frozen_projection"),
                    Column("points in contact", "active_points", integer),
                    Column("slopes", lambda r: ", ".join(f"{s:.4f}" for s in r["slopes"])),
                    Column("facets changed", "facets_changed"),
                ),
            ),
        ),
    ),
    Section(
        "Membrane: an inflated tube between rigid plates",
        "A Neo-Hookean membrane tube inflated by a follower pressure, then pressed by a "
        "frictionless rigid plate (a quarter model; in 2D a string ring, in 3D a long tube), "
        "under refinement (n cells around the quarter), against the closed form: the "
        "relative errors of the contact width (from the free arc), of the contact pressure in "
        "the flat zone and of the plate force.",
        "python benchmarks/membrane.py [--quick] [--steps N] --json FILE",
        (
            Table(
                "Errors under refinement",
                ("membrane.json",),
                (
                    Column("dim", "dim"),
                    Column("n", "n", integer),
                    Column("unknowns", "unknowns", integer),
                    Column("steps", "steps", integer),
                    Column("cut-backs", "cutbacks", integer),
                    Column("Newton max/mean", _newton_max_mean),
                    Column("width", "width_error", scientific),
                    Column("pressure", "pressure_error", scientific),
                    Column("force", "force_error", scientific),
                    Column("wall s", "wall_s", significant),
                ),
            ),
        ),
    ),
)
