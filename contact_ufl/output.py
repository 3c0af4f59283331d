"""Output: VTX files for ParaView, and off-screen pictures with pyvista.

Every picture is written as a PNG file; inside a Jupyter (IPython) kernel it is also shown
inline, by rank 0 only.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import dolfinx
import numpy as np
from mpi4py import MPI

if TYPE_CHECKING:
    import pyvista

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


class ResultWriter:
    """Write the displacement and the multipliers of every load step to VTX (ADIOS2) files.

    Files are flushed at every step, so results already written survive a later failure.

    Parameters
    ----------
    problem
        The contact problem.
    folder
        Output folder; ``displacement.bp``, ``contact_<k>.bp`` (the multipliers of pair
        ``k``) and, for each elastoplastic body, ``plastic_strain_<tag>.bp`` (the cell means
        of its equivalent plastic strain) are written there.
    """

    def __init__(self, problem, folder: str | Path):
        folder = Path(folder)
        if problem.comm.rank == 0:
            folder.mkdir(parents=True, exist_ok=True)
        problem.comm.barrier()
        comm = problem.comm
        self.writers = [dolfinx.io.VTXWriter(comm, folder / "displacement.bp", [problem.u])]
        for k, c in enumerate(problem.contacts):
            multipliers = [c.lambda_N] + ([c.friction.lambda_T] if c.friction else [])
            self.writers.append(dolfinx.io.VTXWriter(comm, folder / f"contact_{k}.bp", multipliers))
        self.histories = list(problem.histories.values())
        for tag, h in problem.histories.items():
            path = folder / f"plastic_strain_{tag}.bp"
            self.writers.append(dolfinx.io.VTXWriter(comm, path, [h.plastic_strain]))

    def write(self, t: float) -> None:
        """Write the current state at pseudo-time ``t``."""
        for h in self.histories:
            h.update_plastic_strain()
        for w in self.writers:
            w.write(t)

    def close(self) -> None:
        """Close the files."""
        for w in self.writers:
            w.close()

    def __call__(self, problem, record) -> None:
        """Use as the ``callback`` of :meth:`ContactProblem.solve`."""
        self.write(record.t)


def _pyvista():
    import pyvista

    pyvista.OFF_SCREEN = True
    return pyvista


def gathered_grid(
    problem, deformed: bool = True, cell_data: dict[str, dolfinx.fem.Function] | None = None
) -> pyvista.UnstructuredGrid | None:
    """The mesh of all ranks as one pyvista grid on rank 0 (``None`` on the other ranks).

    Each rank contributes its owned cells; the point data hold the displacement, and the
    cell data ``"body"`` the cell tag of each cell, plus the cellwise (DG0) functions of
    ``cell_data`` under their keys. With ``deformed`` the grid is warped by the displacement.
    """
    pv = _pyvista()
    V = problem.V
    mesh = V.mesh
    tdim, gdim = mesh.topology.dim, mesh.geometry.dim
    topology, cell_types, x = dolfinx.plot.vtk_mesh(V)
    owned = mesh.topology.index_map(tdim).size_local
    cells = topology.reshape(len(cell_types), -1)[:owned]
    u = np.zeros((x.shape[0], 3))
    u[:, :gdim] = problem.u.x.array.reshape(-1, gdim)[: x.shape[0]]
    body = np.zeros(owned, dtype=np.int32)
    tags = problem.scene.cell_tags
    local = tags.indices < owned
    body[tags.indices[local]] = tags.values[local]
    fields = {
        name: f.x.array[f.function_space.dofmap.list[:owned, 0]]
        for name, f in (cell_data or {}).items()
    }
    parts = problem.comm.gather((cells, cell_types[:owned], x, u, body, fields), root=0)
    if problem.comm.rank != 0:
        return None
    offset, all_cells = 0, []
    for c, _, xx, *_ in parts:
        shifted = c.copy()
        shifted[:, 1:] += offset
        all_cells.append(shifted)
        offset += len(xx)
    grid = pv.UnstructuredGrid(
        np.concatenate(all_cells).ravel(),
        np.concatenate([p[1] for p in parts]),
        np.concatenate([p[2] for p in parts]),
    )
    grid.point_data["displacement"] = np.concatenate([p[3] for p in parts])
    grid.cell_data["body"] = np.concatenate([p[4] for p in parts])
    for name in fields:
        grid.cell_data[name] = np.concatenate([p[5][name] for p in parts])
    return grid.warp_by_vector("displacement") if deformed else grid


def gathered_tractions(problem, pair: int = 0) -> tuple[np.ndarray, ...] | None:
    """Current positions ``(n, 3)``, contact tractions ``(n, 3)`` and normal tractions
    ``t_N`` ``(n,)`` (nominal, on the slave body) of the slave points in contact, gathered on
    rank 0 (``None`` on the other ranks)."""
    c = problem.contacts[pair]
    gdim = c.gdim
    active = c.active()
    x = np.zeros((int(active.sum()), 3))
    t = np.zeros_like(x)
    x[:, :gdim] = c.slave.positions(problem.u).reshape(-1, gdim)[active]
    t[:, :gdim] = c.traction_at_points()[active]
    t_N = c.normal_traction_at_points()[active]
    parts = problem.comm.gather((x, t, t_N), root=0)
    if problem.comm.rank != 0:
        return None
    return tuple(np.concatenate([p[k] for p in parts]) for k in range(3))


def _view(plotter, view: str) -> None:
    """Camera: ``"iso"`` (3D view from the front, above and to the right), ``"xz"`` (the
    x-z plane seen from -y: the plane of bending of the beams) or ``"xy"`` (seen from +z)."""
    directions = {"iso": (0.7, -1.0, 0.6), "xz": (0.0, -1.0, 0.0), "xy": (0.0, 0.0, 1.0)}
    if view not in directions:
        raise ValueError(f"view must be one of {sorted(directions)}, got {view!r}")
    up = (0.0, 1.0, 0.0) if view == "xy" else (0.0, 0.0, 1.0)
    plotter.view_vector(directions[view], viewup=up)
    plotter.reset_camera()


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


def plot_reference(problem, path: str | Path, view: str = "iso", title: str = "") -> None:
    """The reference configuration: the mesh of every body, coloured by body (collective;
    rank 0 writes the picture)."""
    grid = gathered_grid(problem, deformed=False)
    if grid is None:
        return
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=(1200, 700))
    plotter.add_mesh(grid, scalars="body", show_edges=True, cmap="Pastel1", show_scalar_bar=False)
    _view(plotter, view)
    _screenshot(plotter, path, title)


def plot_contact_state(
    problem, path: str | Path, view: str = "iso", title: str = "", scale: float | None = None
) -> None:
    """The deformed bodies with the contact tractions of the first pair drawn as arrows at
    the slave points in contact, coloured by the normal traction ``t_N`` (at a converged
    state the multiplier lambda_N there; collective, rank 0 writes the picture).

    ``scale`` is the arrow length per unit traction (default: the longest arrow is a
    tenth of the scene's size).
    """
    grid = gathered_grid(problem)
    tractions = gathered_tractions(problem)
    if grid is None:
        return
    pv = _pyvista()
    plotter = pv.Plotter(off_screen=True, window_size=(1200, 700))
    plotter.add_mesh(grid, color="lightgrey", show_edges=True, opacity=0.5)
    x, t, t_N = tractions
    magnitude = np.linalg.norm(t, axis=1)
    if len(x) and magnitude.max() > 0.0:
        size = float(np.linalg.norm(np.ptp(grid.points, axis=0)))
        factor = scale or 0.1 * size / magnitude.max()
        arrows = pv.PolyData(x)
        arrows["traction"] = t
        arrows["length"] = magnitude
        arrows["t_N"] = t_N
        glyphs = arrows.glyph(orient="traction", scale="length", factor=factor)
        plotter.add_mesh(glyphs, scalars="t_N", cmap="plasma")
    _view(plotter, view)
    _screenshot(plotter, path, title)


def plot_pressure_profile(
    x: np.ndarray,
    pressure: np.ndarray,
    path: str | Path,
    exact: tuple[np.ndarray, np.ndarray] | None = None,
    title: str = "contact pressure",
) -> None:
    """A line chart of the contact pressure along x, with an optional exact curve."""
    pv = _pyvista()
    order = np.argsort(x)
    chart = pv.Chart2D(x_label="x", y_label="pressure")
    chart.title = title
    chart.scatter(x[order], pressure[order], color="tab:blue", size=6, label="lambda_N (FE)")
    if exact is not None:
        chart.line(*exact, color="tab:red", width=2.0, label="Hertz")
    plotter = pv.Plotter(off_screen=True, window_size=(900, 600))
    plotter.add_chart(chart)
    _save(plotter, path)


def plot_curves(
    curves: dict[str, tuple[np.ndarray, np.ndarray]],
    path: str | Path,
    x_label: str,
    y_label: str,
    title: str = "",
) -> None:
    """A line chart of the ``curves`` (label: ``(x, y)``)."""
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
    (DG0) ``cell_field`` with the colour bar title ``label`` (2D: seen from +z)."""
    if problem.comm.size > 1:
        raise NotImplementedError("pictures are drawn from a serial run")
    pv = _pyvista()
    cells = {} if cell_field is None else {label: cell_field}
    grid = gathered_grid(problem, cell_data=cells)
    plotter = pv.Plotter(off_screen=True, window_size=(1000, 700))
    plotter.add_mesh(
        grid,
        scalars="displacement" if cell_field is None else label,
        show_edges=True,
        cmap="viridis",
        scalar_bar_args={"title": label},
    )
    if problem.V.mesh.geometry.dim == 2:
        plotter.view_xy()
    if focus is not None:
        plotter.set_focus(focus)
    plotter.camera.zoom(zoom)
    _save(plotter, path)
