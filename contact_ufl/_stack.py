"""Load the DOLFINx stack in the right order.

The PyPI wheel ``dolfinx-solver-real`` ships its own MPI and PETSc libraries; its module
``dolfinx_solver`` must be imported before ``dolfinx`` or ``petsc4py``. Other installs
(conda-forge, Docker) do not have it, and need nothing.
"""

try:
    import dolfinx_solver  # noqa: F401
except ImportError:  # conda-forge, Docker or source install of DOLFINx
    pass

from mpi4py import MPI  # noqa: E402, F401
