"""Meshes from gmsh: a ``.msh`` file or a live gmsh model, distributed over the MPI ranks.

The mesh is read on one rank (``rank``, 0 by default) and distributed by
:func:`dolfinx.io.gmsh.model_to_mesh`. The cells of the highest dimension become the mesh;
the physical groups of that dimension are the cell tags (bodies), those one dimension lower
the facet tags (boundary parts: supports, loads, contact surfaces). Every physical group
is also known by its name (:attr:`MeshData.groups`), so a scene can say ``"block_bottom"``
where it would say ``14``.

Typical use::

    data = read_gmsh("two_blocks.msh")           # or read_gmsh(gmsh.model) after meshing
    data.groups                                  # {"upper": (2, 1), "upper_contact": (1, 11), ...}

Bad input (a missing file, a model without mesh or physical groups, a dimension that does
not match, unnamed or twice-used names) raises :class:`~contact_ufl.errors.ContactInputError`
on every rank.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import dolfinx
import dolfinx.io.gmsh
import gmsh
import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from contact_ufl.errors import ContactInputError
from contact_ufl.partition import PARTITIONS, cell_partitioner

__all__ = ["MeshData", "gmsh_session", "read_gmsh", "generate_mesh"]

#: Physical group name -> (dimension, tag).
Groups = dict[str, tuple[int, int]]

#: Environment variable naming the default partition (``bodies`` or ``graph``).
PARTITION_VARIABLE = "CONTACT_UFL_PARTITION"
#: The environment variable that makes :func:`gmsh_session` pass gmsh's messages to the
#: terminal (``1``) rather than silence them (the default), to see a mesher at work.
GMSH_VERBOSE_VARIABLE = "CONTACT_UFL_GMSH_VERBOSE"


@dataclass(frozen=True, eq=False)
class MeshData:
    """A DOLFINx mesh with its cell and facet tags and the names of its physical groups.

    Attributes
    ----------
    mesh
        The mesh (distributed over the ranks of its communicator).
    cell_tags
        Cell markers: the physical groups of the cells (bodies).
    facet_tags
        Facet markers: the physical groups one dimension lower (boundary parts); empty if
        the model has none.
    groups
        Physical group name -> ``(dimension, tag)``, the same on every rank.
    """

    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTags
    facet_tags: dolfinx.mesh.MeshTags
    groups: Groups

    @property
    def tags(self) -> dict[str, int]:
        """Physical group name -> tag value (the dimension left out)."""
        return {name: tag for name, (_, tag) in self.groups.items()}

    def cells(self, name: str) -> npt.NDArray[np.int32]:
        """Local indices (owned and ghost) of the cells of the group ``name``."""
        return self.cell_tags.find(self.tags[name])

    def facets(self, name: str) -> npt.NDArray[np.int32]:
        """Local indices (owned and ghost) of the facets of the group ``name``."""
        return self.facet_tags.find(self.tags[name])


@contextmanager
def gmsh_session(
    name: str, options: dict[str, float] | None = None, verbose: bool | None = None
) -> Iterator[None]:
    """Work in a fresh gmsh model, and clean up afterwards.

    Initialises gmsh unless it is initialised already (then finalises it on exit), silences the
    terminal unless ``verbose``, adds a model ``name`` and makes it current, and sets the
    numeric ``options``.
    On exit the model is removed; if gmsh was initialised by the caller, the options and the
    previous current model are restored.

    Parameters
    ----------
    name
        Name of the gmsh model.
    options
        Numeric gmsh options, e.g. ``{"Mesh.Algorithm": 6}``.
    verbose
        Pass gmsh's messages to the terminal (default: whether the environment variable
        :data:`GMSH_VERBOSE_VARIABLE` is ``1``), e.g. to see where a mesher hangs.

    Yields
    ------
    None
        Use the ``gmsh`` module API inside the block.
    """
    initialised_here = not gmsh.isInitialized()
    if initialised_here:
        gmsh.initialize(interruptible=False)
    if verbose is None:
        verbose = os.environ.get(GMSH_VERBOSE_VARIABLE, "0") not in ("", "0")
    all_options = {"General.Terminal": float(bool(verbose)), **(options or {})}
    saved = {key: gmsh.option.getNumber(key) for key in all_options}
    previous = gmsh.model.getCurrent() if not initialised_here else None
    try:
        for key, value in all_options.items():
            gmsh.option.setNumber(key, value)
        gmsh.model.add(name)
        yield
    finally:
        if initialised_here:
            gmsh.finalize()
        else:
            gmsh.model.remove()
            for key, value in saved.items():
                gmsh.option.setNumber(key, value)
            if previous:
                try:
                    gmsh.model.setCurrent(previous)
                except Exception:  # the caller's model may have gone: nothing to restore
                    pass


@contextmanager
def _session_on(
    comm: MPI.Comm, rank: int, name: str, options: dict[str, float] | None = None
) -> Iterator[None]:
    """A :func:`gmsh_session` on rank ``rank`` of ``comm``, nothing on the other ranks."""
    if comm.rank == rank:
        with gmsh_session(name, options):
            yield
    else:
        yield


def _raise_from(comm: MPI.Comm, rank: int, error: str | None) -> None:
    """Raise ``ContactInputError(error)`` on every rank if rank ``rank`` found an error."""
    error = comm.bcast(error, root=rank)
    if error is not None:
        raise ContactInputError(error)


def read_gmsh(
    source: str | os.PathLike | Any,
    comm: MPI.Comm = MPI.COMM_WORLD,
    gdim: int | None = None,
    rank: int = 0,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
    require_names: bool = False,
    tdim: int | None = None,
    partition: str | None = None,
    contact_surfaces: Sequence[str | int] = (),
) -> MeshData:
    """Read a mesh and its physical groups from a ``.msh`` file or a live gmsh model.

    Parameters
    ----------
    source
        Path of a ``.msh`` file, or the live model (``gmsh.model``, meshed, with physical
        groups). Only rank ``rank`` reads it: the other ranks may pass ``None``.
    comm
        Communicator of the mesh.
    gdim
        Geometric dimension of the mesh (default: the dimension of the model). With
        ``gdim < 3`` the nodes must lie in the plane (line) of the first ``gdim`` axes.
    rank
        The rank of ``comm`` that reads the file or holds the model.
    ghost_mode
        Ghost mode of the cell partitioner (shared facets: what the contact search needs).
    require_names
        Refuse physical groups without a name (a scene that looks tags up by name).
    tdim
        The topological dimension the caller needs (a scene of solid bodies: ``gdim``);
        refuse a mesh of another dimension.
    partition
        How the cells are spread over the ranks: ``"bodies"`` splits every body (connected
        piece of the mesh) over all the ranks, so that each rank holds a share of every
        contact surface (:mod:`contact_ufl.partition`); ``"graph"`` is DOLFINx's partition
        of the whole mesh, which puts whole bodies on ranks. Default: the environment
        variable ``CONTACT_UFL_PARTITION``, else ``"bodies"``.
    contact_surfaces
        The facet groups (names or tags) of the contact pairs: with ``"bodies"`` every rank
        also gets an equal share of the cells along them (of the slave points and master
        facets, where the contact work is). Names and tags the mesh has no facet group of are
        passed over (a scene checks its pairs' names itself).

    Returns
    -------
    MeshData
        The mesh, its cell and facet tags and the physical group names.

    Raises
    ------
    ContactInputError
        On every rank: the file is missing or unreadable, the model has no mesh or no
        physical group of its cells, the dimension does not match ``gdim``/``tdim``, a name
        is used by two groups, (with ``require_names``) a group has no name, or
        ``partition`` is unknown.
    """
    partition = _partition(partition)
    is_file = comm.bcast(
        isinstance(source, str | os.PathLike) if comm.rank == rank else None, root=rank
    )
    mine = comm.rank == rank

    def distribute(model: Any, origin: str) -> MeshData:
        how = (ghost_mode, partition, tuple(contact_surfaces))
        return _distribute(model, comm, rank, gdim, how, require_names, tdim, origin)

    if not is_file:
        return distribute(source if mine else None, "the gmsh model")
    with _session_on(comm, rank, "msh"):
        _raise_from(comm, rank, _merge(Path(source)) if mine else None)
        return distribute(gmsh.model if mine else None, f"mesh file '{source}'" if mine else "")


def _partition(partition: str | None) -> str:
    """The partition asked for, else the environment's, else ``"bodies"``; checked."""
    chosen = partition or os.environ.get(PARTITION_VARIABLE) or "bodies"
    if chosen not in PARTITIONS:
        source = "partition" if partition else PARTITION_VARIABLE
        raise ContactInputError(f"{source} = '{chosen}' is unknown: use one of {PARTITIONS}")
    return chosen


def _merge(path: Path) -> str | None:
    """Merge the file ``path`` into the current gmsh model; an error message or ``None``."""
    if not path.is_file():
        return f"mesh file '{path}' does not exist"
    try:
        gmsh.merge(str(path))
    except Exception as exc:  # gmsh's own message, raised collectively by the caller
        return f"gmsh could not read the mesh file '{path}': {exc}"
    return None


def _distribute(
    model: Any,
    comm: MPI.Comm,
    rank: int,
    gdim: int | None,
    how: tuple[dolfinx.mesh.GhostMode, str, tuple[str | int, ...]],
    require_names: bool,
    tdim: int | None,
    origin: str,
) -> MeshData:
    """Check the model on ``rank``, then build the distributed mesh and the name table."""
    summary = None
    if comm.rank == rank:
        if model is None:
            summary = ("no gmsh model was given on the rank that reads it", 0, {}, "")
        else:
            summary = _inspect(model, gdim, tdim, require_names, origin)
    error, model_dim, groups, name = comm.bcast(summary, root=rank)
    _raise_from(comm, rank, error)
    gdim = model_dim if gdim is None else gdim
    facets, error = None, None
    if comm.rank == rank and how[1] == "bodies":
        try:  # a gmsh error here must not leave the other ranks waiting
            tags = _facet_groups(groups, model_dim, how[2])
            facets = [_facet_vertices(model, model_dim - 1, [tag]) for tag in tags]
        except Exception as e:
            error = f"could not read the contact surfaces' facets from the gmsh model: {e}"
    _raise_from(comm, rank, error)
    partitioner = cell_partitioner(how[1], how[0], facets)
    data = dolfinx.io.gmsh.model_to_mesh(
        model if comm.rank == rank else None, comm, rank, gdim=gdim, partitioner=partitioner
    )
    data.mesh.name = name
    facet_tags = data.facet_tags
    if facet_tags is None:
        empty = np.empty(0, dtype=np.int32)
        facet_tags = dolfinx.mesh.meshtags(data.mesh, model_dim - 1, empty, empty)
    return MeshData(data.mesh, data.cell_tags, facet_tags, groups)


def _facet_groups(groups: Groups, dim: int, surfaces: tuple[str | int, ...]) -> list[int]:
    """The tags of the facet groups among ``surfaces`` (names or tags; others passed over)."""
    tags = []
    for key in surfaces:
        if isinstance(key, str):
            if key in groups and groups[key][0] == dim - 1:
                tags.append(groups[key][1])
        elif isinstance(key, int | np.integer):
            tags.append(int(key))
    return sorted(set(tags))


def _facet_vertices(model: Any, fdim: int, tags: list[int]) -> list[npt.NDArray[np.int64]]:
    """The vertices (gmsh node tags - 1: the mesh's input numbering) of the facets of the
    physical groups ``tags`` of dimension ``fdim``, one ``(n, k)`` array per facet shape."""
    known = {int(t) for d, t in model.getPhysicalGroups() if d == fdim}
    by_width: dict[int, list[npt.NDArray[np.int64]]] = {}
    for tag in tags:
        if tag not in known:
            continue
        for entity in model.getEntitiesForPhysicalGroup(fdim, tag):
            types, _, nodes = model.mesh.getElements(fdim, int(entity))
            for kind, block in zip(types, nodes, strict=True):
                properties = model.mesh.getElementProperties(kind)
                count, corners = int(properties[3]), int(properties[5])
                vertices = np.asarray(block, dtype=np.int64).reshape(-1, count)[:, :corners] - 1
                by_width.setdefault(corners, []).append(vertices)
    return [np.concatenate(blocks) for blocks in by_width.values()]


def _inspect(
    model: Any, gdim: int | None, tdim: int | None, require_names: bool, origin: str
) -> tuple[str | None, int, Groups, str]:
    """``(error, dimension, groups, model name)`` of a gmsh model (on the reading rank)."""
    dim = int(model.getDimension())
    name = model.getCurrent()
    groups = model.getPhysicalGroups()

    def fail(message: str) -> tuple[str, int, Groups, str]:
        return message, dim, {}, name

    if dim < 1 or _count_elements(model, dim, model.getEntities(dim)) == 0:
        return fail(f"{origin} holds no mesh: generate it first (gmsh.model.mesh.generate)")
    if tdim is not None and dim != tdim:
        return fail(
            f"{origin} holds a mesh of dimension {dim}, but {tdim}D cells are needed "
            f"(solid bodies fill their {tdim}D space)"
        )
    if gdim is not None and gdim < dim:
        return fail(f"{origin} holds a mesh of dimension {dim}: gdim = {gdim} is too small")
    if (gdim or dim) < 3:
        x = model.mesh.getNodes()[1].reshape(-1, 3)
        scale = max(float(np.ptp(x[:, : gdim or dim], axis=0).max()), 1.0)
        if np.abs(x[:, gdim or dim :]).max() > 1e-12 * scale:
            return fail(
                f"{origin}: the mesh is not in the first {gdim or dim} coordinate axes "
                f"(a {gdim or dim}D mesh needs z = 0)"
            )
    if not any(d == dim for d, _ in groups):
        return fail(
            f"{origin} has no physical group of dimension {dim}: every cell must belong "
            "to one (a body)"
        )
    table: Groups = {}
    unnamed = []
    for d, tag in groups:
        group_name = model.getPhysicalName(d, tag)
        if _count_elements(model, d, model.getEntitiesForPhysicalGroup(d, tag)) == 0:
            return fail(f"{origin}: physical group '{group_name or tag}' has no mesh element")
        if not group_name:
            unnamed.append((d, tag))
        elif group_name in table:
            return fail(
                f"{origin}: the name '{group_name}' is used by two physical groups, "
                f"(dim, tag) = {table[group_name]} and {(d, tag)}"
            )
        else:
            table[group_name] = (int(d), int(tag))
    if require_names and unnamed:
        return fail(
            f"{origin}: physical groups without a name, (dim, tag) = {unnamed}; "
            "name every group (gmsh.model.addPhysicalGroup(dim, entities, name=...))"
        )
    return None, dim, table, name


def _count_elements(model: Any, dim: int, entities: Any) -> int:
    """Number of mesh elements of dimension ``dim`` on the given entities."""
    count = 0
    for entity in entities:
        tag = entity[1] if isinstance(entity, tuple) else entity
        _, element_tags, _ = model.mesh.getElements(dim, tag)
        count += sum(len(t) for t in element_tags)
    return count


def generate_mesh(
    comm: MPI.Comm,
    name: str,
    build: Callable[[], None],
    gdim: int,
    options: dict[str, float] | None = None,
    msh_file: str | Path | None = None,
    ghost_mode: dolfinx.mesh.GhostMode = dolfinx.mesh.GhostMode.shared_facet,
    rank: int = 0,
    partition: str | None = None,
    contact_surfaces: Sequence[str] = (),
) -> MeshData:
    """Run ``build`` (geometry, size fields, named groups, meshing) in a fresh gmsh model on
    rank ``rank`` and distribute the mesh (:func:`read_gmsh`).

    Errors of ``build`` on that rank are raised on every rank. With ``msh_file`` the gmsh
    mesh is also written there. ``partition``, ``contact_surfaces``: see :func:`read_gmsh`.
    """
    error = None
    with _session_on(comm, rank, name, options):
        if comm.rank == rank:
            try:
                build()
                if msh_file is not None:
                    path = Path(msh_file)
                    path.parent.mkdir(parents=True, exist_ok=True)
                    gmsh.write(str(path))
            except Exception as exc:  # made collective just below
                error = f"{type(exc).__name__}: {exc}"
        error = comm.bcast(error, root=rank)
        if error is not None:
            raise RuntimeError(f"building the gmsh model '{name}' failed: {error}")
        model = gmsh.model if comm.rank == rank else None
        return read_gmsh(
            model,
            comm,
            gdim,
            rank,
            ghost_mode,
            require_names=True,
            partition=partition,
            contact_surfaces=contact_surfaces,
        )
