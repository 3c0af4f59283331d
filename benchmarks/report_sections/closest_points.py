"""The section of the report on the closest-point search: its sweeps pivoted into tables
(a column per radius, per distance or per number of points).
"""

import math
from collections.abc import Callable, Iterable

from report_sections.tables import (
    Column,
    Section,
    Table,
    _records,
    fixed,
    general,
    integer,
    milliseconds,
    scientific,
    share,
    significant,
)


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


RADII = (1.0, 10.0, 100.0, None)


SECTIONS = (
    Section(
        "Closest-point search",
        "The closest-point search alone (`search.closest_points`, one core), in CPU "
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
)
