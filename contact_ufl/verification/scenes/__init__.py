"""Ready-made scenes of the verification problems, shared by tests, demos and benchmarks.

Each function meshes its geometry (:mod:`contact_ufl.verification.geometries`) and returns a
:class:`~contact_ufl.scene.Scene` with the bodies, supports, loads and contact pair, plus the
data needed to compare with the analytic solution. Every scene is importable from here; the
modules group them by family:

* :mod:`~contact_ufl.verification.scenes.hertz`: Hertz in 2D and 3D, force-driven, plastic.
* :mod:`~contact_ufl.verification.scenes.patches`: the contact patch tests, the pushed block.
* :mod:`~contact_ufl.verification.scenes.pairs`: curved pairs (Taylor tests), bodies on meshes
  of their own.
* :mod:`~contact_ufl.verification.scenes.ironing_problems`: the 2D, plane-strain and 3D
  ironing.
* :mod:`~contact_ufl.verification.scenes.cantilevers`: the two beams.
* :mod:`~contact_ufl.verification.scenes.obstacles`: rigid obstacles, the self-contact ring.
* :mod:`~contact_ufl.verification.scenes.membranes`: inflation, a surface made a membrane,
  the tube between plates.
* :mod:`~contact_ufl.verification.scenes.drumheads`: the pre-tensioned drumhead, indented.
* :mod:`~contact_ufl.verification.scenes.flat_membranes`: a flat membrane on a block, on a
  rigid plane.
"""

from contact_ufl.verification.scenes._common import E_STEEL
from contact_ufl.verification.scenes.cantilevers import BeamsScene, beams
from contact_ufl.verification.scenes.drumheads import (
    IndentedDrumhead,
    drumhead_supports,
    indented_drumhead,
    pretension,
    pretensioned_drumhead,
    retagged_membrane,
)
from contact_ufl.verification.scenes.flat_membranes import (
    membrane_dragged_on_plane,
    membrane_on_block,
)
from contact_ufl.verification.scenes.hertz import (
    Hertz3DScene,
    HertzScene,
    hertz_2d,
    hertz_2d_driven,
    hertz_3d,
    plastic_indentation,
    rotation_2d,
)
from contact_ufl.verification.scenes.ironing_problems import (
    ironing,
    ironing_3d,
    ironing_plane_strain,
)
from contact_ufl.verification.scenes.membranes import (
    PlatesSchedule,
    inflated_sphere,
    membrane_sandwich,
    surface_as_membrane,
    tube_for_plates,
    with_membrane,
)
from contact_ufl.verification.scenes.obstacles import (
    block_under_circle,
    hertz_on_rigid_flat,
    pushed_block_on_plane,
    squeezed_ring,
)
from contact_ufl.verification.scenes.pairs import curved_pair, on_meshes_of_their_own, warp_saddle
from contact_ufl.verification.scenes.patches import patch, patch_3d_pressed, pushed_block

__all__ = [
    "E_STEEL",
    "BeamsScene",
    "beams",
    "IndentedDrumhead",
    "drumhead_supports",
    "indented_drumhead",
    "pretension",
    "pretensioned_drumhead",
    "retagged_membrane",
    "membrane_dragged_on_plane",
    "membrane_on_block",
    "Hertz3DScene",
    "HertzScene",
    "hertz_2d",
    "hertz_2d_driven",
    "hertz_3d",
    "plastic_indentation",
    "rotation_2d",
    "ironing",
    "ironing_3d",
    "ironing_plane_strain",
    "PlatesSchedule",
    "inflated_sphere",
    "membrane_sandwich",
    "surface_as_membrane",
    "tube_for_plates",
    "with_membrane",
    "block_under_circle",
    "hertz_on_rigid_flat",
    "pushed_block_on_plane",
    "squeezed_ring",
    "curved_pair",
    "on_meshes_of_their_own",
    "warp_saddle",
    "patch",
    "patch_3d_pressed",
    "pushed_block",
]
