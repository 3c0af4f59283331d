"""What several families of scenes share: a body per cell group, and the steel of the
force-driven scenes.
"""

from __future__ import annotations

from contact_ufl.materials import (
    Hyperelastic,
)
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.scene import Body


def _solids(**materials: Hyperelastic | J2Plasticity) -> list[Body]:
    """One body per cell group (``group=material``), named after its group."""
    return [Body(group, material, group) for group, material in materials.items()]


E_STEEL = 200e9
"""Young's modulus of steel (Pa), of the force-driven scenes."""
