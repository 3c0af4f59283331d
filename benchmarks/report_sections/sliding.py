"""The sections of the report on large sliding and the hard cases: the 2D, plane-strain and
3D ironing, the smoothed master normal in 3D, and the suite of hard cases.
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


SECTIONS = (
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
)
