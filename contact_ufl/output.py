"""Output: VTX files for ParaView, and off-screen pictures with pyvista."""

from __future__ import annotations

import os
from pathlib import Path

import dolfinx
import numpy as np

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


class ResultWriter:
    """Write the displacement and the multipliers of every load step to VTX (ADIOS2) files.

    Files are flushed at every step, so results already written survive a later failure.

    Parameters
    ----------
    problem
        The contact problem.
    folder
        Output folder; ``displacement.bp`` and ``contact_<k>.bp`` are written there.
    """

    def __init__(self, problem, folder: str | Path):
        folder = Path(folder)
        if problem.comm.rank == 0:
            folder.mkdir(parents=True, exist_ok=True)
        problem.comm.barrier()
        comm = problem.comm
        self.writers = [dolfinx.io.VTXWriter(comm, folder / "displacement.bp", [problem.u])]
        for k, c in enumerate(problem.contacts):
            self.writers.append(
                dolfinx.io.VTXWriter(comm, folder / f"contact_{k}.bp", [c.lambda_N])
            )

    def write(self, t: float) -> None:
        """Write the current state at pseudo-time ``t``."""
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


def deformed_grid(problem):
    """The mesh as a pyvista grid, warped by the displacement (gathered on rank 0)."""
    pv = _pyvista()
    V = problem.V
    topology, cell_types, x = dolfinx.plot.vtk_mesh(V)
    grid = pv.UnstructuredGrid(topology, cell_types, x)
    gdim = V.mesh.geometry.dim
    u = np.zeros((x.shape[0], 3))
    u[:, :gdim] = problem.u.x.array.reshape(-1, gdim)[: x.shape[0]]
    grid.point_data["displacement"] = u
    return grid.warp_by_vector("displacement")


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
    plotter.screenshot(str(path))
    plotter.close()


def plot_deformed(
    problem, path: str | Path, zoom: float = 1.0, focus: tuple[float, float, float] | None = None
) -> None:
    """The deformed bodies coloured by the displacement magnitude (2D: seen from +z)."""
    if problem.comm.size > 1:
        raise NotImplementedError("pictures are drawn from a serial run")
    pv = _pyvista()
    grid = deformed_grid(problem)
    plotter = pv.Plotter(off_screen=True, window_size=(1000, 700))
    plotter.add_mesh(
        grid,
        scalars="displacement",
        show_edges=True,
        cmap="viridis",
        scalar_bar_args={"title": "|u|"},
    )
    if problem.V.mesh.geometry.dim == 2:
        plotter.view_xy()
    if focus is not None:
        plotter.set_focus(focus)
    plotter.camera.zoom(zoom)
    plotter.screenshot(str(path))
    plotter.close()
