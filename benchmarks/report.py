"""The benchmark report: ``docs/benchmarks.md`` generated from ``benchmarks/results/*.json``.

Every results file (written by :func:`resultfile.write`, see ``benchmarks/resultfile.py``)
belongs to one table of :data:`SECTIONS`; a table lists the key columns of its files'
records and, under it, each file's stamp (commit, date, machine, ranks) and the command that
makes it again. A results file that no table names, or a table's file that is missing or
has no stamp, is an error: the page always shows every result there is, and only those.

    python benchmarks/report.py            # docs/benchmarks.md and its figures
    python benchmarks/report.py --check    # exit 1 if docs/benchmarks.md is not up to date

The page depends on nothing but the results files (no date or machine of the report's own
run), so running it again on unchanged results gives the same page. The figures (PNG,
matplotlib's Agg backend) go to ``docs/benchmarks/``.
"""

import argparse
import math
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import resultfile

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
PAGE = ROOT / "docs" / "benchmarks.md"
#: the figures' folder, and its path as the page refers to it
FIGURES = ROOT / "docs" / "benchmarks"
FIGURES_LINK = "benchmarks"


# -- formats: a value of a record to the text of a cell ("-" where there is none) ---------------
def _missing(x) -> bool:
    return x is None or (isinstance(x, float) and math.isnan(x))


def percent(x, digits: int = 2) -> str:
    """A relative error as a signed percentage: ``+0.23%``."""
    return "-" if _missing(x) else f"{100.0 * x:+.{digits}f}%"


def significant(x, n: int = 3) -> str:
    """``n`` significant digits, trailing zeros kept, without an exponent down to 1e-4:
    ``0.0120``, ``12.0``, ``1,230``."""
    if _missing(x):
        return "-"
    if x == 0:
        return "0"
    rounded = float(f"{x:.{n}g}")
    if abs(rounded) >= 10 ** (n - 1):
        return f"{rounded:,.0f}"
    if abs(rounded) < 1e-4:
        return scientific(x, n - 1)
    return f"{rounded:#.{n}g}"


def scientific(x, digits: int = 2) -> str:
    """``x`` as ``1.24e6``."""
    if _missing(x):
        return "-"
    if x == 0:
        return "0"
    mantissa, exponent = f"{x:.{digits}e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def integer(x) -> str:
    """An integer with thousands separators: ``12,516``."""
    return "-" if _missing(x) else f"{int(x):,}"


def fixed(digits: int) -> Callable:
    """A number with ``digits`` decimals."""
    return lambda x: "-" if _missing(x) else f"{x:.{digits}f}"


def general(x) -> str:
    """Python's shortest form of a number (mesh sizes: ``0.0035``), or the text of a value."""
    if _missing(x):
        return "-"
    return f"{x:g}" if isinstance(x, float) else str(x)


def milliseconds(x) -> str:
    """Seconds as milliseconds, three significant digits."""
    return "-" if _missing(x) else significant(1e3 * x)


def share(x) -> str:
    """A fraction as a whole percentage: ``64%``."""
    return "-" if _missing(x) else f"{100.0 * x:.0f}%"


def speedup(x) -> str:
    """A ratio of times as ``1.57x``."""
    return "-" if _missing(x) else f"{x:.2f}x"


# -- the page's building blocks ----------------------------------------------------------------
@dataclass(frozen=True)
class Column:
    """A column: its ``header``, the record's value (a key, or a function of the record)
    and the format of a cell."""

    header: str
    value: str | Callable[[dict], object]
    format: Callable[[object], str] = general

    def cell(self, record: dict) -> str:
        value = record.get(self.value) if isinstance(self.value, str) else self.value(record)
        return self.format(value)


def _records(results) -> list[dict]:
    """The records of a results file: the list itself, or its ``records`` or ``cases``."""
    if isinstance(results, list):
        return results
    return results.get("records", results.get("cases", []))


@dataclass(frozen=True)
class Table:
    """A table of the records of ``files`` (in order): ``rows`` makes the rows of one
    file's results (default: its records), ``where`` keeps some of them."""

    caption: str
    files: tuple[str, ...]
    columns: tuple[Column, ...]
    rows: Callable[[object], list[dict]] = _records
    where: Callable[[dict], bool] | None = None

    def table_rows(self, results: dict[str, object]) -> list[dict]:
        rows = [r for name in self.files for r in self.rows(results[name])]
        return [r for r in rows if self.where is None or self.where(r)]


@dataclass(frozen=True)
class Figure:
    """A figure of the records of ``files``, drawn by ``draw(results, path)``."""

    name: str
    caption: str
    alt: str
    files: tuple[str, ...]
    draw: Callable[[dict[str, object], Path], None]


@dataclass(frozen=True)
class Section:
    """A benchmark: what it measures (``text``, Markdown), how to run it (``usage``: the
    script's command line), its figures and tables."""

    title: str
    text: str
    usage: str
    tables: tuple[Table, ...]
    figures: tuple[Figure, ...] = ()


# -- record helpers ------------------------------------------------------------------------------
def _mesh_edge(record: dict) -> str:
    return general(record.get("h_edge"))


def _eps_label(record: dict) -> str:
    """The eps of a Hertz or Newton-cost record: ``E / L`` (the package's default) or
    ``E / h`` (the scenes', also where the record predates the choice)."""
    return "E / L" if record.get("eps") == "default" else "E / h"


def _newton_max_mean(record: dict) -> str:
    if "newton_max" not in record:
        return "-"
    return f"{record['newton_max']}/{record['newton_mean']:.1f}"


def _hard_case_end(record: dict) -> str:
    status = record.get("status", "")
    if status == "completed":
        return "completed"
    if status in ("stopped", "expected stop"):
        why = (record.get("diagnosis") or "").split(":")[0]
        why = "active-set cycling" if "cycles" in why else why
        why = "limit point" if record.get("expected_stop") == "limit point" else why
        return f"{status} at t = {record['t_reached']:.3g}" + (f" ({why})" if why else "")
    return status


def _ironing_rows(results) -> list[dict]:
    rows = []
    for run in results:
        steps = run["history"]
        energy = run.get("steady_energy")
        mismatch = None
        if energy and energy["work"]:
            mismatch = (energy["work"] - energy["dissipation"] - energy["stored"]) / energy["work"]
        rows.append(
            {
                **run,
                "mesh": f"{run.get('h_punch', '-')} / {run.get('h_block', '-')}",
                "steps": len(steps),
                "cutback_count": len(run["cutbacks"]),
                "newton": sum(s["newton_iterations"] for s in steps),
                "newton_range": _range(s["newton_iterations"] for s in steps),
                "energy_mismatch": mismatch,
            }
        )
    return rows


def _range(values: Iterable[int]) -> str:
    values = list(values)
    return f"{min(values)}-{max(values)}" if values else "-"


def _force_at(run: dict, t: float, key: str):
    step = min(run["history"], key=lambda s: abs(s["time"] - t))
    return step.get(key)


def _ironing_3d_rows(results) -> list[dict]:
    rows = _ironing_rows(results)
    for row, run in zip(rows, results, strict=True):
        row["mesh"] = f"{run['h_die']:g} / {run['h_slab']:g}"
        row["Fz_1"] = _force_at(run, 1.0, "Fz")
        row["Fz_15"] = _force_at(run, 1.5, "Fz")
        row["Fx_15"] = _force_at(run, 1.5, "Fx")
    return rows


def _plane_strain_rows(results) -> list[dict]:
    rows = _ironing_rows(results)
    for row in rows:
        row["run"] = "2D" if row.get("thickness") is None else "extruded"
        difference = row.get("difference_to_2d", {})
        row["fx_difference"] = difference.get("fx")
        row["fy_difference"] = difference.get("fy")
    return rows


def _cattaneo_rows(results) -> list[dict]:
    return [
        {"h": run["h"], "dofs": run["dofs"], **level} for run in results for level in run["levels"]
    ]


def _search_pivot(
    sweep: str, row_keys: tuple[str, ...], column_key: str, value_key: str
) -> Callable[[object], list[dict]]:
    """Rows of one ``sweep`` of a search results file, one per value of ``row_keys``, a
    column per value of ``column_key`` (named ``column_key=value``) holding ``value_key``."""

    def rows(results) -> list[dict]:
        table: dict[tuple, dict] = {}
        for r in _records(results):
            if r.get("sweep") != sweep:
                continue
            key = tuple(r.get(k) for k in row_keys)
            row = table.setdefault(key, {k: r.get(k) for k in row_keys})
            row[f"{column_key}={_key(r.get(column_key))}"] = r.get(value_key)
        return list(table.values())

    return rows


def _key(value) -> str:
    return "inf" if value is None or value == math.inf else f"{value:g}"


def _pivot_columns(column_key: str, values: Iterable, header: Callable[[object], str]):
    return tuple(Column(header(v), f"{column_key}={_key(v)}", scientific) for v in values)


def _radius_header(value) -> str:
    return "radius inf" if value is None else f"radius {value:g} h"


def _sweep(name: str) -> Callable[[dict], bool]:
    return lambda r: r.get("sweep") == name


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


def _is_field_split(record: dict) -> bool:
    options = record.get("options") or record.get("petsc_options") or {}
    return isinstance(options, dict) and options.get("pc_type") == "fieldsplit"


def _pair(row: dict, part: str) -> str:
    """A part's ms per iteration on one and on two ranks: ``2370 / 1612``."""
    return f"{milliseconds(row.get(f'{part}_1'))} / {milliseconds(row.get(f'{part}_2'))}"


def _distance_rows(results) -> list[dict]:
    """The ``distance`` sweep: a row per facet kind and distance of the points, a column per
    radius over that distance (``factor=2``, ``factor=10``, ``factor=inf``)."""
    table: dict[tuple, dict] = {}
    for r in _records(results):
        if r.get("sweep") != "distance":
            continue
        offset = r["offset_over_h"]
        row = table.setdefault(
            (r["kind"], r["facets"], offset),
            {"kind": r["kind"], "facets": r["facets"], "offset_over_h": offset},
        )
        radius = r.get("radius_over_h")
        factor = "inf" if radius is None else f"{radius / offset:.0f}"
        row[f"factor={factor}"] = r.get("cpu_points_per_s")
    return list(table.values())


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


# -- the figures -------------------------------------------------------------------------------
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


# -- the catalogue -------------------------------------------------------------------------------
#: the command that makes each file again, shown where its stamp has none (stamps rebuilt from
#: the history); a run's stamp has its own
COMMANDS = {
    "cattaneo_mindlin.json": "python benchmarks/cattaneo_mindlin.py --json {path}",
    "eps_default_2d.json": "python benchmarks/eps_default.py --json {path}",
    "eps_default_2d_p2.json": "python benchmarks/eps_default.py --degree 2 --json {path}",
    "eps_default_3d.json": "python benchmarks/eps_default.py --dim 3 --json {path}",
    "eps_default_3d_p2.json": "python benchmarks/eps_default.py --dim 3 --degree 2 --json {path}",
    "eps_default_3d_p2_fine.json": (
        "python benchmarks/eps_default.py --dim 3 --degree 2 --h 0.0175 --json {path}"
    ),
    "eps_friction.json": "python benchmarks/eps_friction.py --json {path}",
    "hard_cases.json": "python benchmarks/hard_cases.py --json {path}",
    "hard_cases_quick.json": "python benchmarks/hard_cases.py --quick --json {path}",
    "hertz.json": "python benchmarks/hertz.py --json {path}",
    "hertz_linear.json": "python benchmarks/hertz.py --material linear --json {path}",
    "hertz_2d_linear_1step_p1_wall.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree 1"
        " --repeat 3 --h 0.02 0.015 0.01 0.0075 0.005 0.0035 --json {path}"
    ),
    "hertz_2d_linear_1step_p1_graded_wall.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree 1"
        " --refine-radius 0.1 --repeat 3 --h 0.01 0.0075 0.005 0.0035 0.0025 0.00175"
        " --json {path}"
    ),
    "hertz_2d_linear_1step_p2_wall.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree 2"
        " --repeat 3 --h 0.04 0.03 0.025 0.0225 0.02 0.015 0.01 --json {path}"
    ),
    "hertz_2d_linear_1step_p2_graded_wall.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree 2"
        " --refine-radius 0.1 --repeat 3 --h 0.03 0.025 0.02 0.015 0.01 0.0075 --json {path}"
    ),
    "hertz_2d_linear_1step_p1_eps_h.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1"
        " --h 0.02 0.015 0.01 0.0075 0.005 0.0035 --json {path}"
    ),
    "hertz_2d_linear_1step_p1_graded_eps_h.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1 --refine-radius 0.1"
        " --h 0.01 0.0075 0.005 0.0035 0.0025 0.00175 --json {path}"
    ),
    "hertz_2d_linear_1step_p2_eps_h.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2"
        " --h 0.04 0.03 0.025 0.0225 0.02 0.015 0.01 --json {path}"
    ),
    "hertz_2d_linear_1step_p2_graded_eps_h.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --refine-radius 0.1"
        " --h 0.03 0.025 0.02 0.015 0.01 0.0075 --json {path}"
    ),
    "hertz_3d.json": "python benchmarks/hertz.py --dim 3 --json {path}",
    "hertz_3d_rigid.json": "python benchmarks/hertz.py --dim 3 --flat rigid --json {path}",
    "hertz_3d_p2.json": "python benchmarks/hertz.py --dim 3 --degree 2 --json {path}",
    "hertz_3d_p2_iso.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 [--multiplier-degree iso] --h 0.05 0.035"
        " --json {path}"
    ),
    "hertz_3d_1step_p1_wall.json": (
        "python benchmarks/hertz.py --dim 3 --steps 1 --eps default --json {path}"
    ),
    "hertz_3d_1step_p2_wall.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default --json {path}"
    ),
    "hertz_3d_1step_p2.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default"
        " --h 0.1 0.07 0.05 0.04 --json {path}  (now on the curved mesh)"
    ),
    "hertz_3d_1step_p2_ranks1.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default --h 0.025"
        " --h-edge 0.01 --json {path}"
    ),
    "hertz_3d_1step_p2_ranks2.json": (
        "mpirun -n 2 python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default"
        " --h 0.025 --h-edge 0.01 --json {path}"
    ),
    "hertz_3d_1step_p2_field_split_ranks1.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default --h 0.025"
        " --h-edge 0.01 --field-split --json {path}"
    ),
    "hertz_3d_1step_p2_field_split_ranks2.json": (
        "mpirun -n 2 python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default"
        " --h 0.025 --h-edge 0.01 --field-split --json {path}"
    ),
    "hertz_linear_1step_p1_s1.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1"
        " --h 0.02 0.01 0.0075 0.005 0.0025 --json {path}"
    ),
    "hertz_linear_1step_p1_s4.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1 --subdivisions 4"
        " --h 0.02 0.01 0.0075 0.005 --json {path}"
    ),
    "hertz_linear_1step_p2_s1.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2"
        " --h 0.04 0.03 0.025 0.02 0.01 --json {path}"
    ),
    "hertz_linear_1step_p2_s4.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --subdivisions 4"
        " --h 0.04 0.03 0.025 0.02 0.01 --json {path}"
    ),
    "hertz_linear_1step_refine01_p1_s1.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1 --refine-radius 0.1"
        " --h 0.01 0.005 0.0035 0.0025 --json {path}"
    ),
    "hertz_linear_1step_refine01_p2_s1.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --refine-radius 0.1"
        " --h 0.02 0.015 0.01 0.0075 --json {path}"
    ),
    "hertz_linear_1step_p2_iso_eps_default.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --eps default"
        " [--multiplier-degree iso] [--subdivisions 4] [--refine-radius 0.1] --h ... --json {path}"
    ),
    "hertz_linear_1step_p2_iso_h002.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --h 0.02"
        " [--multiplier-degree iso] [--subdivisions 8] --json {path}"
    ),
    "ironing.json": "python benchmarks/ironing.py --json {path}",
    "ironing_quick.json": "python benchmarks/ironing.py --quick --json {path}",
    "ironing_3d_quick.json": (
        "python benchmarks/ironing_3d.py --quick --json {path} --png docs/ironing_3d_forces.png"
    ),
    "ironing_plane_strain_quick.json": (
        "python benchmarks/ironing_plane_strain.py --quick --json {path}"
    ),
    "membrane.json": "python benchmarks/membrane.py --json {path}",
    "newton_cost.json": "python benchmarks/newton_cost.py --repeat 2 --json {path}",
    "newton_cost_2d_glued.json": (
        "python benchmarks/newton_cost.py --scenes hertz --sizes 0.01 0.005 0.0025 --glued"
        " --repeat 3 --json {path}"
    ),
    "newton_cost_2d_107k_parts.json": (
        "python benchmarks/newton_cost.py --scenes hertz --sizes 0.0023 --glued --repeat 2"
        " --json {path}"
    ),
    "newton_cost_50k_engaged_eps_h.json": (
        "python benchmarks/newton_cost.py --scenes hertz3d --sizes 0.00625 --glued --json {path}"
    ),
    "newton_cost_ranks_11k.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 2 --scenes hertz3d --sizes 0.0125"
        " --glued --json {path}"
    ),
    "newton_cost_ranks_50k_split.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 2 --scenes hertz3d"
        " --sizes 0.00625 --glued --eps default --json {path}"
    ),
    "newton_cost_ranks_113k_fixed.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 1 --scenes hertz3d --sizes 0.0045"
        " --glued --eps default --json {path}"
    ),
    "search.json": (
        "python benchmarks/search.py --sweeps graded self_contact radius distance points"
        " --json {path}"
    ),
    "search_points.json": "python benchmarks/search.py --sweeps points --json {path}",
    "search_quadratic.json": "python benchmarks/search.py --sweeps quadratic --json {path}",
    "search_scenes.json": "python benchmarks/search.py --sweeps scenes --json {path}",
    "smoothed_normal_3d.json": "python benchmarks/smoothed_normal_3d.py --json {path}",
    "solvers_3d_mumps.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --scenes hertz3d"
        " --sizes 0.0125 0.00625 0.0045 --eps default --json {path}"
    ),
    "solvers_3d_field_split.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --scenes hertz3d"
        " --sizes 0.0125 0.00625 0.0045 --eps default --field-split --json {path}"
    ),
    "solvers_3d_115k_mumps_best_of_2.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 2 --scenes hertz3d --sizes 0.0045"
        " --eps default --json {path}"
    ),
    "solvers_3d_115k_field_split_best_of_2.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 2 --scenes hertz3d --sizes 0.0045"
        " --eps default --field-split --json {path}"
    ),
    "taylor.json": "python benchmarks/taylor.py --json {path}",
}

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
RADII = (1.0, 10.0, 100.0, None)

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
    Section(
        "Ironing",
        "Large frictional sliding. The shallow ironing of Yang, Laursen & Meng (2005): a "
        "Neo-Hookean block 12 x 4 and a ten times stiffer indenter with a rounded bottom, "
        "pressed 1.0 and slid 10, mu = 0 and 0.3, the smoothed master normal; |Fx/Fy| in "
        "steady sliding (1.2 <= t <= 1.7), its frictional part, and the mismatch of the "
        "energy balance over it (work against frictional dissipation plus stored energy). "
        "The same problem on a 3D mesh of one layer of hexahedra in plane strain, against "
        "the 2D run on the same plane mesh (the largest difference of the forces over the "
        "history, relative to the largest |fy|). The 3D ironing of Puso & Laursen (2004, "
        "example 2): a die with a cylindrical bottom pressed 1.4 into a slab and slid 4; the "
        "forces of the support on the die and the frictional force over the normal one in "
        "steady sliding.",
        "python benchmarks/ironing.py [--quick] --json FILE\n"
        "python benchmarks/ironing_plane_strain.py [--quick] --json FILE\n"
        "python benchmarks/ironing_3d.py [--quick] [--png FILE] --json FILE",
        (
            Table(
                "2D (mesh: h of the indenter / of the block)",
                ("ironing_quick.json", "ironing.json"),
                (
                    Column("mesh", "mesh"),
                    Column("mu", "mu"),
                    Column("unknowns", "unknowns", integer),
                    Column("steps", "steps", integer),
                    Column("cut-backs", "cutback_count", integer),
                    Column("Newton", "newton", integer),
                    Column("wall s", "wall_s", significant),
                    Column("abs(Fx/Fy)", "steady_abs_Fx_over_Fy", fixed(3)),
                    Column("friction part", "steady_friction_part", fixed(3)),
                    Column("energy mismatch", "energy_mismatch", percent),
                ),
                rows=_ironing_rows,
            ),
            Table(
                "Plane strain: 2D and extruded",
                ("ironing_plane_strain_quick.json",),
                (
                    Column("mu", "mu"),
                    Column("run", "run"),
                    Column("unknowns", "unknowns", integer),
                    Column("steps", "steps", integer),
                    Column("cut-backs", "cutback_count", integer),
                    Column(
                        "Newton (per step)",
                        lambda r: f"{integer(r['newton'])} ({r['newton_range']})",
                    ),
                    Column("wall s", "wall_s", significant),
                    Column("abs(fx/fy)", "steady_abs_fx_over_fy", fixed(3)),
                    Column("fx difference", "fx_difference", scientific),
                    Column("fy difference", "fy_difference", scientific),
                ),
                rows=_plane_strain_rows,
            ),
            Table(
                "3D (mesh: h of the die / of the slab)",
                ("ironing_3d_quick.json",),
                (
                    Column("mesh", "mesh"),
                    Column("mu", "mu"),
                    Column("unknowns", "unknowns", integer),
                    Column("steps", "steps", integer),
                    Column("cut-backs", "cutback_count", integer),
                    Column(
                        "Newton (per step)",
                        lambda r: f"{integer(r['newton'])} ({r['newton_range']})",
                    ),
                    Column("wall s", "wall_s", significant),
                    Column("Fz(1.0)", "Fz_1", fixed(2)),
                    Column("Fz(1.5)", "Fz_15", fixed(2)),
                    Column("Fx(1.5)", "Fx_15", fixed(3)),
                    Column("friction / normal", "coulomb_ratio", fixed(4)),
                ),
                rows=_ironing_3d_rows,
            ),
        ),
    ),
    Section(
        "The smoothed master normal in 3D",
        "Newton iterations with the facet and the smoothed master normal on curved 3D "
        "masters (tetrahedra: a half cylinder on a cylindrical top; hexahedra: warped "
        "boxes), the upper body pressed down and slid over the master surface.",
        "python benchmarks/smoothed_normal_3d.py [--steps N] --json FILE",
        (
            Table(
                "Facet and smoothed normal",
                ("smoothed_normal_3d.json",),
                (
                    Column("cells", "cell"),
                    Column("master normal", "master_normal"),
                    Column("master nodes per point", "nodes_per_point", integer),
                    Column("end", lambda r: f"{r['status']} at t = {r['t_reached']:.3g}"),
                    Column("Newton per step", lambda r: ", ".join(map(str, r["newton_per_step"]))),
                    Column("cut-backs", "cutbacks", integer),
                    Column("points in contact", "active_points", integer),
                    Column("wall s", "wall_s", significant),
                ),
            ),
        ),
    ),
    Section(
        "Hard cases",
        "The suite of hard cases: 2D ironing, the two beams, force-driven contact, deep "
        "indentation with the facet and the smoothed master normal, a ring squeezed until its "
        "hole closes on itself, and a balloon past its pressure maximum under volume control "
        "and under load control (expected to stop at the limit point). Steps, cut-backs, "
        "Newton iterations per accepted step and how each case ended. `--quick` runs coarser "
        "meshes with larger steps, and of the deep indentations only the coarsest 2D one.",
        "python benchmarks/hard_cases.py [--quick] [--cases NAME ...] --json FILE",
        tuple(
            Table(
                caption,
                (name,),
                (
                    Column("case", "name"),
                    Column("unknowns", "unknowns", integer),
                    Column("steps", "steps", integer),
                    Column("cut-backs", "cutbacks", integer),
                    Column("Newton max/mean", _newton_max_mean),
                    Column("end", _hard_case_end),
                    Column("wall s", "wall_s", significant),
                ),
            )
            for caption, name in (
                ("The quick suite", "hard_cases_quick.json"),
                ("The full suite", "hard_cases.json"),
            )
        ),
    ),
    Section(
        "Closest-point search",
        "The closest-point search alone (`projection.closest_points`, one core), in CPU "
        "points per second of one process. Synthetic masters: a wavy surface of segments "
        "(2D), triangles or bilinear quadrilaterals (3D), slave points on a perturbed copy "
        "of it, search radius h (about half the points paired) to infinite (all paired); the "
        "points' distance at fixed radii; quadratic facets (3-node segments, 6-node "
        "triangles, 9-node quadrilaterals); the number of points on a master of 1e6 facets, "
        "unchanged between calls or moved at every call (as in a Newton iteration, where "
        "each call refits the tree), and the per-point and per-call cost fitted to it. The "
        "whole pairing of a Newton iteration on the Hertz scenes (the fastest and the median "
        "of 100 calls; *kernel*: the share of the closest-point kernel).",
        "python benchmarks/search.py [--quick] [--largest N] "
        "[--sweeps graded self_contact radius distance points quadratic scenes] --json FILE",
        (
            Table(
                "Radius (`radius` sweep), CPU points/s",
                ("search.json",),
                (
                    Column("facets", "kind"),
                    Column("number", "facets", integer),
                    *_pivot_columns("radius_over_h", RADII, _radius_header),
                ),
                rows=_search_pivot(
                    "radius", ("kind", "facets"), "radius_over_h", "cpu_points_per_s"
                ),
            ),
            Table(
                "Distance of the points (`distance` sweep), CPU points/s",
                ("search.json",),
                (
                    Column("facets", "kind"),
                    Column("number", "facets", integer),
                    Column("distance / h", "offset_over_h"),
                    Column("radius 2x", "factor=2", scientific),
                    Column("radius 10x", "factor=10", scientific),
                    Column("radius inf", "factor=inf", scientific),
                ),
                rows=_distance_rows,
            ),
            Table(
                "A graded master and self-contact, CPU seconds of the second call",
                ("search.json",),
                (
                    Column("sweep", "sweep"),
                    Column("facets", "facets", integer),
                    Column("of them large", lambda r: r.get("large_facets", "-")),
                    Column("points", "points", integer),
                    Column("radius", lambda r: general(r.get("radius", math.inf))),
                    Column("paired", "paired_fraction", fixed(2)),
                    Column("first call s", "first_call_s", significant),
                    Column("second call s", "second_call_s", significant),
                ),
                where=lambda r: r.get("sweep") in ("graded", "self_contact"),
            ),
            Table(
                "Number of points on 1e6 facets (`points` sweep), CPU points/s",
                ("search_points.json",),
                (
                    Column("facets", "kind"),
                    Column("master", "master"),
                    *_pivot_columns("points", (10_000, 50_000, 200_000, 1_000_000), integer),
                ),
                rows=_search_pivot("points", ("kind", "master"), "points", "cpu_points_per_s"),
            ),
            Table(
                "Fitted per-point rate and per-call cost",
                ("search_points.json",),
                (
                    Column("facets", "kind"),
                    Column("master", "master"),
                    Column("points/s", "per_point_rate", scientific),
                    Column("ms per call", "per_call_s", milliseconds),
                ),
                where=_sweep("points_fit"),
            ),
            Table(
                "Quadratic facets (`quadratic` sweep), CPU points/s",
                ("search_quadratic.json",),
                (
                    Column("facets", "kind"),
                    Column("number", "facets", integer),
                    *_pivot_columns("radius_over_h", (1.0, None), _radius_header),
                ),
                rows=_search_pivot(
                    "quadratic", ("kind", "facets"), "radius_over_h", "cpu_points_per_s"
                ),
            ),
            Table(
                "The pairing of a Newton iteration (`scenes` sweep)",
                ("search_scenes.json",),
                (
                    Column("scene", "scene"),
                    Column("degree", "degree"),
                    Column("unknowns", "dofs", integer),
                    Column("slave points", "points", integer),
                    Column("master facets", "master_facets", integer),
                    Column("ms, fastest", "cpu_seconds", milliseconds),
                    Column("points/s, fastest", "cpu_points_per_s", scientific),
                    Column("points/s, median", "cpu_median_points_per_s", scientific),
                    Column("kernel", "kernel_fraction", share),
                ),
            ),
        ),
    ),
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


# -- the page ------------------------------------------------------------------------------------
def describe_machine(machine) -> str:
    """The machine of a stamp in words (what was recorded of it)."""
    if not isinstance(machine, dict):
        return str(machine)
    known = {k: v for k, v in machine.items() if v != resultfile.UNRECORDED}
    parts = []
    if "cpu" in known:
        parts.append(str(known["cpu"]))
    if "cores" in known:
        parts.append(f"{known['cores']} cores")
    if "memory_GB" in known:
        parts.append(f"{known['memory_GB']} GB")
    if "platform" in known:
        parts.append(str(known["platform"]))
    names = {"cpu": "CPU", "memory_GB": "memory", "platform": "platform"}
    missing = [names[k] for k in names if k not in known]
    if missing:
        listed = ", ".join(missing[:-1]) + " and " + missing[-1] if len(missing) > 1 else missing[0]
        parts.append(f"{listed} not recorded")
    return ", ".join(parts)


def describe_stamp(name: str, stamp: dict) -> str:
    """One line of a table's stamps: the file, commit, date, machine, ranks, versions, and
    the command that makes it again."""
    commit = str(stamp["commit"])
    text = f"`{name}`: commit `{commit[:7]}`" if commit != resultfile.UNRECORDED else f"`{name}`"
    if stamp.get("dirty") is True:
        text += " with local changes"
    date = str(stamp["date"])
    text += f", {date[:10]} {date[11:16]} UTC" if len(date) >= 16 else f", {date}"
    text += f"; {describe_machine(stamp['machine'])}"
    ranks = stamp["ranks"]
    if isinstance(ranks, list):
        text += f"; {' and '.join(map(str, ranks))} ranks"
    elif ranks == resultfile.UNRECORDED:
        text += "; ranks not recorded"
    else:
        text += f"; {ranks} rank{'s' if ranks != 1 else ''}"
    versions = stamp.get("versions")
    if isinstance(versions, dict):
        labels = {
            "dolfinx": "DOLFINx",
            "petsc4py": "petsc4py",
            "numpy": "NumPy",
            "python": "Python",
        }
        text += "; " + ", ".join(f"{labels.get(k, k)} {v}" for k, v in versions.items())
    if stamp.get("stamp_source") == "git history":
        text += "; stamp rebuilt from the repository's history"
    command = stamp.get("command")
    if not command or command == resultfile.UNRECORDED:
        command = COMMANDS[name].format(path=f"benchmarks/results/{name}")
    return text + f". Made by `{command}`."


def markdown_table(columns: tuple[Column, ...], rows: list[dict]) -> list[str]:
    """A Markdown table: a header row and a row per record."""

    def line(cells: Iterable[str]) -> str:
        return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"

    lines = [line(c.header for c in columns), "|" + "---|" * len(columns)]
    lines += [line(c.cell(r) for c in columns) for r in rows]
    return lines


def files_named() -> list[str]:
    """Every results file the sections name."""
    names = {n for s in SECTIONS for t in s.tables for n in t.files}
    return sorted(names | {n for s in SECTIONS for f in s.figures for n in f.files})


def read_results(folder: Path = RESULTS) -> tuple[dict[str, dict], dict[str, object]]:
    """The stamps and the results of the results files of ``folder``.

    Parameters
    ----------
    folder
        The results files' folder.

    Returns
    -------
    tuple[dict[str, dict], dict[str, object]]
        The stamps and the results, by file name.

    Raises
    ------
    ValueError
        If a file has no stamp, or the sections name a file that is not in ``folder`` or
        leave one of its files out.
    """
    present = sorted(p.name for p in folder.glob("*.json"))
    named = files_named()
    problems = []
    if missing := sorted(set(named) - set(present)):
        problems.append(f"named in the report but not in {folder}: {', '.join(missing)}")
    if unused := sorted(set(present) - set(named)):
        problems.append(f"in {folder} but in no table of the report: {', '.join(unused)}")
    stamps, results = {}, {}
    for name in sorted(set(present) & set(named)):
        stamp, content = resultfile.read(folder / name)
        if stamp is None or any(field not in stamp for field in resultfile.FIELDS):
            problems.append(f"{name} has no stamp (write it with resultfile.write)")
            continue
        stamps[name], results[name] = stamp, content
    if problems:
        raise ValueError("; ".join(problems))
    return stamps, results


def render(folder: Path = RESULTS) -> str:
    """The report page (MyST Markdown) of the results files of ``folder``.

    Parameters
    ----------
    folder
        The results files' folder.

    Returns
    -------
    str
        The page: a section per benchmark of :data:`SECTIONS`, each with its usage, figures
        and tables, every table followed by its files' stamps.
    """
    stamps, results = read_results(folder)
    out = [
        "---",
        "orphan: true",  # builds with or without an entry in a toctree
        "---",
        "",
        "% Generated by benchmarks/report.py from benchmarks/results/*.json: do not edit;",
        "% run `make benchmark-report` after a benchmark has written its file.",
        "",
        "# Benchmarks",
        "",
        "The scripts in `benchmarks/` measure the accuracy and the cost of the contact "
        "formulation: errors against closed-form solutions and published results, Newton "
        "iterations, and where the time goes. Each writes its records to a JSON file in "
        "`benchmarks/results/` with a stamp: the commit of the code, the date, the machine, "
        "the number of MPI ranks, the command line and the versions of DOLFINx, petsc4py and "
        "NumPy. This page is generated from those files (`make benchmark-report`, that is "
        "`python benchmarks/report.py`); under each table are its files' stamps and the "
        "command that makes each file again.",
        "",
        "Times depend on the machine and its load. The files whose stamp is *rebuilt from "
        "the repository's history* were measured before the stamp existed, on a shared "
        "2-core machine: their commit is the one that last wrote the file (the run used its "
        "code or the working tree just before it), and their CPU model, memory and software "
        "versions were not recorded. Where a record has the machine's load average, it is in "
        "the *load* column. Errors are relative: +1.00% is 1% above the reference.",
    ]
    for section in SECTIONS:
        out += ["", f"## {section.title}", "", section.text, "", "```console"]
        out += [f"$ {line}" for line in section.usage.split("\n")]
        out += ["```"]
        for figure in section.figures:
            out += [
                "",
                f"```{{figure}} {FIGURES_LINK}/{figure.name}",
                f":alt: {figure.alt}",
                ":width: 100%",
                "",
                figure.caption,
                "```",
            ]
        for table in section.tables:
            out += [
                "",
                f"### {table.caption}" if len(section.tables) > 1 else f"**{table.caption}**",
                "",
            ]
            out += markdown_table(table.columns, table.table_rows(results))
            out += [""]
            out += [f"- {describe_stamp(name, stamps[name])}" for name in table.files]
    return "\n".join(out) + "\n"


def write_figures(folder: Path = RESULTS, figures: Path = FIGURES) -> list[Path]:
    """Draw the figures of :data:`SECTIONS` from the results files of ``folder``.

    Parameters
    ----------
    folder
        The results files' folder.
    figures
        The folder the PNG files go to (made if missing).

    Returns
    -------
    list[Path]
        The files written.
    """
    _, results = read_results(folder)
    figures.mkdir(parents=True, exist_ok=True)
    paths = []
    for section in SECTIONS:
        for figure in section.figures:
            path = figures / figure.name
            figure.draw(results, path)
            paths.append(path)
    return paths


def main(argv: list[str] | None = None) -> int:
    """Write the page and its figures, or with ``--check`` compare the page; the exit
    status."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--results", type=Path, default=RESULTS, help="the results files")
    parser.add_argument("--output", type=Path, default=PAGE, help="the page")
    parser.add_argument("--figures", type=Path, default=FIGURES, help="the figures' folder")
    parser.add_argument("--no-figures", action="store_true", help="write the page only")
    parser.add_argument(
        "--check", action="store_true", help="exit 1 if the page differs from the results'"
    )
    args = parser.parse_args(argv)
    page = render(args.results)
    if args.check:
        if not args.output.exists() or args.output.read_text() != page:
            print(f"{args.output} is not the report of {args.results}: run benchmarks/report.py")
            return 1
        return 0
    args.output.write_text(page)
    print(f"wrote {args.output}")
    if not args.no_figures:
        for path in write_figures(args.results, args.figures):
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
