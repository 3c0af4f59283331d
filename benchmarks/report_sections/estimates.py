"""The section of the report on the error estimate: its effectivity against a true error
under refinement (``benchmarks/estimate_effectivity.py``), with unit weights and with the
proposed per-term weights.
"""

from report_sections.tables import Column, Section, Table, fixed, integer, scientific, significant

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


def _percent(x) -> str:
    return "-" if x is None or x != x else f"{100.0 * x:.0f}%"


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
        "weighted by 1; *weighted* with the proposed weights on the terms' `eta^2` (the "
        "records' `weights`: 1/4 on the bulk's residuals, `bulk`, `jump` and `boundary`, "
        "1/2 on the contact's, `traction`, `penetration`, `complementarity` and `cone`); "
        "*energy eff.* is `eta` over `(2 |W_h - W_ref|)^1/2`, the error "
        "the stored energy measures. The shares are those of the jump, contact traction and "
        "complementarity terms in the unit-weighted `eta^2`.",
        "python benchmarks/estimate_effectivity.py [--quick] [--cases hertz_2d patch cattaneo "
        "hertz_3d] --json FILE",
        (
            Table(
                "Effectivity under refinement",
                ("estimate_effectivity.json",),
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
)
