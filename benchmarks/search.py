"""Throughput of the closest-point search alone (``contact_ufl.contact.projection``).

Times :func:`~contact_ufl.contact.projection.closest_points` (points per second, one core:
the BLAS/OpenMP thread pools are limited to one thread) against the number of master facets,
on three wavy master surfaces:

* 2D segments on ``y = 0.05 sin(6 pi x)``, ``x`` in [0, 1];
* 3D triangles and bilinear quadrilaterals on ``z = 0.05 sin(4 pi x) sin(4 pi y)`` over the
  unit square (a structured grid with its inner vertices moved in-plane by up to 20% of a
  cell, each cell split in two triangles for the triangle surface);

with slave points on a perturbed copy of the surface: uniform over the parameter domain (and
5% beyond it), moved along the vertical by ``+-h 10^U(-2, 2)`` (h the facet size), at most
0.25 (the package's default search radius is a quarter of the surfaces' size), so that a
part of them lies within the search radius and a part beyond it. The radii run from ``h``
to infinity. Each timing is the best of several calls (one call if it takes over a second).

    python benchmarks/search.py --json benchmarks/results/search.json [--quick]

Records: ``kind``, ``gdim``, ``facets``, ``points``, ``radius_over_h`` (``null``: infinite),
``paired_fraction``, ``seconds`` (best repeated call: the KD-tree of the unchanged master is
reused), ``first_call_s`` (the KD-tree built), ``points_per_s``.

Results on this machine: ``benchmarks/results/search_baseline.json`` (before the search was
rewritten) and ``benchmarks/results/search.json`` (after; same results). Points per second
at radius h / infinite radius, before -> after: 1e4 segments 1.0e6 -> 1.6e6 / 4.3e5 -> 5.5e5;
1e5 segments 4.8e5 -> 9.7e5 / 2.5e5 -> 3.7e5; 1e4 triangles 2.4e5 -> 4.7e5 / 3.5e4 -> 7.5e4;
1e5 triangles 8.9e4 -> 2.7e5 / 9.3e3 -> 2.8e4; 1e4 quadrilaterals 1.9e5 -> 4.6e5 / 3.7e4 ->
8.0e4; 1e5 quadrilaterals 9.3e4 -> 2.7e5 / 1.3e4 -> 4.2e4 (the README has the table).
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from contact_ufl.contact import projection  # noqa: E402
from contact_ufl.contact.projection import closest_points  # noqa: E402

AMPLITUDE = 0.05


def surface_2d(x: np.ndarray) -> np.ndarray:
    """Height of the 2D master curve."""
    return AMPLITUDE * np.sin(6 * np.pi * x)


def surface_3d(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Height of the 3D master surface."""
    return AMPLITUDE * np.sin(4 * np.pi * x) * np.sin(4 * np.pi * y)


def segments(nf: int) -> tuple[np.ndarray, float]:
    """``nf`` segments on the 2D curve, and their size."""
    x = np.linspace(0.0, 1.0, nf + 1)
    v = np.stack([x, surface_2d(x)], axis=1)
    return np.stack([v[:-1], v[1:]], axis=1), 1.0 / nf


def grid_3d(m: int, rng: np.random.Generator) -> np.ndarray:
    """Vertices (m + 1, m + 1, 3) of a perturbed structured grid on the 3D surface."""
    s = np.linspace(0.0, 1.0, m + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    jitter = rng.uniform(-0.2, 0.2, size=(2, m - 1, m - 1)) / m
    X[1:-1, 1:-1] += jitter[0]
    Y[1:-1, 1:-1] += jitter[1]
    return np.stack([X, Y, surface_3d(X, Y)], axis=-1)


def quadrilaterals(nf: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """About ``nf`` bilinear quadrilaterals (basix vertex order), and their size."""
    m = max(int(round(np.sqrt(nf))), 2)
    V = grid_3d(m, rng)
    quads = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:], V[1:, 1:]], axis=2)
    return quads.reshape(-1, 4, 3), 1.0 / m


def triangles(nf: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """About ``nf`` triangles (each grid cell split in two), and their size."""
    m = max(int(round(np.sqrt(nf / 2))), 2)
    V = grid_3d(m, rng)
    lower = np.stack([V[:-1, :-1], V[1:, :-1], V[:-1, 1:]], axis=2)
    upper = np.stack([V[1:, :-1], V[1:, 1:], V[:-1, 1:]], axis=2)
    return np.concatenate([lower.reshape(-1, 3, 3), upper.reshape(-1, 3, 3)]), 1.0 / m


def slave_points(gdim: int, npts: int, h: float, rng: np.random.Generator) -> np.ndarray:
    """Points on a perturbed copy of the master surface (see the module docstring)."""
    offset = np.minimum(h * 10.0 ** rng.uniform(-2.0, 2.0, size=npts), 0.25)
    offset *= rng.choice([-1.0, 1.0], size=npts)
    u = rng.uniform(-0.05, 1.05, size=(npts, gdim - 1))
    if gdim == 2:
        return np.stack([u[:, 0], surface_2d(u[:, 0]) + offset], axis=1)
    return np.stack([u[:, 0], u[:, 1], surface_3d(u[:, 0], u[:, 1]) + offset], axis=1)


def time_call(
    points: np.ndarray, nodes: np.ndarray, radius: float
) -> tuple[float, float, np.ndarray]:
    """Wall time of a first call of ``closest_points`` (no KD-tree kept from an earlier call),
    the best over a few more calls (the tree of the unchanged master reused), and the facets
    found."""
    trees = projection.TreeCache() if hasattr(projection, "TreeCache") else None
    options = {} if trees is None else {"trees": trees}
    start = time.perf_counter()
    closest_points(points, nodes, radius, **options)
    first = time.perf_counter() - start
    best, calls = np.inf, 0
    while calls < 5:
        start = time.perf_counter()
        proj = closest_points(points, nodes, radius, **options)
        best = min(best, time.perf_counter() - start)
        calls += 1
        if best > 1.0 or (calls >= 3 and best > 0.2):
            break
    return first, best, proj.facet


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--json", required=True)
    parser.add_argument("--quick", action="store_true", help="fewer facets and points")
    args = parser.parse_args()
    sizes = (1_000, 10_000) if args.quick else (1_000, 10_000, 100_000)
    npts = 10_000 if args.quick else 50_000
    factors = (1.0, 10.0, np.inf) if args.quick else (1.0, 10.0, 100.0, np.inf)
    makers = {
        "segment": lambda nf, rng: segments(nf),
        "triangle": triangles,
        "quadrilateral": quadrilaterals,
    }
    records = []
    print(
        f"{'facets':>8} {'kind':>13} {'radius/h':>8} {'paired':>7} {'time s':>8} {'points/s':>10}"
    )
    for kind, make in makers.items():
        for nf in sizes:
            rng = np.random.default_rng(nf)
            nodes, h = make(nf, rng)
            points = slave_points(nodes.shape[2], npts, h, rng)
            for factor in factors:
                first, seconds, facet = time_call(points, nodes, factor * h)
                record = {
                    "kind": kind,
                    "gdim": int(nodes.shape[2]),
                    "facets": int(nodes.shape[0]),
                    "points": npts,
                    "radius_over_h": None if np.isinf(factor) else factor,
                    "paired_fraction": float(np.mean(facet >= 0)),
                    "seconds": seconds,
                    "first_call_s": first,
                    "points_per_s": npts / seconds,
                }
                records.append(record)
                print(
                    f"{record['facets']:8d} {kind:>13} {factor:8.0f} "
                    f"{record['paired_fraction']:7.2f} {seconds:8.4f} {npts / seconds:10.3g} "
                    f"{first:8.4f}",
                    flush=True,
                )
    with open(args.json, "w") as f:
        json.dump({"quick": args.quick, "records": records}, f, indent=1)


if __name__ == "__main__":
    main()
