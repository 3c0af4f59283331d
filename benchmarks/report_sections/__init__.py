"""The catalogue of the benchmark report (``benchmarks/report.py``): its sections in the
order of the page, one module per part of it, and the command that makes each results file
again.

* :mod:`report_sections.tables`: the formats of a cell, the columns, tables, figures and
  sections, and the record helpers that several sections share.
* :mod:`report_sections.hertz`: Hertz, speed against error (with its figure), the scenes'
  eps, several load steps, P2's quadrature and multipliers.
* :mod:`report_sections.accuracy`: choosing eps, Cattaneo-Mindlin, the Taylor test, the
  membrane tube between plates.
* :mod:`report_sections.sliding`: ironing (2D, plane strain, 3D), the smoothed normal in 3D,
  the hard cases.
* :mod:`report_sections.closest_points`: the closest-point search.
* :mod:`report_sections.solver_cost`: the cost of a Newton iteration, the linear solvers.
* :mod:`report_sections.checkpoints`: the cost of a checkpoint at every step.
* :mod:`report_sections.estimates`: the effectivity of the error estimate, adaptive
  refinement.
* :mod:`report_sections.oscillation`: the multipliers' oscillation on non-matching meshes.
* :mod:`report_sections.commands`: the command of each results file.
"""

from report_sections import (
    accuracy,
    checkpoints,
    closest_points,
    estimates,
    hertz,
    oscillation,
    sliding,
    solver_cost,
)
from report_sections.commands import COMMANDS

#: the report's sections, in the order of the page
SECTIONS = (
    *hertz.SECTIONS,
    *accuracy.SECTIONS,
    *sliding.SECTIONS,
    *closest_points.SECTIONS,
    *solver_cost.SECTIONS,
    *checkpoints.SECTIONS,
    *estimates.SECTIONS,
    *oscillation.SECTIONS,
)

__all__ = ["COMMANDS", "SECTIONS"]
