"""The closest-point search of a contact pair's slave points on its meshed master surface.

The contract: slave points and a master side in, closest points out.

* :class:`ClosestPointSearch` (``slave``, ``master``, ``radius``): ``pair(u, layout)`` gives
  the :class:`Pairing` of the current slave points -- their :class:`Projection` (closest
  facet, reference coordinates ``xi``, closest point, normal, proximity ``gap``, distance
  and the linearisation ``M``) and the master nodes and unknowns each point gathers;
* :func:`closest_points` (points, facet nodes) gives the :class:`Projection` of points on a
  set of facets, by the compiled back end or the NumPy one (``backend``);
* :data:`FACET_KINDS`: the facet kinds searched (:mod:`.kinds`), with their NumPy
  :func:`shape_functions`.

The modules, from the bottom: :mod:`.kinds` (the table of facet kinds), :mod:`.shapes`
(their shape functions and normals), :mod:`.projection` (the result), :mod:`.curved` (the
quadratic facets' projections), :mod:`.compiled` (the build of ``search_kernel.c``) and
:mod:`.hierarchy` (the compiled back end), :mod:`.trees` (the trees kept between searches),
:mod:`.numpy_facets` and :mod:`.numpy_search` (the NumPy back end), :mod:`.closest` (the
search of points on facets), :mod:`.candidates`, :mod:`.normals` and :mod:`.release` (the
candidate facets, the smoothed normal and the release rules of a pair's search) and
:mod:`.pairing` (:class:`ClosestPointSearch`).
"""

from contact_ufl.contact.search.candidates import MasterCandidates, fan_columns
from contact_ufl.contact.search.closest import BACKENDS, closest_points
from contact_ufl.contact.search.kinds import FACET_EDGES, FACET_KINDS, FacetKind, facet_kind
from contact_ufl.contact.search.pairing import ClosestPointSearch, MasterSurface, Pairing
from contact_ufl.contact.search.projection import Projection, SelfContact
from contact_ufl.contact.search.release import release_master_side
from contact_ufl.contact.search.shapes import shape_functions
from contact_ufl.contact.search.trees import TreeCache

__all__ = [
    "BACKENDS",
    "FACET_EDGES",
    "FACET_KINDS",
    "ClosestPointSearch",
    "FacetKind",
    "MasterCandidates",
    "MasterSurface",
    "Pairing",
    "Projection",
    "SelfContact",
    "TreeCache",
    "closest_points",
    "facet_kind",
    "fan_columns",
    "release_master_side",
    "shape_functions",
]
