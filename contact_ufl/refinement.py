"""A scene on refined meshes: Plaza refinement of each mesh at marked cells with its tags
carried over (on any number of ranks), the new nodes of curved boundaries put back on
them, and the slave surfaces kept no coarser than the master surfaces they face. The
adaptive loop (:mod:`contact_ufl.adapt`) calls it; see the user guide, *Adaptive
refinement*.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.errors import ContactInputError, collective_check
from contact_ufl.scene import Domain, Scene

#: the cell types :func:`dolfinx.mesh.refine` refines
REFINABLE = (
    dolfinx.mesh.CellType.interval,
    dolfinx.mesh.CellType.triangle,
    dolfinx.mesh.CellType.tetrahedron,
)


#: a curved boundary: its points moved onto it, ``(n, 3) -> (n, 3)``
Boundary = Callable[[np.ndarray], np.ndarray]


def refine_scene(
    scene: Scene,
    cells: list[np.ndarray],
    boundaries: Mapping[int | str, Boundary] | None = None,
) -> Scene:
    """The scene on its meshes refined at ``cells`` (one array of owned cells per mesh, in
    the order of :attr:`Scene.parts`; empty: the mesh is kept), its tags carried over.

    ``boundaries`` maps a facet group (tag or name) to a function that moves points onto the
    curved surface the group approximates (e.g. ``lambda x: centre + R * (x - centre) /
    |x - centre|``): the new nodes Plaza puts at the midpoints of the group's edges are moved
    onto it (collective).
    """
    parts = scene.parts
    comm = parts[0].mesh.comm
    collective_check(
        comm,
        len(cells) == len(parts),
        f"refine_scene: {len(cells)} arrays of cells for a scene of {len(parts)} meshes",
    )
    check_boundaries(scene, boundaries or {})
    refined = [_refine_domain(d, c, boundaries or {}) for d, c in zip(parts, cells, strict=True)]
    if scene.mesh is None:
        return dataclasses.replace(scene, domains=refined)
    own, *others = refined
    return dataclasses.replace(
        scene, mesh=own.mesh, cell_tags=own.cell_tags, facet_tags=own.facet_tags, domains=others
    )


def _refine_domain(domain: Domain, cells: np.ndarray, boundaries: Mapping) -> Domain:
    """``domain`` on its mesh refined at ``cells``, with its tags and curved boundaries."""
    mesh = domain.mesh
    comm = mesh.comm
    if comm.allreduce(len(cells), MPI.SUM) == 0:
        return domain
    tdim = mesh.topology.dim
    mesh.topology.create_entities(1)
    mesh.topology.create_connectivity(tdim, tdim - 1)
    edges = dolfinx.mesh.compute_incident_entities(mesh.topology, cells, tdim, 1)
    option = dolfinx.mesh.RefinementOption.parent_cell_and_facet
    fine, parent_cell, parent_facet = dolfinx.mesh.refine(mesh, edges, option=option)
    fine.topology.create_connectivity(tdim, tdim - 1)
    fine.topology.create_connectivity(tdim - 1, tdim)
    cell_tags, facet_tags = _carry_tags(domain, fine, parent_cell, parent_facet)
    out = dataclasses.replace(domain, mesh=fine, cell_tags=cell_tags, facet_tags=facet_tags)
    for key, surface in boundaries.items():
        tag = _facet_tag(domain, key)
        if tag is not None:
            _snap(fine, facet_tags.find(tag), surface)
    return out


def slave_finer_than_master(
    scene: Scene,
    displacements: list[dolfinx.fem.Function] | None = None,
    boundaries: Mapping[int | str, Boundary] | None = None,
    max_passes: int = 4,
    sources: list[Domain] | None = None,
) -> Scene:
    """``scene`` with its slave surfaces refined until no slave facet is larger than a
    master facet it faces (collective).

    The multipliers live on the slave surface and its quadrature points carry the contact
    force to the master: where the master is finer, its facets see the slave's points as
    point loads and the pairing cycles (see the user guide, *Adaptive refinement*). Facing:
    a master facet's midpoint within the slave facet's size of the slave facet's midpoint,
    in the configuration displaced by ``displacements`` (one field per mesh of the scene,
    on any mesh: moved by interpolation; ``None``: the reference configuration).
    ``sources``: the domains of the displacements' meshes, whose cell tags let each body
    take its displacement from its own cells (see :func:`interpolate_by_body`).
    """
    surfaces: dict[int, set[int]] = {}  # the contact groups of each mesh
    for pair in scene.contacts:
        if not pair.on_obstacle:
            surfaces.setdefault(_domain_index(pair.slave_domain), set()).add(pair.slave)
            surfaces.setdefault(_domain_index(pair.master_domain), set()).add(pair.master)
    for _ in range(max_passes):
        parts = scene.parts
        current = [
            _nodes_moved(
                d,
                displacements[k] if displacements else None,
                surfaces.get(k, set()),
                sources[k] if sources else None,
            )
            for k, d in enumerate(parts)
        ]
        marked = [np.zeros(0, dtype=np.int32) for _ in parts]
        for pair in scene.contacts:
            if pair.on_obstacle:
                continue
            ks, km = _domain_index(pair.slave_domain), _domain_index(pair.master_domain)
            cells = _coarser_slave_cells(
                parts[ks], current[ks], pair.slave, parts[km], current[km], pair.master
            )
            marked[ks] = np.union1d(marked[ks], cells).astype(np.int32)
        comm = parts[0].mesh.comm
        if comm.allreduce(sum(len(m) for m in marked), MPI.SUM) == 0:
            return scene
        scene = refine_scene(scene, marked, boundaries)
    return scene


def _domain_index(index: int | None) -> int:
    return 0 if index is None else int(index)


def _nodes_moved(
    domain: Domain,
    u: dolfinx.fem.Function | None,
    groups: set[int],
    source: Domain | None = None,
) -> np.ndarray:
    """The geometry nodes of ``domain``'s mesh, those of the facet ``groups`` displaced by
    ``u`` (interpolated on their cells; body by body from ``source``, the domain of ``u``'s
    mesh, if given)."""
    mesh = domain.mesh
    x = mesh.geometry.x.copy()
    if u is None or not groups:
        return x
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    facets = np.concatenate([domain.facet_tags.find(tag) for tag in sorted(groups)])
    cells = dolfinx.mesh.compute_incident_entities(mesh.topology, facets, tdim - 1, tdim)
    gdim = mesh.geometry.dim
    degree = mesh.geometry.cmaps[0].degree
    space = dolfinx.fem.functionspace(mesh, ("Lagrange", degree, (gdim,)))
    moved = dolfinx.fem.Function(space)
    if u.function_space.mesh is mesh:
        moved.interpolate(u, cells0=cells)
    elif source is not None:
        interpolate_by_body(moved, domain, u, source, 1e-6 * _size(mesh), cells)
    else:
        interpolate_onto(moved, u, 1e-6 * _size(mesh), cells)
    # the space's dofs and the geometry's nodes follow the same element: cell by cell
    nodes = mesh.geometry.dofmaps[0]
    dofs = space.dofmap.list
    values = moved.x.array.reshape(-1, gdim)
    x[nodes.ravel(), :gdim] += values[dofs.ravel()]
    return x


def _size(mesh: dolfinx.mesh.Mesh) -> float:
    x = mesh.geometry.x
    low = np.min(mesh.comm.allgather(x.min(axis=0, initial=np.inf)), axis=0)
    high = np.max(mesh.comm.allgather(x.max(axis=0, initial=-np.inf)), axis=0)
    return float(np.linalg.norm(high - low))


def _facet_shapes(
    domain: Domain, x: np.ndarray, tag: int, owned_only: bool
) -> tuple[np.ndarray, ...]:
    """The facets of group ``tag`` (the owned ones, or all this rank holds), their midpoints
    and sizes (largest edge) at the node positions ``x``."""
    mesh = domain.mesh
    fdim = mesh.topology.dim - 1
    facets = domain.facet_tags.find(tag)
    if owned_only:
        facets = facets[facets < mesh.topology.index_map(fdim).size_local]
    vertices = x[dolfinx.mesh.entities_to_geometry(mesh, fdim, facets)]
    n = vertices.shape[1]
    edges = [vertices[:, i] - vertices[:, j] for i in range(n) for j in range(i + 1, n)]
    size = np.max([np.linalg.norm(e, axis=1) for e in edges], axis=0, initial=0.0)
    size = size if len(facets) else np.zeros(0)
    return facets, vertices.mean(axis=1), size


def _coarser_slave_cells(slave, x_slave, slave_tag, master, x_master, master_tag) -> np.ndarray:
    """The owned cells of the slave facets larger than a master facet they face."""
    comm = slave.mesh.comm
    tdim = slave.mesh.topology.dim
    slave.mesh.topology.create_connectivity(tdim - 1, tdim)  # collective: on every rank
    # every slave facet of an owned cell (owned or not), every master facet once
    facets, mid, size = _facet_shapes(slave, x_slave, slave_tag, owned_only=False)
    _, m_mid, m_size = _facet_shapes(master, x_master, master_tag, owned_only=True)
    m_mid = np.concatenate(comm.allgather(m_mid.reshape(-1, 3)))
    m_size = np.concatenate(comm.allgather(m_size))
    if len(facets) == 0 or len(m_size) == 0:
        return np.zeros(0, dtype=np.int32)
    from scipy.spatial import cKDTree

    k = min(16, len(m_size))
    distance, index = cKDTree(m_mid).query(mid, k=k)
    distance, index = distance.reshape(len(mid), k), index.reshape(len(mid), k)
    facing = distance <= size[:, None]
    finest = np.where(facing, m_size[np.minimum(index, len(m_size) - 1)], np.inf).min(axis=1)
    coarse = facets[size > finest * (1.0 + 1e-9)]
    cells = dolfinx.mesh.compute_incident_entities(slave.mesh.topology, coarse, tdim - 1, tdim)
    owned = slave.mesh.topology.index_map(tdim).size_local
    return cells[cells < owned].astype(np.int32)


def _facet_tag(domain: Domain, key: int | str) -> int | None:
    """The integer of facet group ``key`` in ``domain`` (``None``: not a group of it)."""
    if isinstance(key, str):
        return domain.tags.get(key)
    return int(key)


def _carry_tags(
    domain: Domain, fine: dolfinx.mesh.Mesh, parent_cell: np.ndarray, parent_facet: np.ndarray
) -> tuple[dolfinx.mesh.MeshTags, dolfinx.mesh.MeshTags]:
    """The cell and facet tags of ``domain`` on its refined mesh ``fine``.

    :func:`dolfinx.mesh.transfer_meshtag` refuses ghosted meshes; here each owned fine cell
    takes its parent's tag and, for each of its facets inside a parent facet, that facet's
    tag; the ghost cells get theirs from their owners (a DG0 scatter), so that every rank
    knows the tags of all its cells' facets, as a mesh read from a file does."""
    coarse = domain.mesh
    tdim = coarse.topology.dim
    fdim = tdim - 1
    num_facets = dolfinx.cpp.mesh.cell_num_entities(coarse.topology.cell_type, fdim)
    coarse_facets = coarse.topology.connectivity(tdim, fdim).array.reshape(-1, num_facets)
    n_coarse_facets = coarse.topology.index_map(fdim).size_local
    n_coarse_facets += coarse.topology.index_map(fdim).num_ghosts
    facet_value = np.full(n_coarse_facets, -1, dtype=np.int64)
    facet_value[domain.facet_tags.indices] = domain.facet_tags.values
    cell_value = np.full(coarse_facets.shape[0], -1, dtype=np.int64)
    cell_value[domain.cell_tags.indices] = domain.cell_tags.values

    owned = len(parent_cell)
    # the parent maps are in the order the refinement made the cells, before the mesh
    # reordered them: fine cell i is the refinement's original_cell_index[i] - offset
    offset = fine.topology.index_map(tdim).local_range[0]
    made = np.asarray(fine.topology.original_cell_index[:owned], dtype=np.int64) - offset
    parent_cell = np.asarray(parent_cell)[made]
    parent_facet = np.asarray(parent_facet).reshape(owned, num_facets)[made]
    # per owned fine cell: its tag and the tags of its facets (-1: none), one DG0 block
    block = np.full((owned, 1 + num_facets), -1.0)
    block[:, 0] = cell_value[parent_cell]
    local = parent_facet.astype(np.int64)
    inside = local >= 0
    rows = np.broadcast_to(parent_cell[:, None], local.shape)
    block[:, 1:][inside] = facet_value[coarse_facets[rows[inside], local[inside]]]
    space = dolfinx.fem.functionspace(fine, ("DG", 0, (1 + num_facets,)))
    carrier = dolfinx.fem.Function(space)
    n_cells = fine.topology.index_map(tdim).size_local + fine.topology.index_map(tdim).num_ghosts
    dofs = space.dofmap.list[:, 0]
    values = carrier.x.array.reshape(-1, 1 + num_facets)
    values[dofs[:owned]] = block
    carrier.x.scatter_forward()
    every = values[dofs[:n_cells]].round().astype(np.int64)

    cells = np.flatnonzero(every[:, 0] >= 0).astype(np.int32)
    cell_tags = dolfinx.mesh.meshtags(fine, tdim, cells, every[cells, 0].astype(np.int32))
    fine_facets = fine.topology.connectivity(tdim, fdim).array.reshape(-1, num_facets)
    tagged = every[:, 1:] >= 0
    facets, first = np.unique(fine_facets[:n_cells][tagged], return_index=True)
    tags = every[:, 1:][tagged][first].astype(np.int32)
    facet_tags = dolfinx.mesh.meshtags(fine, fdim, facets.astype(np.int32), tags)
    return cell_tags, facet_tags


def _snap(mesh: dolfinx.mesh.Mesh, facets: np.ndarray, surface: Boundary) -> None:
    """Move the geometry nodes of ``facets`` onto ``surface`` (every rank its own copies)."""
    fdim = mesh.topology.dim - 1
    nodes = dolfinx.mesh.entities_to_geometry(mesh, fdim, facets).ravel()
    nodes = np.unique(nodes)
    if len(nodes):
        x = mesh.geometry.x
        x[nodes] = np.asarray(surface(x[nodes].copy()), dtype=x.dtype).reshape(-1, 3)


def interpolate_onto(
    new: dolfinx.fem.Function,
    old: dolfinx.fem.Function,
    padding: float,
    cells: np.ndarray | None = None,
) -> None:
    """``new`` at its dofs of ``cells`` (default: all this rank holds) from ``old`` on
    another mesh (collective)."""
    mesh = new.function_space.mesh
    if cells is None:
        tdim = mesh.topology.dim
        n = mesh.topology.index_map(tdim).size_local + mesh.topology.index_map(tdim).num_ghosts
        cells = np.arange(n, dtype=np.int32)
    data = dolfinx.fem.create_interpolation_data(
        new.function_space, old.function_space, cells, padding=padding
    )
    new.interpolate_nonmatching(old, cells, data)
    new.x.scatter_forward()


def interpolate_unknowns(old: list, new: list, skip: set[int], padding: float) -> None:
    """The unknowns ``new`` of a problem on other (or remade) meshes from ``old``, those
    whose ``id`` is in ``skip`` (the displacements, moved by the caller) left out: a
    global unknown (a control's load factor) copied, a field (a pair's multipliers)
    interpolated (:func:`interpolate_onto`; collective)."""
    for source, target in zip(old, new, strict=True):
        if id(source) in skip:
            continue
        if source.function_space.mesh.topology.dim == 0 or source.x.index_map.size_global <= 1:
            target.x.array[:] = source.x.array
        else:
            interpolate_onto(target, source, padding)


def interpolate_by_body(
    new: dolfinx.fem.Function,
    new_domain: Domain,
    old: dolfinx.fem.Function,
    old_domain: Domain,
    padding: float,
    cells: np.ndarray | None = None,
) -> None:
    """:func:`interpolate_onto` body by body: the dofs of each body's cells (of ``cells``;
    default all) from ``old`` on that body's cells of ``old_domain`` only (collective).

    Where two bodies of one mesh touch, a point of one lies in the other's cells too, and a
    search over the whole mesh may take the other body's value: after the bodies part, a
    node of one carries the other's displacement."""
    mesh = old.function_space.mesh
    tdim = mesh.topology.dim
    for body in new_domain.bodies:
        targets = new_domain.cell_tags.find(body.tag)
        if cells is not None:
            targets = np.intersect1d(targets, cells)
        sources = old_domain.cell_tags.find(body.tag)
        sub, entity_map, _, _ = dolfinx.mesh.create_submesh(mesh, tdim, sources)
        cell_map = sub.topology.index_map(tdim)
        local = np.arange(cell_map.size_local + cell_map.num_ghosts, dtype=np.int32)
        parents = entity_map.sub_topology_to_topology(local, inverse=False)
        restricted = dolfinx.fem.Function(
            dolfinx.fem.functionspace(sub, old.function_space.ufl_element())
        )
        restricted.interpolate(old, cells0=parents, cells1=local)
        interpolate_onto(new, restricted, padding, targets.astype(np.int32))


def check_boundaries(scene: Scene, boundaries: Mapping[int | str, Boundary]) -> None:
    """Raise :class:`~contact_ufl.errors.ContactInputError` (every rank) unless every key of
    ``boundaries`` is a facet group of a mesh of ``scene`` and every value callable."""
    names = {n for d in scene.parts for n, (dim, _) in d.groups.items() if dim == d.surface_dim}
    tags = {t for d in scene.parts for n, (dim, t) in d.groups.items() if dim == d.surface_dim}
    for key, surface in boundaries.items():
        known = key in names if isinstance(key, str) else key in tags
        if not known:
            raise ContactInputError(
                f"boundaries: {key!r} is not a facet group of the scene (its groups: "
                f"{', '.join(sorted(names))})"
            )
        if not callable(surface):
            raise ContactInputError(
                f"boundaries[{key!r}] must be a function that moves points onto the surface, "
                f"got {surface!r}"
            )


def check_refinable(scene: Scene) -> None:
    """Raise :class:`~contact_ufl.errors.ContactInputError` (every rank) unless every mesh of
    ``scene`` is made of simplices, which :func:`dolfinx.mesh.refine` refines."""
    for k, d in enumerate(scene.parts):
        cell = d.mesh.topology.cell_type
        if cell not in REFINABLE:
            raise ContactInputError(
                f"{d.name or f'mesh {k}'} has {cell.name} cells: adaptive refinement refines "
                "triangles and tetrahedra only (dolfinx.mesh.refine, Plaza); mesh the scene "
                "with simplices"
            )
