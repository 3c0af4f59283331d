"""Adaptive refinement of a scene's meshes to a target accuracy.

One level of the loop: solve, estimate (:mod:`contact_ufl.estimate`), mark the cells that
carry a fraction ``theta`` of the estimate (Doerfler), refine every mesh of the scene there
(:func:`dolfinx.mesh.refine`, Plaza; triangles and tetrahedra) with its tags carried over and
the nodes of curved boundaries put back on them, and solve on the new meshes. A scene without
history (no friction, no plasticity) starts each new mesh from the last solution moved onto
it and brings it to equilibrium at the same load; a scene with history replays its load path
on each mesh. See the user guide, *Adaptive refinement*.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.errors import ContactInputError, ConvergenceError, collective_check
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Domain, Scene

#: the cell types :func:`dolfinx.mesh.refine` refines
REFINABLE = (
    dolfinx.mesh.CellType.interval,
    dolfinx.mesh.CellType.triangle,
    dolfinx.mesh.CellType.tetrahedron,
)

#: a curved boundary: its points moved onto it, ``(n, 3) -> (n, 3)``
Boundary = Callable[[np.ndarray], np.ndarray]


@dataclass
class Level:
    """One mesh of the adaptive loop and what its solve gave.

    Attributes
    ----------
    unknowns
        Number of unknowns of the problem (all meshes, multipliers).
    cells
        Number of cells of each mesh.
    estimate, relative
        The error estimate and its ratio to the solution's energy norm.
    newton_iterations
        Newton iterations of the solve on this mesh (all steps).
    wall
        Wall time of the solve and estimate, seconds (not the refinement).
    start
        ``"load path"``: the solve ran the scene's load path from the reference state;
        ``"moved state"``: it started from the last level's solution moved onto this mesh.
    """

    unknowns: int
    cells: list[int]
    estimate: float
    relative: float
    newton_iterations: int
    wall: float
    start: str


@dataclass
class AdaptiveSolve:
    """The result of :func:`refine_to_tolerance`.

    Attributes
    ----------
    problem
        The problem on the last mesh, solved (its :attr:`estimate` is the last level's).
    estimate
        The error estimate of :attr:`problem`.
    levels
        Every mesh the loop solved on, coarsest first.
    reached
        Whether the relative estimate met the tolerance (else the budget or the number of
        levels stopped the loop: :attr:`stopped_by` says which).
    stopped_by
        ``"tolerance"``, ``"budget"`` or ``"levels"``.
    """

    problem: ContactProblem
    estimate: object
    levels: list[Level] = field(default_factory=list)
    reached: bool = False
    stopped_by: str = ""


def doerfler_marking(
    indicators: list[dolfinx.fem.Function], theta: float, comm: MPI.Comm
) -> list[np.ndarray]:
    """The fewest cells (largest indicators first) whose ``eta_K^2`` sum to at least
    ``theta`` of the total, over all meshes and ranks (Doerfler's bulk criterion).

    Parameters
    ----------
    indicators
        ``eta_K^2`` per cell, a DG0 function per mesh
        (:attr:`ErrorEstimate.indicators <contact_ufl.estimate.ErrorEstimate.indicators>`).
    theta
        The fraction, in (0, 1].

    Returns
    -------
    The marked owned cells of each mesh (local indices).
    """
    values = [_cell_values(eta) for eta in indicators]
    local = np.concatenate(values) if values else np.zeros(0)
    gathered = comm.gather(local, root=0)
    threshold = None
    if comm.rank == 0:
        every = np.sort(np.concatenate(gathered))[::-1]
        total = every.sum()
        if total > 0.0:
            k = int(np.searchsorted(np.cumsum(every), theta * total * (1.0 - 1e-12)))
            threshold = float(every[min(k, len(every) - 1)])
    threshold = comm.bcast(threshold, root=0)
    if threshold is None:
        return [np.zeros(0, dtype=np.int32) for _ in values]
    return [np.flatnonzero(v >= threshold).astype(np.int32) for v in values]


def _cell_values(eta: dolfinx.fem.Function) -> np.ndarray:
    """The values of a DG0 function on the owned cells, in cell order."""
    mesh = eta.function_space.mesh
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    dofs = eta.function_space.dofmap.list[:owned, 0]
    return eta.x.array[dofs]


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
) -> Scene:
    """``scene`` with its slave surfaces refined until no slave facet is larger than a
    master facet it faces (collective).

    The multipliers live on the slave surface and its quadrature points carry the contact
    force to the master: where the master is finer, its facets see the slave's points as
    point loads and the pairing cycles (see the user guide, *Adaptive refinement*). Facing:
    a master facet's midpoint within the slave facet's size of the slave facet's midpoint,
    in the configuration displaced by ``displacements`` (one field per mesh of the scene,
    on any mesh: moved by interpolation; ``None``: the reference configuration).
    """
    surfaces: dict[int, set[int]] = {}  # the contact groups of each mesh
    for pair in scene.contacts:
        if not pair.on_obstacle:
            surfaces.setdefault(_domain_index(pair.slave_domain), set()).add(pair.slave)
            surfaces.setdefault(_domain_index(pair.master_domain), set()).add(pair.master)
    for _ in range(max_passes):
        parts = scene.parts
        current = [
            _nodes_moved(d, displacements[k] if displacements else None, surfaces.get(k, set()))
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


def _nodes_moved(domain: Domain, u: dolfinx.fem.Function | None, groups: set[int]) -> np.ndarray:
    """The geometry nodes of ``domain``'s mesh, those of the facet ``groups`` displaced by
    ``u`` (interpolated on their cells)."""
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
    else:
        _interpolate(moved, u, 1e-6 * _size(mesh), cells)
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


def transfer_state(source: ContactProblem, target: ContactProblem, padding: float = 1e-6) -> None:
    """Set the unknowns of ``target`` (a problem on refined meshes of ``source``'s scene) to
    those of ``source`` moved onto its meshes (pointwise interpolation), and its pseudo-time
    to ``source``'s (collective). ``padding``: the distance, relative to the scene's size,
    within which a point outside the source's cells (a node put onto a curved boundary) is
    still found."""
    size = source.scales()[0]
    for old, new in zip(source.unknowns, target.unknowns, strict=True):
        if old.function_space.mesh.topology.dim == 0 or old.x.index_map.size_global <= 1:
            new.x.array[:] = old.x.array  # a control's global unknown
            continue
        _interpolate(new, old, padding * size)
    target.set_time(source.t)


def _interpolate(
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


def has_history(scene: Scene) -> bool:
    """Whether the state of ``scene`` depends on its load path: friction or plasticity."""
    from contact_ufl.plasticity import J2Plasticity

    frictional = any(c.mu > 0.0 for c in scene.contacts)
    plastic = any(isinstance(b.material, J2Plasticity) for d in scene.parts for b in d.bodies)
    return bool(frictional or plastic)


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


def _check_estimable(scene: Scene) -> None:
    """Refuse, before any work, the bodies the error estimate does not cover yet."""
    from contact_ufl.plasticity import J2Plasticity

    for k, d in enumerate(scene.parts):
        for body in d.bodies:
            if body.membrane or isinstance(body.material, J2Plasticity):
                kind = "a membrane" if body.membrane else "an elastoplastic body"
                raise NotImplementedError(
                    f"{d.name or f'mesh {k}'} has {kind} (tag {body.tag}): the error estimate, "
                    "and so adaptive refinement, covers hyperelastic solids only"
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


def refine_to_tolerance(
    scene: Scene,
    solve: Callable[[ContactProblem], object],
    tolerance: float,
    max_unknowns: int,
    theta: float = 0.5,
    max_levels: int = 10,
    boundaries: Mapping[int | str, Boundary] | None = None,
    problem_options: Mapping | None = None,
    on_level: Callable[[ContactProblem, Level], None] | None = None,
) -> AdaptiveSolve:
    """Solve ``scene``, refine its meshes where the error estimate says, and solve again,
    until the relative estimate (over the solution's energy norm) is at most ``tolerance``
    or the next mesh would exceed ``max_unknowns`` (collective).

    Parameters
    ----------
    scene
        The scene on its starting meshes (simplices).
    solve
        The load path, ``solve(problem)``: e.g. ``lambda p: p.solve(num_steps=4)``. It runs
        on the first mesh, and on every mesh of a scene with history (friction,
        plasticity); a scene without history starts each later mesh from the last solution
        moved onto it and brings that to equilibrium at the same load (its load path
        replayed if that fails).
    tolerance
        The target of :attr:`ErrorEstimate.relative
        <contact_ufl.estimate.ErrorEstimate.relative>`, > 0.
    max_unknowns
        The budget: no mesh with more unknowns is solved on.
    theta
        Doerfler's fraction (:func:`doerfler_marking`), in (0, 1].
    max_levels
        At most this many meshes.
    boundaries
        Curved facet groups and the functions that put points onto them
        (:func:`refine_scene`).
    problem_options
        Keyword arguments of :class:`~contact_ufl.problem.ContactProblem` (``degree``,
        ``petsc_options``, ...).
    on_level
        Called with the problem and its :class:`Level` after each solve (e.g. to write
        pictures of the meshes and indicators).

    Returns
    -------
    :class:`AdaptiveSolve`: the problem on the last mesh, its estimate, the levels.
    """
    comm = scene.parts[0].mesh.comm
    options = dict(problem_options or {})
    _check_loop_input(comm, tolerance, max_unknowns, theta, max_levels)
    check_refinable(scene)
    check_boundaries(scene, boundaries or {})
    _check_estimable(scene)
    history = has_history(scene)
    problem = ContactProblem(scene, **options)
    _check_budget(problem, max_unknowns, first=True)
    levels: list[Level] = []
    previous = None
    while True:
        start = time.perf_counter()
        kind = "load path"
        if previous is None or history:
            solve(problem)
        else:
            problem, kind = _solve_from(previous, problem, solve, options)
            previous.close()
        estimate = problem.error_estimate()
        level = Level(
            unknowns=problem.layout.global_size,
            cells=[_num_cells(b.V.mesh) for b in problem.bulks],
            estimate=estimate.estimate,
            relative=estimate.relative,
            newton_iterations=sum(r.newton_iterations for r in problem.history.steps),
            wall=time.perf_counter() - start,
            start=kind,
        )
        levels.append(level)
        if on_level is not None:
            on_level(problem, level)
        result = AdaptiveSolve(problem, estimate, levels)
        if level.relative <= tolerance:
            result.reached, result.stopped_by = True, "tolerance"
            return result
        if len(levels) >= max_levels:
            result.stopped_by = "levels"
            return result
        marked = doerfler_marking(estimate.indicators, theta, comm)
        scene = refine_scene(problem.scene, marked, boundaries)
        moved = [b.u for b in problem.bulks]
        scene = slave_finer_than_master(scene, moved, boundaries)
        finer = ContactProblem(scene, **options)
        if not _check_budget(finer, max_unknowns):
            finer.close()
            result.stopped_by = "budget"
            return result
        if history:
            problem.close()
        previous, problem = problem, finer


def _solve_from(
    previous: ContactProblem, problem: ContactProblem, solve, options: dict
) -> tuple[ContactProblem, str]:
    """Solve ``problem`` from the state of ``previous`` moved onto it, at its load; where
    that fails, a new problem on the same meshes along the load path. The problem solved
    and which start it took."""
    transfer_state(previous, problem)
    problem.resume_solver()
    try:
        problem.stepper.equilibrate()
        return problem, "moved state"
    except ConvergenceError:
        scene = problem.scene
        problem.close()
    problem = ContactProblem(scene, **options)
    solve(problem)
    return problem, "load path"


def _num_cells(mesh: dolfinx.mesh.Mesh) -> int:
    return mesh.topology.index_map(mesh.topology.dim).size_global


def _check_loop_input(comm, tolerance, max_unknowns, theta, max_levels) -> None:
    def number(value) -> bool:
        return isinstance(value, int | float | np.number) and not isinstance(value, bool)

    collective_check(
        comm,
        number(tolerance) and tolerance > 0.0,
        f"tolerance must be a number > 0 (a relative error estimate), got {tolerance!r}",
    )
    collective_check(
        comm,
        isinstance(max_unknowns, int | np.integer) and max_unknowns > 0,
        f"max_unknowns must be a whole number > 0, got {max_unknowns!r}",
    )
    collective_check(
        comm,
        number(theta) and 0.0 < theta <= 1.0,
        f"theta (Doerfler's fraction) must be in (0, 1], got {theta!r}",
    )
    collective_check(
        comm,
        isinstance(max_levels, int | np.integer) and max_levels >= 1,
        f"max_levels must be a whole number >= 1, got {max_levels!r}",
    )


def _check_budget(problem: ContactProblem, max_unknowns: int, first: bool = False) -> bool:
    """Whether ``problem`` is within the budget; on the starting mesh, an error if not."""
    n = problem.layout.global_size
    if first and n > max_unknowns:
        problem.close()
        raise ContactInputError(
            f"the starting meshes have {n} unknowns, more than max_unknowns = {max_unknowns}: "
            "raise the budget or start from coarser meshes"
        )
    return n <= max_unknowns
