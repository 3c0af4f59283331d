"""Output: VTX files for ParaView, a time series of the contact surfaces that ParaView and
pyvista open (``.pvd``), and off-screen pictures with pyvista.

Every picture is written as a PNG file by rank 0 only; inside a Jupyter (IPython) kernel it
is also shown inline.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

import dolfinx
import numpy as np
from mpi4py import MPI

from contact_ufl.estimate import TERMS, check_estimable

if TYPE_CHECKING:
    import pyvista

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


class ResultWriter:
    """Write the displacement and the multipliers of every load step to VTX (ADIOS2) files,
    and the contact surfaces to ``.pvd`` time series (collective).

    Files are flushed at every step, so results already written survive a later failure.
    ParaView opens both kinds; pyvista (and VTK without ADIOS2) reads only the ``.pvd``
    series.

    A problem restarted from the checkpoint of step ``n`` (:meth:`ContactProblem.restart
    <contact_ufl.problem.ContactProblem.restart>`) writes its VTX files beside the first
    run's, named ``<name>_from_step_<n>.bp`` (those of the first run are kept), and goes on
    with the ``.pvd`` series after its step ``n``.

    Parameters
    ----------
    problem
        The contact problem.
    folder
        Output folder; ``displacement.bp`` (with several meshes ``displacement_<k>.bp``, one
        per mesh ``k``), ``contact_<k>.bp`` (the multipliers of pair ``k``) and, for each
        elastoplastic body, ``plastic_strain_<tag>.bp`` (the cell means of its equivalent
        plastic strain) are written there.
    contact_surfaces
        Also write ``contact_surface_<k>.pvd`` for each pair ``k``: its slave points at
        every step (:class:`ContactSurfaceWriter`).
    error_indicators
        Also write the error indicators of every step (:meth:`ContactProblem.error_estimate
        <contact_ufl.problem.ContactProblem.error_estimate>`, ``eta_K^2`` per cell) to
        ``error_indicators.bp`` (``error_indicators_<k>.bp`` per mesh), and the estimate,
        its value relative to the solution's energy norm and its terms to
        ``error_estimate.csv``, one line a step (solids only: a membrane is refused).
    """

    def __init__(
        self,
        problem,
        folder: str | Path,
        contact_surfaces: bool = True,
        error_indicators: bool = False,
    ):
        if error_indicators:  # refused before any file is opened
            check_estimable(problem.scene)
        folder = Path(folder)
        if problem.comm.rank == 0:
            folder.mkdir(parents=True, exist_ok=True)
        problem.comm.barrier()
        comm = problem.comm
        bulks = problem.bulks
        names = (
            ["displacement"]
            if len(bulks) == 1
            else [f"displacement_{k}" for k in range(len(bulks))]
        )
        restored = getattr(problem, "restored_from", None)
        suffix = "" if restored is None else f"_from_step_{restored[1]}"
        self.writers = [
            dolfinx.io.VTXWriter(comm, folder / f"{name}{suffix}.bp", [b.u])
            for name, b in zip(names, bulks, strict=True)
        ]
        for k, c in enumerate(problem.contacts):
            multipliers = [c.lambda_N] + ([c.friction.lambda_T] if c.friction else [])
            path = folder / f"contact_{k}{suffix}.bp"
            self.writers.append(dolfinx.io.VTXWriter(comm, path, multipliers))
        self.histories = [h for b in bulks for h in b.histories.values()]
        for tag, h in ((tag, h) for b in bulks for tag, h in b.histories.items()):
            path = folder / f"plastic_strain_{tag}{suffix}.bp"
            self.writers.append(dolfinx.io.VTXWriter(comm, path, [h.plastic_strain]))
        self.surfaces = [
            ContactSurfaceWriter(problem, folder / f"contact_surface_{k}.pvd", k)
            for k in range(len(problem.contacts) if contact_surfaces else 0)
        ]
        self.estimates = (
            _EstimateWriter(problem, folder, [n.replace("displacement", "") for n in names], suffix)
            if error_indicators
            else None
        )
        if self.estimates:
            self.writers += self.estimates.writers

    def write(self, t: float) -> None:
        """Write the current state at pseudo-time ``t``."""
        for h in self.histories:
            h.update_plastic_strain()
        if self.estimates:
            self.estimates.update(t)
        for w in self.writers:
            w.write(t)
        for w in self.surfaces:
            w.write(t)

    def close(self) -> None:
        """Close the files."""
        for w in self.writers:
            w.close()
        for w in self.surfaces:
            w.close()

    def __call__(self, problem, record) -> None:
        """Use as the ``callback`` of :meth:`ContactProblem.solve`."""
        self.write(record.t)


class _EstimateWriter:
    """The error indicators of each mesh (DG0, VTX) and the estimate's lines of
    ``error_estimate.csv`` (rank 0) of a :class:`ResultWriter`."""

    def __init__(self, problem, folder: Path, endings: list[str], suffix: str):
        self.problem = problem
        self.fields = []
        for bulk in problem.bulks:
            field = dolfinx.fem.Function(dolfinx.fem.functionspace(bulk.V.mesh, ("DG", 0)))
            field.name = "error_indicator"
            self.fields.append(field)
        comm = problem.comm
        self.writers = [
            dolfinx.io.VTXWriter(comm, folder / f"error_indicators{end}{suffix}.bp", [f])
            for f, end in zip(self.fields, endings, strict=True)
        ]
        self.table = folder / f"error_estimate{suffix}.csv"
        if comm.rank == 0:
            header = ",".join(["t", "estimate", "relative", *TERMS])
            self.table.write_text(header + "\n")

    def update(self, t: float) -> None:
        """The indicators and the estimate of the current state (collective)."""
        estimate = self.problem.error_estimate()
        for field, eta in zip(self.fields, estimate.indicators, strict=True):
            field.x.array[:] = eta.x.array
        if self.problem.comm.rank == 0:
            values = [t, estimate.estimate, estimate.relative]
            values += [estimate.parts[name] for name in TERMS]
            with self.table.open("a") as f:
                f.write(",".join(f"{v:.10g}" for v in values) + "\n")


class ContactSurfaceWriter:
    """Write the slave surface of a contact pair at every load step as a ``.pvd`` time
    series: one ``.vtu`` file a step, which ParaView and pyvista open (collective).

    Each step's file holds the surface of :func:`gathered_contact_surface` (the slave
    quadrature points at their current positions, joined facet by facet) with its point
    data: ``lambda_N``, ``pressure``, ``gap`` (NaN where no master facet was found),
    ``in_contact`` (1 or 0), ``t_N``, ``traction``, ``t_T``, the reference positions ``X``,
    with friction ``stick`` (1 or 0) and, in 2D, ``arc_length`` and ``arc_length_current``
    (see :class:`~contact_ufl.results.ContactSamples`). The points of all ranks are gathered
    and rank 0 writes the files, once; the ``.pvd`` file is rewritten at every step, so it
    lists the steps written so far.

    Parameters
    ----------
    problem
        The contact problem.
    path
        The ``.pvd`` file; the step files go into the folder of that name without its
        suffix, beside it.
    pair
        The contact pair.

    Examples
    --------
    Read it back with pyvista (``read()`` gives a one-block ``MultiBlock``)::

        reader = pyvista.get_reader("output/contact_surface_0.pvd")
        for t in reader.time_values:
            reader.set_active_time_value(t)
            surface = reader.read()[0]
    """

    def __init__(self, problem, path: str | Path, pair: int = 0):
        if not 0 <= pair < len(problem.contacts):
            raise ValueError(f"no contact pair {pair}: the problem has {len(problem.contacts)}")
        self.problem, self.pair = problem, pair
        self.path = Path(path).with_suffix(".pvd")
        self.folder = self.path.with_suffix("")
        self.steps: list[tuple[float, str]] = []
        restored = getattr(problem, "restored_from", None)
        if restored is not None:  # go on after the restart's step, drop the later ones
            self.steps = [(t, f) for t, f in _series(self.path) if t <= restored[2]]
        if problem.comm.rank == 0:
            self.folder.mkdir(parents=True, exist_ok=True)
        problem.comm.barrier()

    def write(self, t: float) -> None:
        """Write the current state of the surface at pseudo-time ``t`` (collective)."""
        surface = gathered_contact_surface(self.problem, self.pair)
        name = f"{self.folder.name}/step_{len(self.steps):05d}.vtu"
        self.steps.append((float(t), name))
        if surface is None:
            return
        pv = _pyvista()
        pv.UnstructuredGrid(surface).save(self.path.parent / name)
        entries = "".join(
            f'    <DataSet timestep="{t!r}" part="0" file={quoteattr(file)}/>\n'
            for t, file in self.steps
        )
        text = (
            '<?xml version="1.0"?>\n<VTKFile type="Collection" version="1.0">\n'
            f"  <Collection>\n{entries}  </Collection>\n</VTKFile>\n"
        )
        partial = self.path.with_name(self.path.name + ".part")
        partial.write_text(text)
        partial.replace(self.path)  # a reader never sees half a file

    def close(self) -> None:
        """Nothing to close: every file is complete once written (for symmetry with
        :class:`ResultWriter`)."""

    def __call__(self, problem, record) -> None:
        """Use as the ``callback`` of :meth:`ContactProblem.solve`."""
        self.write(record.t)


def _series(path: Path) -> list[tuple[float, str]]:
    """The steps of a ``.pvd`` series written by :class:`ContactSurfaceWriter` (none if
    there is no such file)."""
    if not path.is_file():
        return []
    entries = re.findall(r'timestep="([^"]*)"[^>]*file="([^"]*)"', path.read_text())
    return [(float(t), file) for t, file in entries]


def say(text: str, comm=None) -> None:
    """Print ``text`` on rank 0 of ``comm`` (default: ``MPI.COMM_WORLD``), flushed: the
    progress lines of a script that runs on any number of ranks."""
    from mpi4py import MPI

    if (comm or MPI.COMM_WORLD).rank == 0:
        print(text, flush=True)


def _pyvista():
    import pyvista

    pyvista.OFF_SCREEN = True
    return pyvista


def gathered_grid(
    problem, deformed: bool = True, cell_data: dict[str, dolfinx.fem.Function] | None = None
) -> pyvista.UnstructuredGrid | None:
    """The meshes of all ranks as one pyvista grid on rank 0 (``None`` on the other ranks).

    Each rank contributes the owned cells of every mesh; the point data hold the
    displacement, and the cell data ``"body"`` the cell tag of each cell, plus the cellwise
    (DG0) functions of ``cell_data`` under their keys (NaN on the cells of other meshes).
    With ``deformed`` the grid is warped by the displacement.
    """
    pv = _pyvista()
    mine = [_owned_cells(b, cell_data or {}) for b in problem.bulks]
    local = (
        [part[0] for part in mine],
        *(np.concatenate([p[i] for p in mine]) for i in range(1, 5)),
        {name: np.concatenate([p[5][name] for p in mine]) for name in cell_data or {}},
    )
    parts = problem.comm.gather(local, root=0)
    if problem.comm.rank != 0:
        return None
    offset, all_cells = 0, []
    for blocks, *_ in parts:
        for block, count in blocks:  # one block of cells of one mesh on one rank
            shifted = block.copy()
            shifted[:, 1:] += offset
            all_cells.append(shifted.ravel())
            offset += count
    grid = pv.UnstructuredGrid(
        np.concatenate(all_cells),
        np.concatenate([p[1] for p in parts]),
        np.concatenate([p[2] for p in parts]),
    )
    grid.point_data["displacement"] = np.concatenate([p[3] for p in parts])
    grid.cell_data["body"] = np.concatenate([p[4] for p in parts])
    for name in cell_data or {}:
        grid.cell_data[name] = np.concatenate([p[5][name] for p in parts])
    return grid.warp_by_vector("displacement") if deformed else grid


def _owned_cells(bulk, cell_data: dict[str, dolfinx.fem.Function]) -> tuple:
    """The owned cells of the mesh of ``bulk`` as VTK arrays: the cells ``(n, 1 + nv)``
    (count first) with the number of points, the cell types, points, displacement
    ``(npts, 3)``, body tags and cell data."""
    V = bulk.V
    mesh = V.mesh
    tdim, gdim = mesh.topology.dim, mesh.geometry.dim
    topology, cell_types, x = dolfinx.plot.vtk_mesh(V)
    owned = mesh.topology.index_map(tdim).size_local
    cells = topology.reshape(len(cell_types), -1)[:owned]
    u = np.zeros((x.shape[0], 3))
    u[:, :gdim] = bulk.u.x.array.reshape(-1, gdim)[: x.shape[0]]
    body = np.zeros(owned, dtype=np.int32)
    tags = bulk.domain.cell_tags
    local = tags.indices < owned
    body[tags.indices[local]] = tags.values[local]
    fields = {
        name: f.x.array[f.function_space.dofmap.list[:owned, 0]]
        if f.function_space.mesh is mesh
        else np.full(owned, np.nan)
        for name, f in cell_data.items()
    }
    return (cells, len(x)), cell_types[:owned], x, u, body, fields


_DIRECTIONS = {"iso": (0.7, -1.0, 0.6), "xz": (0.0, -1.0, 0.0), "xy": (0.0, 0.0, 1.0)}


def _direction(view: str | tuple[float, float, float]) -> tuple[float, ...]:
    """The direction to look from of the camera ``view`` (see :func:`_view`); a clear
    error for an unknown name or a direction that is not 3 numbers, not all 0."""
    if isinstance(view, str):
        if view not in _DIRECTIONS:
            names = sorted(_DIRECTIONS)
            raise ValueError(f"view must be one of {names} or a direction, got {view!r}")
        return _DIRECTIONS[view]
    direction = tuple(float(v) for v in view)
    if len(direction) != 3 or not any(direction):
        raise ValueError(f"a view direction needs 3 components, not all 0, got {view!r}")
    return direction


def _default_view(view: str | tuple[float, float, float] | None, gdim: int):
    """The camera ``view``, or by default the plane view ``"xy"`` of a 2D scene and
    ``"iso"`` for a 3D one; validated (:func:`_direction`)."""
    if view is None:
        view = "xy" if gdim == 2 else "iso"
    _direction(view)
    return view


def _view(plotter, view: str | tuple[float, float, float]) -> None:
    """Camera: ``"iso"`` (3D view from the front, above and to the right), ``"xz"`` (the
    x-z plane seen from -y: the plane of bending of the beams), ``"xy"`` (seen from +z, the
    plane of a 2D scene: pyvista's ``view_xy``), or a direction ``(x, y, z)`` to look from
    (with +z up). The plane views are parallel projections: the angles in that plane are
    true."""
    if view == "xy":
        plotter.view_xy()
    else:
        plotter.view_vector(_direction(view), viewup=(0.0, 0.0, 1.0))
    if view in ("xz", "xy"):
        plotter.enable_parallel_projection()
    plotter.reset_camera()


def _focus(plotter, point) -> None:
    """Move the camera so that it looks at ``point``, in the same direction (pyvista's
    ``set_focus`` turns it instead, which tilts a plane view out of its plane)."""
    camera = plotter.camera
    shift = np.asarray(point, dtype=float) - np.asarray(camera.focal_point)
    position = np.asarray(camera.position) + shift
    camera.focal_point = tuple(np.asarray(camera.focal_point) + shift)
    camera.position = tuple(position)


def in_jupyter_kernel() -> bool:
    """Whether this process is a Jupyter (IPython) kernel.

    IPython is not imported: a kernel has imported it already, and without it (or in a
    terminal IPython, which has no kernel) the answer is ``False``.
    """
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    shell = ipython.get_ipython()
    return getattr(shell, "kernel", None) is not None


def show_inline(path: str | Path) -> None:
    """Show the PNG file ``path`` as a cell output when running inside a Jupyter kernel,
    on rank 0 only; elsewhere do nothing."""
    if MPI.COMM_WORLD.rank != 0 or not in_jupyter_kernel():
        return
    from IPython.display import Image, display

    display(Image(filename=str(path)))


def _save(plotter, path: str | Path) -> None:
    """Write the plotter's picture to ``path`` (creating its folder), close the plotter
    and show the picture inline in a Jupyter kernel."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(path))
    plotter.close()
    show_inline(path)


def _screenshot(plotter, path: str | Path, title: str) -> None:
    plotter.add_text(title, font_size=12)
    _save(plotter, path)


def plot_reference(
    problem, path: str | Path, view: str | tuple[float, float, float] | None = None, title: str = ""
) -> None:
    """The reference configuration: the mesh of every body, coloured by body (collective;
    rank 0 writes the picture). ``view``: the camera (see :func:`_view`); by default the
    plane view ``"xy"`` of a 2D scene, ``"iso"`` in 3D."""
    view = _default_view(view, problem.gdim)  # bad input fails on every rank
    grid = gathered_grid(problem, deformed=False)
    if grid is None:
        return
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=(1200, 700))
    plotter.add_mesh(grid, scalars="body", show_edges=True, cmap="Pastel1", show_scalar_bar=False)
    _view(plotter, view)
    _screenshot(plotter, path, title)


def _facet_cells(points_ref: np.ndarray) -> np.ndarray:
    """Cells joining the quadrature points of one slave facet, in its reference coordinates
    ``points_ref`` ``(nq, fdim)``: segments (``fdim = 1``) or triangles (``fdim = 2``), as
    local point indices ``(k, fdim + 1)``."""
    if points_ref.shape[1] == 1:
        order = np.argsort(points_ref[:, 0])
        return np.column_stack([order[:-1], order[1:]])
    from scipy.spatial import Delaunay

    return Delaunay(points_ref).simplices


def gathered_contact_surface(problem, pair: int = 0) -> pyvista.PolyData | None:
    """The deformed slave surface of contact pair ``pair`` as one pyvista surface on rank 0
    (``None`` on the other ranks).

    Its points are the slave quadrature points at their current positions; the
    quadrature points of each facet are joined into triangles (segments in 2D). Point
    data: ``"t_N"`` (the normal traction ``<lambda_N + eps_N g>``, 0 where open),
    ``"traction"`` (the contact traction on the slave body, nominal), ``"t_T"`` (its
    tangential part, the frictional traction; 0 without friction), and the samples of
    :func:`~contact_ufl.results.contact_samples`: ``"lambda_N"``, ``"pressure"``, ``"gap"``
    (NaN where no master facet was found), ``"in_contact"`` (1 where in contact, else 0),
    ``"X"`` (reference positions), with friction ``"stick"`` (1 or 0) and in 2D
    ``"arc_length"`` and ``"arc_length_current"``. Collective.
    """
    from contact_ufl.results import contact_samples

    samples = contact_samples(problem, pair)
    c = problem.contacts[pair]
    gdim = c.gdim
    n = c.slave.X.shape[0] * c.slave.X.shape[1]
    x, t = np.zeros((n, 3)), np.zeros((n, 3))
    x[:, :gdim] = c.slave.positions(c.u).reshape(-1, gdim)
    t_N = np.zeros(n)
    t_T = t.copy()
    if c.projection is not None:  # else not searched yet: no traction
        t_N = c.normal_traction_at_points()
        t[:, :gdim] = c.traction_at_points()
        t_T = t.copy()
        t_T[:, :gdim] -= t_N[:, None] * c.projection.normal.reshape(-1, gdim)
        t_T[t_N <= 0.0] = 0.0
    parts = problem.comm.gather((x, t_N, t, t_T), root=0)
    if problem.comm.rank != 0:
        return None
    pv = _pyvista()
    local = _facet_cells(c.slave.points_ref)
    nq = c.slave.num_points
    x, t_N, t, t_T = (np.concatenate([q[k] for q in parts]) for k in range(4))
    cells = local[None] + nq * np.arange(len(x) // nq)[:, None, None]
    cells = cells.reshape(-1, local.shape[1])
    prefixed = np.column_stack([np.full(len(cells), cells.shape[1]), cells]).ravel()
    surface = pv.PolyData(x, lines=prefixed) if local.shape[1] == 2 else pv.PolyData(x, prefixed)
    surface.point_data["t_N"] = t_N
    surface.point_data["traction"] = t
    surface.point_data["t_T"] = t_T
    for name, values in _sample_fields(samples).items():
        surface.point_data[name] = values
    return surface


def _sample_fields(samples) -> dict[str, np.ndarray]:
    """The contact samples as point data of a VTK file: vectors with 3 components, flags as
    0 or 1 (``uint8``), no infinite values (an unpaired point's gap is NaN)."""
    X = np.zeros((len(samples.x), 3))
    X[:, : samples.x.shape[1]] = samples.X
    fields = {
        "lambda_N": samples.lambda_N,
        "pressure": samples.pressure,
        "gap": np.where(np.isfinite(samples.gap), samples.gap, np.nan),
        "in_contact": samples.in_contact.astype(np.uint8),
        "X": X,
    }
    if samples.stick is not None:
        fields["stick"] = samples.stick.astype(np.uint8)
    if samples.arc_length is not None:
        fields["arc_length"] = samples.arc_length
        fields["arc_length_current"] = samples.arc_length_current
    return fields


def _arrows(
    points: pyvista.PolyData, vectors: str, length: float, saturate: float
) -> pyvista.PolyData:
    """Arrow glyphs at ``points`` along the point vectors ``vectors``: their lengths are
    proportional to the vectors' up to the ``saturate`` percentile of the nonzero ones,
    which is ``length`` long, and capped at that length above it."""
    norms = np.linalg.norm(points[vectors], axis=1)
    top = float(np.percentile(norms[norms > 0.0], saturate))
    points["length"] = norms
    return points.glyph(orient=vectors, scale="length", factor=length, clamping=True, rng=(0, top))


def plot_contact_state(
    problem,
    path: str | Path,
    view: str | tuple[float, float, float] | None = None,
    title: str = "",
    scale: float = 0.08,
    saturate: float = 100.0,
    zoom: float = 1.0,
    pair: int = 0,
) -> None:
    """The deformed bodies and the contact state of a pair (collective; rank 0 writes the
    picture).

    The bodies are drawn translucent; the slave surface is grey where open and coloured by
    the normal traction ``t_N`` (at a converged state the multiplier lambda_N) where in
    contact. In the ``"xz"`` view of a 3D scene and the ``"xy"`` view of a 2D one (the
    surface seen edge-on) the slave points in contact carry the contact tractions on the
    slave body as arrows coloured by ``t_N``. With friction, the frictional tractions
    ``t_T`` are black arrows, in every view.

    Parameters
    ----------
    problem
        The contact problem, at a converged state.
    path, view, title
        The PNG file, the camera (see :func:`_view`; by default the plane view ``"xy"`` of a
        2D scene, ``"iso"`` in 3D) and a title.
    scale
        Length of the longest arrows (those at or above the saturation value), relative to
        the scene's size (in 2D, to the size shown: divided by ``zoom``); the frictional
        arrows are half as long.
    saturate
        Percentile of the positive ``t_N`` taken as the top of the colour range (from 0):
        below 100, larger values (a peak at a corner) get the top colour, and the colour
        bar's title gives the largest value. The arrow lengths saturate the same way (at
        that percentile of the traction's, or the frictional traction's, magnitudes).
    zoom
        Camera zoom towards the part of the slave surface in contact.
    pair
        The contact pair.
    """
    view = _default_view(view, problem.gdim)  # bad input fails on every rank, first
    if not 0.0 < saturate <= 100.0:
        raise ValueError(f"saturate is a percentile in (0, 100], got {saturate}")
    grid = gathered_grid(problem)
    surface = gathered_contact_surface(problem, pair)
    if grid is None:
        return
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=(1200, 700))
    plotter.add_mesh(grid, color="lightgrey", show_edges=True, opacity=0.2)
    in_contact = surface["t_N"] > 0.0
    patch = surface.extract_points(in_contact, adjacent_cells=True)
    lines = {"line_width": 4} if problem.gdim == 2 else {}  # a 2D surface is a curve
    plotter.add_mesh(surface, color="darkgrey", **lines)
    contact = surface.extract_points(in_contact, adjacent_cells=False, include_cells=False)
    if contact.n_points == 0:
        _view(plotter, view)
        _screenshot(plotter, path, title)
        return
    t_N = contact["t_N"]
    top = float(np.percentile(t_N, saturate))
    label = "t_N = lambda_N" + (f" (max {t_N.max():.3g})" if top < t_N.max() else "")
    colours = {
        "scalars": "t_N",
        "cmap": "plasma",
        "clim": (0.0, top),
        "scalar_bar_args": {"title": label},
    }
    if patch.n_cells:
        plotter.add_mesh(patch, **colours, **lines)
    length = scale * float(np.linalg.norm(np.ptp(grid.points, axis=0)))
    if problem.gdim == 2:
        length /= zoom  # the 2D view zooms in the plane of the arrows: keep their size
    if view == ("xy" if problem.gdim == 2 else "xz"):
        arrows = _arrows(contact, "traction", length, saturate)
        plotter.add_mesh(arrows, **(colours | {"show_scalar_bar": not patch.n_cells}))
        plotter.add_points(contact, render_points_as_spheres=True, point_size=8, **colours)
    if np.any(contact["t_T"]):
        plotter.add_mesh(_arrows(contact, "t_T", 0.5 * length, saturate), color="black")
    _view(plotter, view)
    _focus(plotter, contact.center)
    plotter.camera.zoom(zoom)
    _screenshot(plotter, path, title)


_ALONG_LABELS = {
    "x": "x",
    "arc length": "arc length (reference)",
    "current arc length": "arc length (current)",
}


def plot_pressure_profile(
    x,
    pressure=None,
    path: str | Path | None = None,
    exact: tuple[np.ndarray, np.ndarray] | None = None,
    title: str = "contact pressure",
    *,
    along: str = "x",
    span: tuple[float, float] | None = None,
    exact_label: str = "Hertz",
    comm: MPI.Comm | None = None,
    label: str = "lambda_N (FE)",
) -> None:
    """A chart of the contact pressure along the slave surface, with an optional exact
    curve. Rank 0 writes the picture. Two forms:

    ``plot_pressure_profile(samples, path, along="arc length")``
        ``samples`` from :func:`~contact_ufl.results.contact_samples` (which gathers them,
        the same on every rank: call this on every rank or on rank 0 only; rank 0 of
        ``comm``, by default ``MPI.COMM_WORLD``, writes). The Cauchy pressure against
        ``along``: ``"x"`` (the current x), ``"arc length"`` (along the reference slave
        curve) or ``"current arc length"`` (along the deformed one; both 2D only: see
        :class:`~contact_ufl.results.ContactSamples`); the points in contact in blue, the
        open ones in grey. ``span`` bounds the abscissa (default: the contact zone widened
        by half its length on either side, or all points if none is in contact).
    ``plot_pressure_profile(x, pressure, path)``
        Arrays (``along`` is then only the axis' name). Without ``comm`` they are plotted as
        given and only rank 0 of ``MPI.COMM_WORLD`` writes (a call on rank 0 only, or on
        every rank with the same arrays); with ``comm`` the call is collective and each
        rank's arrays are its part of the profile, gathered to rank 0 of ``comm``.

    ``exact`` is ``(abscissa, pressure)`` on the same abscissa, drawn as a line labelled
    ``exact_label``; ``label`` names the arrays' points.
    """
    from contact_ufl.results import ALONG, ContactSamples

    if along not in ALONG:
        raise ValueError(f"along must be one of {list(ALONG)}, got {along!r}")
    if isinstance(x, ContactSamples):
        if path is None:  # plot_pressure_profile(samples, path)
            path, pressure = pressure, None
        if pressure is not None or path is None:
            raise TypeError("plot_pressure_profile(samples, path, ...): no pressure array")
        samples = x
        x, pressure = samples.abscissa(along), samples.pressure
        touching, label = samples.in_contact, "in contact"
        if span is None and touching.any():
            low, high = x[touching].min(), x[touching].max()
            span = (low - 0.5 * (high - low), high + 0.5 * (high - low))
    else:
        if path is None:
            raise TypeError("plot_pressure_profile(x, pressure, path, ...): no path")
        x, pressure = np.asarray(x, dtype=float), np.asarray(pressure, dtype=float)
        if comm is not None:
            x = np.concatenate(comm.gather(x, root=0) or [x])
            pressure = np.concatenate(comm.gather(pressure, root=0) or [pressure])
        touching = np.ones(len(x), dtype=bool)
    if (comm or MPI.COMM_WORLD).rank != 0:
        return
    shown = np.ones(len(x), dtype=bool) if span is None else (x >= span[0]) & (x <= span[1])
    pv = _pyvista()
    chart = pv.Chart2D(x_label=_ALONG_LABELS[along], y_label="pressure")
    chart.title = title
    for mask, colour, name in (
        (shown & touching, "tab:blue", label),
        (shown & ~touching, "darkgrey", "open"),
    ):
        if mask.any():
            order = np.argsort(x[mask])
            chart.scatter(x[mask][order], pressure[mask][order], color=colour, size=6, label=name)
    if exact is not None:
        chart.line(*exact, color="tab:red", width=2.0, label=exact_label)
    plotter = pv.Plotter(off_screen=True, window_size=(900, 600))
    plotter.add_chart(chart)
    _save(plotter, path)


def plot_curves(
    curves: dict[str, tuple[np.ndarray, np.ndarray]],
    path: str | Path,
    x_label: str,
    y_label: str,
    title: str = "",
    comm: MPI.Comm | None = None,
) -> None:
    """A line chart of the ``curves`` (label: ``(x, y)``), written by rank 0 of ``comm``
    (default ``MPI.COMM_WORLD``) only: call it on every rank with the same curves, or on
    rank 0."""
    if (comm or MPI.COMM_WORLD).rank != 0:
        return
    pv = _pyvista()
    chart = pv.Chart2D(x_label=x_label, y_label=y_label)
    chart.title = title
    colours = ["tab:blue", "tab:red", "tab:green", "tab:orange"]
    for k, (name, (x, y)) in enumerate(curves.items()):
        chart.line(x, y, color=colours[k % len(colours)], width=2.0, label=name)
    plotter = pv.Plotter(off_screen=True, window_size=(900, 600))
    plotter.add_chart(chart)
    _save(plotter, path)


def plot_deformed(
    problem,
    path: str | Path,
    zoom: float = 1.0,
    focus: tuple[float, float, float] | None = None,
    cell_field: dolfinx.fem.Function | None = None,
    label: str = "|u|",
) -> None:
    """The deformed bodies coloured by the displacement magnitude, or by the cellwise
    (DG0) ``cell_field`` with the colour bar title ``label`` (2D: the plane view ``"xy"``,
    see :func:`_view`). Collective: the meshes of all ranks are gathered, rank 0 writes."""
    cells = {} if cell_field is None else {label: cell_field}
    grid = gathered_grid(problem, cell_data=cells)
    if grid is None:
        return
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=(1000, 700))
    plotter.add_mesh(
        grid,
        scalars="displacement" if cell_field is None else label,
        show_edges=True,
        cmap="viridis",
        scalar_bar_args={"title": label},
    )
    if problem.gdim == 2:
        _view(plotter, "xy")
    if focus is not None:
        _focus(plotter, focus)
    plotter.camera.zoom(zoom)
    _save(plotter, path)


def plot_mesh_with_indicator(
    problem,
    indicators: list[dolfinx.fem.Function],
    path: str | Path,
    zoom: float = 1.0,
    focus: tuple[float, float, float] | None = None,
    clim: tuple[float, float] | None = None,
    title: str = "",
) -> None:
    """The reference meshes, edges drawn, coloured by an error indicator per cell on a log
    scale (2D: the plane view ``"xy"``). ``indicators``: one cellwise (DG0) function per mesh
    of the problem, e.g. :attr:`ErrorEstimate.indicators
    <contact_ufl.estimate.ErrorEstimate.indicators>` (``eta_K^2``); ``clim``: the colour
    range (default: the largest value and 1e-6 of it), to draw several meshes on one scale.
    Collective: the meshes of all ranks are gathered, rank 0 writes."""
    names = [f"indicator {k}" for k in range(len(indicators))]
    fields = dict(zip(names, indicators, strict=True))
    grid = gathered_grid(problem, deformed=False, cell_data=fields)
    if grid is None:
        return
    # each cell is in one mesh: its value is the one that is not NaN
    values = np.nanmax(np.vstack([grid.cell_data[name] for name in names]), axis=0)
    if clim is None:
        top = float(values.max()) if values.max() > 0.0 else 1.0
        clim = (1e-6 * top, top)
    grid.cell_data["eta_K^2"] = np.clip(values, *clim)
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=(1000, 700))
    plotter.add_mesh(
        grid,
        scalars="eta_K^2",
        show_edges=True,
        edge_opacity=0.3,  # the cells show through the edges of fine meshes
        cmap="viridis",
        log_scale=True,
        clim=clim,
        scalar_bar_args={"title": "eta_K^2", "fmt": "%.0e"},
    )
    if problem.gdim == 2:
        _view(plotter, "xy")
    if focus is not None:
        _focus(plotter, focus)
    plotter.camera.zoom(zoom)
    _screenshot(plotter, path, title)


def _plane_patch(obstacle, t: float, size: float) -> pyvista.PolyData:
    """A square of side ``size`` on the rigid plane ``obstacle`` at pseudo-time ``t``,
    centred at its moved point (3D)."""
    pv = _pyvista()
    point, Q = obstacle.pose(t, 3)
    normal = Q @ np.asarray(obstacle.normal, dtype=float)
    return pv.Plane(center=point, direction=normal, i_size=size, j_size=size)


def membrane_contact_pressure(problem) -> dict[int, dolfinx.fem.Function]:
    """The contact pressure on the membranes as cellwise (DG0) functions: for each membrane
    mesh (its index in ``problem.bulks``), the mean normal traction ``t_N`` over the slave
    points of each of its cells, summed over the pairs whose slave surface it holds (0 on
    cells of no slave surface or open)."""
    out = {}
    for k, bulk in enumerate(problem.bulks):
        if not bulk.membrane:
            continue
        mesh = bulk.V.mesh
        f = dolfinx.fem.Function(dolfinx.fem.functionspace(mesh, ("DG", 0)))
        for c in problem.contacts:
            if problem.bulk_of(c) is not bulk:
                continue
            cells = c.slave.parent_cells  # (a rank may hold none)
            t_N = c.normal_traction_at_points().reshape(len(cells), c.slave.num_points)
            dofs = f.function_space.dofmap.list[cells, 0]
            f.x.array[dofs] += t_N.mean(axis=1)
        f.x.scatter_forward()
        out[k] = f
    return out


def plot_membrane_contact(
    problem,
    path: str | Path,
    view: str | tuple[float, float, float] = "iso",
    title: str = "",
    obstacles: list | tuple = (),
    zoom: float = 1.0,
) -> None:
    """The deformed bodies of a 3D scene with its membranes coloured by their contact
    pressure (collective; rank 0 writes the picture).

    A membrane's cells are its contact surface, and may be the slave of several pairs: each
    membrane cell is coloured by the mean normal traction ``t_N`` of its slave points, over
    all pairs (:func:`membrane_contact_pressure`), and grey where open; the solids are drawn
    translucent, and the rigid planes of ``obstacles`` as squares at their current
    position.
    """
    _direction(view)  # bad input fails on every rank, before the collective gathers
    if problem.gdim != 3:
        raise ValueError(f"plot_membrane_contact draws 3D scenes, got gdim = {problem.gdim}")
    pressures = membrane_contact_pressure(problem)
    grid = gathered_grid(problem, cell_data={f"t_N {k}": f for k, f in pressures.items()})
    if grid is None:
        return
    pv = _pyvista()
    values = np.column_stack(
        [grid.cell_data[f"t_N {k}"] for k in pressures] or [np.full(grid.n_cells, np.nan)]
    )
    on_membrane = ~np.all(np.isnan(values), axis=1)
    grid.cell_data["t_N"] = np.nansum(values, axis=1)
    plotter = pv.Plotter(off_screen=True, window_size=(1200, 800))
    size = 1.2 * float(np.ptp(grid.points, axis=0).max())
    for obstacle in obstacles:
        plotter.add_mesh(_plane_patch(obstacle, problem.t, size), color="steelblue", opacity=0.4)
    if not np.all(on_membrane):
        solids = grid.extract_cells(np.flatnonzero(~on_membrane))
        plotter.add_mesh(solids, color="lightgrey", show_edges=True, opacity=0.35)
    if np.any(on_membrane):
        membranes = grid.extract_cells(np.flatnonzero(on_membrane))
        top = float(membranes["t_N"].max())
        membranes["t_N"] = np.where(membranes["t_N"] > 0.0, membranes["t_N"], np.nan)  # open
        plotter.add_mesh(
            membranes,
            scalars="t_N",
            cmap="plasma",
            clim=(0.0, top if top > 0.0 else 1.0),
            nan_color="lightgrey",
            show_edges=True,
            edge_color="dimgrey",
            scalar_bar_args={"title": "t_N = lambda_N (cell mean)"},
        )
    _view(plotter, view)
    plotter.camera.zoom(zoom)
    _screenshot(plotter, path, title)
