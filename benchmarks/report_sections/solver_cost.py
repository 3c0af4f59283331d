"""The sections of the report on the cost of a Newton iteration (against the free and the
glued bodies, on one rank and two) and on the linear solvers in 3D.
"""

from collections.abc import Callable

from report_sections.tables import (
    Column,
    Section,
    Table,
    _eps_label,
    _is_field_split,
    fixed,
    integer,
    milliseconds,
    significant,
    speedup,
)


def _by_case(case: str) -> Callable[[dict], bool]:
    return lambda r: r.get("case") == case


def _solvers_rows(results) -> list[dict]:
    """One row per size and case of a ``newton_cost.py --ranks 1 2`` file: on 1 and 2 ranks
    the wall time of the solve, the seconds per Newton iteration (of it the factorisation,
    the analysis and ``PtAP``) and the largest memory of a rank; the speed-up, and the load
    at the start of the one-rank run."""
    rows: dict[tuple, dict] = {}
    for r in results:
        row = rows.setdefault(
            (r["size"], r["case"]),
            {
                "size": r["size"],
                "case": r["case"],
                "dofs": r["dofs"],
                "newton": r["newton_iterations"],
                "field_split": _is_field_split(r),
            },
        )
        k = r["ranks"]
        row[f"wall_{k}"] = r.get("wall_s")
        row[f"per_it_{k}"] = r.get("total_s")
        row[f"factorisation_{k}"] = r.get("factorisation_s")
        row[f"analysis_{k}"] = r.get("analysis_s")
        row[f"ptap_{k}"] = r.get("ptap_s")
        row[f"rss_{k}"] = max(r["peak_rss_MB"]) if r.get("peak_rss_MB") else None
        if k > 1:
            row["speedup"] = r.get("speedup")
        if k == 1:
            row["load"] = r.get("load")
    return list(rows.values())


def _pair(row: dict, part: str) -> str:
    """A part's ms per iteration on one and on two ranks: ``2370 / 1612``."""
    return f"{milliseconds(row.get(f'{part}_1'))} / {milliseconds(row.get(f'{part}_2'))}"


def _per_rank_rows(results) -> list[dict]:
    """The contact record on two ranks of a ``--ranks 1 2`` file: its ranks' shares."""
    rows = []
    for r in results:
        if r.get("case") != "contact" or r.get("ranks") != 2:
            continue
        ranks = r["per_rank"]

        def both(key: str, ranks=ranks) -> str:
            return " / ".join(integer(p.get(key)) for p in ranks)

        rows.append(
            {
                "dofs": r["dofs"],
                "slave_points": both("slave_points"),
                "unknowns": both("unknowns"),
                "K_rows": both("K_rows"),
                "K_nonzeros": both("K_nonzeros"),
                "J_nonzeros": both("J_nonzeros"),
                "search": " / ".join(milliseconds(p.get("search_own_s")) for p in ranks),
            }
        )
    return rows


COST_COLUMNS = (
    Column("scene", "scene"),
    Column("size", "size"),
    Column("unknowns", "dofs", integer),
    Column("Newton", "newton_iterations", integer),
    Column("new pairings", "new_patterns", integer),
    Column("analyses after the first", "analyses", integer),
    Column("ms/it", "total_s", milliseconds),
    Column("search", "search_s", milliseconds),
    Column("residual", "residual_assembly_s", milliseconds),
    Column("Jacobian", "jacobian_assembly_s", milliseconds),
    Column("PtAP", "ptap_s", milliseconds),
    Column("linear solve", "linear_solve_s", milliseconds),
    Column("contact / bulk", "ratio", fixed(2)),
    Column("CPU ratio", "cpu_ratio", fixed(2)),
    Column("load", "load", fixed(1)),
)
GLUED_COLUMNS = (
    Column("scene", "scene"),
    Column("unknowns", "dofs", integer),
    Column("eps", _eps_label),
    Column("ranks", "ranks"),
    Column(
        "Newton (analyses after the first)",
        lambda r: f"{r['newton_iterations']} ({r['analyses']})",
    ),
    Column("contact ms/it", "total_s", milliseconds),
    Column("contact / glued", "glued_ratio", fixed(2)),
    Column("CPU contact / glued", "glued_cpu_ratio", fixed(2)),
    Column("contact / free bodies", "ratio", fixed(2)),
    Column("flops contact / glued", "factor_ratio", fixed(2)),
    Column("load", "load", fixed(1)),
)
NEWTON_COST_FILES = (
    "newton_cost_2d_glued.json",
    "newton_cost_2d_107k_parts.json",
    "newton_cost_50k_engaged_eps_h.json",
    "newton_cost_ranks_11k.json",
    "newton_cost_ranks_50k_split.json",
    "newton_cost_ranks_113k_fixed.json",
)
RANKS_FILES = (
    "newton_cost_ranks_11k.json",
    "newton_cost_ranks_50k_split.json",
    "newton_cost_ranks_113k_fixed.json",
)
SOLVER_COLUMNS = (
    Column("unknowns", "dofs", integer),
    Column("case", "case"),
    Column("Newton", "newton", integer),
    Column("1 rank, s", "wall_1", significant),
    Column("2 ranks, s", "wall_2", significant),
    Column("speed-up", "speedup", speedup),
    Column("memory 1 rank, MB", "rss_1", significant),
    Column("memory 2 ranks, MB", "rss_2", significant),
)


SECTIONS = (
    Section(
        "The cost of a Newton iteration",
        "What a Newton iteration costs with contact against the same mesh without it, from "
        "the solver's timers (ms per iteration, wall; the search, the residual and Jacobian "
        "assembly, `PtAP`, the linear solve with its symbolic analyses and numeric "
        "factorisations). *Bulk*: the two bodies free (Hertz: the cylinder's arc or the "
        "sphere's cap held fixed); *glued*: the same bodies glued where the contact pairs "
        "them (the displacement block of the final contact tangent), the fair baseline. The "
        "fastest of the repeated runs is kept; *load* is the load average at its start.",
        "python benchmarks/newton_cost.py [--scenes hertz beams hertz3d] [--sizes ...] "
        "[--glued] [--eps default] [--ranks 1 2] [--repeat N] --json FILE",
        (
            Table(
                "Contact against the free bodies, one rank (the contact runs)",
                ("newton_cost.json",),
                COST_COLUMNS,
                where=_by_case("contact"),
            ),
            Table(
                "Contact against the glued bodies (the contact runs)",
                NEWTON_COST_FILES,
                GLUED_COLUMNS,
                where=_by_case("contact"),
            ),
            Table(
                "One rank against two, 3D Hertz P1, ms per iteration",
                RANKS_FILES,
                (
                    Column("unknowns", "dofs", integer),
                    Column("case", "case"),
                    Column("Newton", "newton", integer),
                    Column("1 rank", "per_it_1", milliseconds),
                    Column("2 ranks", "per_it_2", milliseconds),
                    Column("speed-up of the solve", "speedup", speedup),
                    Column("factorisation 1 / 2", lambda r: _pair(r, "factorisation")),
                    Column("analysis 1 / 2", lambda r: _pair(r, "analysis")),
                    Column("PtAP 1 / 2", lambda r: _pair(r, "ptap")),
                    Column("load, 1 rank", "load", fixed(1)),
                ),
                rows=_solvers_rows,
            ),
            Table(
                "Where the work is on two ranks (rank 0 / rank 1; search: ms per iteration)",
                RANKS_FILES,
                (
                    Column("unknowns", "dofs", integer),
                    Column("slave points", "slave_points"),
                    Column("unknowns owned", "unknowns"),
                    Column("rows of K", "K_rows"),
                    Column("nonzeros of K", "K_nonzeros"),
                    Column("solver matrix nonzeros", "J_nonzeros"),
                    Column("own search", "search"),
                ),
                rows=_per_rank_rows,
            ),
        ),
    ),
    Section(
        "Linear solvers in 3D",
        "3D Hertz P1 (two load steps, the default eps) solved with MUMPS (the default) and "
        "with the package's iterative field split (`FIELD_SPLIT_PETSC_OPTIONS`), on one and "
        "two ranks: the wall time of the solve, the speed-up on two ranks and each rank "
        "count's largest resident memory of a rank. *bulk*: the same bodies free.",
        "python benchmarks/newton_cost.py --ranks 1 2 [--repeat N] --scenes hertz3d "
        "--sizes ... --eps default [--field-split] --json FILE",
        (
            Table("MUMPS", ("solvers_3d_mumps.json",), SOLVER_COLUMNS, rows=_solvers_rows),
            Table(
                "Field split",
                ("solvers_3d_field_split.json",),
                SOLVER_COLUMNS,
                rows=_solvers_rows,
            ),
            Table(
                "114,962 unknowns, the faster of two runs on each rank count",
                (
                    "solvers_3d_115k_mumps_best_of_2.json",
                    "solvers_3d_115k_field_split_best_of_2.json",
                ),
                (
                    Column("solver", lambda r: "field split" if r["field_split"] else "MUMPS"),
                    *SOLVER_COLUMNS,
                ),
                rows=_solvers_rows,
            ),
        ),
    ),
)
