"""What the discrete operator asks of everything that adds unknowns or gathered fields.

The assembled fields of a contact problem are ``[u_1, ..., u_m]`` and the fields of its
*couplings*: a contact interface adds its multipliers (unknowns) and the master data it
gathers at the slave points (``xhat = Xhat + P u``, the slip reference's last-step master
nodes), a volume control its pressure (an unknown) and the pressure field gathered from it.
The operator (:mod:`contact_ufl.operator`) builds the chain operator ``T`` from their
*gathers*: for every owned dof of a gathered field, the stacked index of the unknown it
copies (or several, ``-1`` padded, in a superset of the pattern; ``-1`` for none).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import dolfinx
import numpy as np
from petsc4py import PETSc

from contact_ufl.layout import StackedLayout

#: A gathered field and, for every owned dof of it (unrolled, local order), the stacked
#: index of the unknown it gathers (``(ndofs,)``), or several (``(ndofs, width)``), ``-1``
#: for none.
Gather = tuple[dolfinx.fem.Function, np.ndarray]


@runtime_checkable
class Coupling(Protocol):
    """A part of the system that adds unknowns and gathered fields: a contact interface
    (:class:`~contact_ufl.contact.interface.ContactInterface`) or a volume control
    (:class:`~contact_ufl.control.VolumeConstraint`)."""

    @property
    def fields(self) -> list[dolfinx.fem.Function]:
        """Its assembled fields (unknowns and gathered), in the order of its residuals."""
        ...

    @property
    def unknowns(self) -> list[dolfinx.fem.Function]:
        """Its unknowns."""
        ...

    def update(self, x: PETSc.Vec, layout: StackedLayout) -> list[Gather]:
        """Refresh its gathered fields and point data at the unknowns ``x`` (whose values
        the problem's functions hold; a contact searches) and return its gathers
        (collective)."""
        ...

    def pattern_gathers(self) -> list[Gather]:
        """A superset of the gathers of the last :meth:`update` from which the solver
        matrix's pattern is made (the same list where it has none wider)."""
        ...
