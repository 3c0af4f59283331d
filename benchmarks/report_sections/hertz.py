"""The Hertz sections of the report: speed against error (with its figure), the scenes'
eps, several load steps, and P2's quadrature and multipliers.
"""

from pathlib import Path

from report_sections.tables import (
    Column,
    Figure,
    Section,
    Table,
    _eps_label,
    _is_field_split,
    fixed,
    general,
    integer,
    percent,
    significant,
)


def _mesh_edge(record: dict) -> str:
    return general(record.get("h_edge"))


HERTZ_SERIES = (
    ("hertz_2d_linear_1step_p1_wall.json", "2D P1", "o-", "p0_error_nominal", "a_error_nominal"),
    (
        "hertz_2d_linear_1step_p1_graded_wall.json",
        "2D P1, graded",
        "o:",
        "p0_error_nominal",
        "a_error_nominal",
    ),
    ("hertz_2d_linear_1step_p2_wall.json", "2D P2", "s-", "p0_error_nominal", "a_error_nominal"),
    (
        "hertz_2d_linear_1step_p2_graded_wall.json",
        "2D P2, graded",
        "s:",
        "p0_error_nominal",
        "a_error_nominal",
    ),
    ("hertz_3d_1step_p1_wall.json", "3D P1", "^-", "p0_error", "a_error"),
    ("hertz_3d_1step_p2_wall.json", "3D P2", "D-", "p0_error", "a_error"),
)


def draw_hertz(results: dict[str, object], path: Path) -> None:
    """|p0 error| and |a error| (nominal) of the Hertz series against the wall time of the
    solve and against the unknowns, log-log."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(2, 2, figsize=(10.0, 7.5), sharey="row")
    for k, (name, label, style, p0_key, a_key) in enumerate(HERTZ_SERIES):
        records = sorted(results[name], key=lambda r: r["dofs"])
        color = f"C{k}"
        for row, key in enumerate((p0_key, a_key)):
            error = [max(abs(r[key]), 1e-6) for r in records]
            axes[row, 0].loglog(
                [r["wall_s"] for r in records], error, style, color=color, label=label
            )
            axes[row, 1].loglog(
                [r["dofs"] for r in records], error, style, color=color, label=label
            )
    for row, what in enumerate(("|p0 error|", "|a error|")):
        axes[row, 0].set_ylabel(f"{what} against Hertz (nominal)")
    axes[1, 0].set_xlabel("wall time of the solve (s), one rank")
    axes[1, 1].set_xlabel("unknowns")
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
        ax.xaxis.set_minor_formatter(NullFormatter())
    axes[0, 1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100, metadata={"Software": None})
    plt.close(fig)


HERTZ_2D_COLUMNS = (
    Column("h", "h"),
    Column("unknowns", "dofs", integer),
    Column("a/h", "a_over_h", fixed(1)),
    Column("p0 (nominal)", "p0_error_nominal", percent),
    Column("p0 (Cauchy)", "p0_error", percent),
    Column("a (nominal)", "a_error_nominal", percent),
    Column("pressure L2", "pressure_l2_error", fixed(3)),
    Column("Newton", "newton_iterations", integer),
    Column("wall s", "wall_s", significant),
    Column("CPU s", "cpu_s", significant),
    Column("load", "load", fixed(1)),
)
HERTZ_3D_COLUMNS = (
    Column("h", "h_contact"),
    Column("h edge", _mesh_edge),
    Column("unknowns", "dofs", integer),
    Column("a/h", "a_over_h", fixed(1)),
    Column("p0", "p0_error", percent),
    Column("a", "a_error", percent),
    Column("pressure L2", "pressure_l2_error", fixed(3)),
    Column("largest node", "p0_node_error", percent),
    Column("Newton per step", "newton_per_step"),
    Column("wall s", "wall_s", significant),
    Column("search s", "search_s", significant),
)
HERTZ_STUDY_COLUMNS = (
    Column("u", lambda r: f"P{r['degree']}"),
    Column("multiplier", "multiplier_degree"),
    Column("rule", "subdivisions"),
    Column("zone", lambda r: r.get("refine_radius", 0.3)),
    Column("eps", _eps_label),
    Column("h", "h"),
    Column("unknowns", "dofs", integer),
    Column("a/h", "a_over_h", fixed(1)),
    Column("p0 (nominal)", "p0_error_nominal", percent),
    Column("a (nominal)", "a_error_nominal", percent),
    Column("p0 (Cauchy)", "p0_error", percent),
    Column("pressure L2", "pressure_l2_error", fixed(3)),
    Column("Newton", "newton_iterations", integer),
    Column("wall s", "wall_s", significant),
)


SECTIONS = (
    Section(
        "Hertz: speed against error",
        "A cylinder (2D, plane strain) or a sphere (3D, a quarter model) pressed on an elastic "
        "block: linear elastic, one load step, the package's default `eps_N = E / L`, on a "
        "sequence of meshes. The errors are those of the contact pressure's peak p0 and the "
        "contact half-width a against Hertz's solution at the computed force. *Nominal*: the "
        "elliptic profile fitted to the multiplier at the reference positions, which is what "
        "the small-strain Hertz solution describes (in 3D the p0 and a columns are this "
        "measure); *Cauchy*: the pressure at the current positions, which differs from it by "
        "the contact's large-deformation area change. *pressure L2*: the relative L2 error of "
        "the pressure profile; *largest node*: the largest nodal multiplier against p0. P2 "
        "runs on the curved (degree-2) mesh with P1 multipliers; *graded*: the mesh's zone of "
        "size h reaches 0.1 R instead of 0.3 R (`--refine-radius 0.1`). Times are of the "
        "solve on one rank, in 2D the fastest of the repeated solves in one process; *load* "
        "is the machine's 1-minute load average before the kept solve.",
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree {1,2} "
        "[--refine-radius 0.1] [--repeat N] --h ... --json FILE   (2D)\n"
        "python benchmarks/hertz.py --dim 3 --steps 1 --eps default --degree {1,2} --json FILE",
        (
            Table("2D, P1", ("hertz_2d_linear_1step_p1_wall.json",), HERTZ_2D_COLUMNS),
            Table(
                "2D, P1, graded", ("hertz_2d_linear_1step_p1_graded_wall.json",), HERTZ_2D_COLUMNS
            ),
            Table("2D, P2", ("hertz_2d_linear_1step_p2_wall.json",), HERTZ_2D_COLUMNS),
            Table(
                "2D, P2, graded", ("hertz_2d_linear_1step_p2_graded_wall.json",), HERTZ_2D_COLUMNS
            ),
            Table("3D, P1", ("hertz_3d_1step_p1_wall.json",), HERTZ_3D_COLUMNS),
            Table("3D, P2", ("hertz_3d_1step_p2_wall.json",), HERTZ_3D_COLUMNS),
            Table(
                "3D, P2 on one and two ranks, MUMPS and the field split",
                (
                    "hertz_3d_1step_p2_ranks1.json",
                    "hertz_3d_1step_p2_ranks2.json",
                    "hertz_3d_1step_p2_field_split_ranks1.json",
                    "hertz_3d_1step_p2_field_split_ranks2.json",
                ),
                (
                    Column("solver", lambda r: "field split" if _is_field_split(r) else "MUMPS"),
                    Column("ranks", "ranks"),
                    Column("unknowns", "dofs", integer),
                    Column("p0", "p0_error", percent),
                    Column("Newton", "newton_iterations", integer),
                    Column("wall s", "wall_s", significant),
                    Column("assembly s", "assembly_s", significant),
                    Column("linear solve s", "solver_s", significant),
                    Column("search s", "search_s", significant),
                ),
            ),
        ),
        (
            Figure(
                "hertz_speed_error.png",
                "Hertz, P1 and P2, 2D and 3D: the errors of p0 (top) and a (bottom), nominal, "
                "against the wall time of the solve (left) and the unknowns (right); one "
                "rank, one load step, the default eps.",
                "Errors of the Hertz peak pressure and half-width against wall time and unknowns",
                tuple(name for name, *_ in HERTZ_SERIES),
                draw_hertz,
            ),
        ),
    ),
    Section(
        "Hertz with the scenes' eps",
        "The 2D series of the previous section (one load step, linear elastic) with the "
        "scenes' `eps_N = E / h` in place of the package's default `E / L`. These records "
        "are older than those of the previous section (earlier code, a shared machine): "
        "compare their errors and Newton iterations with those, not their times.",
        "python benchmarks/hertz.py --material linear --steps 1 --degree {1,2} "
        "[--refine-radius 0.1] --h ... --json FILE",
        tuple(
            Table(
                caption,
                (name,),
                (
                    Column("h", "h"),
                    Column("unknowns", "dofs", integer),
                    Column("a/h", "a_over_h", fixed(1)),
                    Column("eps_N", "eps_N", significant),
                    Column("p0 (nominal)", "p0_error_nominal", percent),
                    Column("p0 (Cauchy)", "p0_error", percent),
                    Column("Newton", "newton_iterations", integer),
                    Column("CPU s", "cpu_s", significant),
                    Column("wall s", "wall_s", significant),
                ),
            )
            for caption, name in (
                ("2D, P1", "hertz_2d_linear_1step_p1_eps_h.json"),
                ("2D, P1, graded", "hertz_2d_linear_1step_p1_graded_eps_h.json"),
                ("2D, P2", "hertz_2d_linear_1step_p2_eps_h.json"),
                ("2D, P2, graded", "hertz_2d_linear_1step_p2_graded_eps_h.json"),
            )
        ),
    ),
    Section(
        "Hertz in several load steps",
        "The configuration of the tests: the scenes' `eps_N = E / h`, in 2D a Neo-Hookean or "
        "linear elastic cylinder in four load steps, in 3D the linear elastic sphere in two "
        "(on an elastic block, or on a rigid flat), P1 and P2. In 2D p0 and a are the Cauchy "
        "measure (the nominal one is in the one-step records above); in 3D the nominal one.",
        "python benchmarks/hertz.py [--material linear] --json FILE   (2D)\n"
        "python benchmarks/hertz.py --dim 3 [--degree 2] [--flat rigid] "
        "[--multiplier-degree iso] --json FILE",
        (
            Table(
                "2D, P1, Neo-Hookean and linear elastic, four load steps",
                ("hertz.json", "hertz_linear.json"),
                (
                    Column("material", "material"),
                    Column("h", "h"),
                    Column("unknowns", "dofs", integer),
                    Column("a/h", "a_over_h", fixed(1)),
                    Column("p0 (Cauchy)", "p0_error", percent),
                    Column("a (Cauchy)", "a_error", percent),
                    Column("pressure L2", "pressure_l2_error", fixed(3)),
                    Column("Newton per step", "newton_per_step"),
                    Column("wall s", "wall_s", significant),
                    Column("linear solve s", "solver_s", significant),
                ),
            ),
            Table(
                "3D, two load steps",
                (
                    "hertz_3d.json",
                    "hertz_3d_rigid.json",
                    "hertz_3d_p2.json",
                    "hertz_3d_p2_iso.json",
                ),
                (
                    Column("u", lambda r: f"P{r.get('degree', 1)}"),
                    Column("multiplier", lambda r: r.get("multiplier_degree", 1)),
                    Column("flat", lambda r: r.get("flat", "elastic")),
                    *HERTZ_3D_COLUMNS,
                ),
            ),
        ),
    ),
    Section(
        "Hertz with P2: quadrature and multipliers",
        "One load step, linear elastic, in 2D: P1 against P2 with the contact rule on the "
        "slave facets as it is (*rule* 1) and on facets split in 4 or 8 (`--subdivisions`), "
        "on the mesh of the default zone (0.3 R) and on the graded one (0.1 R); P1 "
        "multipliers against P1-iso-P2 ones (`--multiplier-degree iso`); *zone*: the size of "
        "the mesh's zone of size h, in units of R; *eps*: the scenes' `E / h` or the "
        "package's default `E / L`. "
        "Last, 3D P2 on the straight (faceted) mesh of the ball, which the benchmark used "
        "before it moved to the curved one.",
        "python benchmarks/hertz.py --material linear --steps 1 --degree {1,2} "
        "[--subdivisions N] [--multiplier-degree iso] [--refine-radius 0.1] [--eps default] "
        "--h ... --json FILE",
        (
            Table(
                "2D, the contact rule",
                (
                    "hertz_linear_1step_p1_s1.json",
                    "hertz_linear_1step_p1_s4.json",
                    "hertz_linear_1step_p2_s1.json",
                    "hertz_linear_1step_p2_s4.json",
                ),
                HERTZ_STUDY_COLUMNS,
            ),
            Table(
                "2D, the graded mesh",
                (
                    "hertz_linear_1step_refine01_p1_s1.json",
                    "hertz_linear_1step_refine01_p2_s1.json",
                ),
                HERTZ_STUDY_COLUMNS,
            ),
            Table(
                "2D, P1 and P1-iso-P2 multipliers",
                (
                    "hertz_linear_1step_p2_iso_eps_default.json",
                    "hertz_linear_1step_p2_iso_h002.json",
                ),
                HERTZ_STUDY_COLUMNS,
            ),
            Table(
                "3D, P2 on the straight mesh, one load step",
                ("hertz_3d_1step_p2.json",),
                HERTZ_3D_COLUMNS,
            ),
        ),
    ),
)
