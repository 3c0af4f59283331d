"""contact_ufl: large-deformation frictional contact for FEniCSx.

Augmented-Lagrangian mixed weak form (displacements of both bodies plus contact multipliers
on the slave surface), closest-point projection onto the master surface, Newton (PETSc SNES)
with the tangent from UFL's Gateaux derivative chained through the master side.
"""

from contact_ufl import _stack  # noqa: F401  (loads the MPI/PETSc libraries first)

__version__ = "0.1.0"
