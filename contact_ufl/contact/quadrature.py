"""Quadrature rules of the contact integrals over the slave facets."""

from __future__ import annotations

import basix
import numpy as np

#: Quadrature rules of the contact integrals, by name.
QUADRATURE_RULES = {"gauss": basix.QuadratureType.default, "lobatto": basix.QuadratureType.gll}


def composite_quadrature(
    cell: basix.CellType, degree: int, subdivisions: int = 1, rule: str = "gauss"
) -> tuple[np.ndarray, np.ndarray]:
    """A rule of ``degree`` repeated on a uniform ``subdivisions``-fold split of ``cell``.

    A master facet edge inside a slave facet puts a kink into the contact integrand, which
    one Gauss rule integrates only to O(1/n^2); a composite rule bounds the kink's error by
    the size of one sub-cell. ``rule`` is a key of :data:`QUADRATURE_RULES`; the Lobatto
    rule (intervals and quadrilaterals) has points on the vertices of the (sub-)cells.
    """
    if rule == "lobatto" and cell == basix.CellType.triangle:
        raise ValueError("the Lobatto contact rule needs interval or quadrilateral facets")
    points, weights = basix.make_quadrature(cell, degree, rule=QUADRATURE_RULES[rule])
    points = np.clip(points, 0.0, 1.0)  # GLL end points come with round-off outside [0, 1]
    m = subdivisions
    if m == 1:
        return points, weights
    if cell == basix.CellType.interval:
        corners = np.arange(m)[:, None, None] / m  # (m, 1, 1)
        sub = corners + points[None] / m
    elif cell == basix.CellType.quadrilateral:
        i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
        corners = np.stack([i.ravel(), j.ravel()], axis=1)[:, None, :] / m
        sub = corners + points[None] / m
    elif cell == basix.CellType.triangle:
        i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
        up = (i + j < m).ravel()
        down = (i + j < m - 1).ravel()
        ij = np.stack([i.ravel(), j.ravel()], axis=1).astype(float)
        e0, e1 = np.array([1.0, 0.0]), np.array([0.0, 1.0])
        v_up = [ij[up], ij[up] + e0, ij[up] + e1]
        v_down = [ij[down] + e0 + e1, ij[down] + e1, ij[down] + e0]
        v = [np.vstack([a, b]) / m for a, b in zip(v_up, v_down, strict=True)]
        sub = (
            v[0][:, None, :]
            + points[None, :, :1] * (v[1] - v[0])[:, None, :]
            + points[None, :, 1:] * (v[2] - v[0])[:, None, :]
        )
    else:
        raise ValueError(f"no composite rule on {cell}")
    nsub = sub.shape[0]
    return sub.reshape(-1, points.shape[1]), np.tile(weights, nsub) / nsub


def iso_subdivisions(subdivisions: int) -> int:
    """The subdivisions of a composite contact rule with P1-iso-P2 multipliers:
    ``subdivisions`` rounded up to an even number (1 -> 2, 3 -> 4), so that every sub-cell
    of the rule lies in one of the once-refined cells on which those multipliers are
    linear (a rule across their kinks would integrate them only to O(1/n^2))."""
    m = int(subdivisions)
    return m + m % 2
