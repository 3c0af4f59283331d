# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Adaptive refinement to a stated accuracy (Hertz, plane strain)
#
# On a scene of your own there is no closed form to tell you whether the mesh is fine
# enough, nor where it should be fine. Here we state the accuracy we want and let the
# program find the mesh: `contact_ufl.refine_to_tolerance` solves, estimates the error of
# the solution cell by cell, refines the cells where the estimate is large, and solves
# again, until the estimate, relative to the solution's energy norm, is below the tolerance.
#
# The scene is that of the Hertz demo (a Neo-Hookean half disc of radius $R = 1$ pressed
# onto a Neo-Hookean block), but meshed coarsely, with a mild grading only: we do not tell
# the mesher how wide the contact zone will be. Hertz's closed form (Johnson, *Contact
# Mechanics*, 4.2) then tells *us* how good the meshes the program chose are.
#
# Run it as `python demos/adaptive_hertz.py`, `mpirun -n 2 python demos/adaptive_hertz.py`,
# or as a notebook.

# %%
import argparse
import time
from pathlib import Path

import gmsh
import numpy as np
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl import output
from contact_ufl.contact import ContactPair
from contact_ufl.gmshio import gmsh_session
from contact_ufl.loads import Dirichlet
from contact_ufl.materials import NeoHookean
from contact_ufl.results import contact_samples
from contact_ufl.scene import Body, Scene
from contact_ufl.verification.analytic import Hertz2D, fit_elliptic_profile, plane_strain_modulus

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--h", type=float, default=0.05, help="element size at the contact")
parser.add_argument("--h-far", type=float, default=0.2, help="element size far from it")
parser.add_argument("--depth", type=float, default=0.02, help="imposed displacement of the top")
parser.add_argument("--steps", type=int, default=2, help="load steps on the first mesh")
parser.add_argument("--tolerance", type=float, default=0.05, help="relative error estimate")
parser.add_argument("--max-unknowns", type=int, default=100_000, help="the budget")
parser.add_argument("--out", default="output", help="folder for the pictures")
args, _ = parser.parse_known_args()
comm = MPI.COMM_WORLD
out = Path(args.out)

# %% [markdown]
# ## The geometry, coarsely meshed
# The disc is the lower half of the circle of radius $R = 1$ and centre $(0, R)$, touching
# the block $[-2, 2] \times [-1.5, 0]$ at the origin; two separate gmsh surfaces, meshed
# each on its own (non-matching at the interface). The element size is `h` = 0.05 within
# $0.3 R$ of the origin, growing to 0.2 over a further $R$: the contact zone will be a
# few cells wide, and nothing else is graded.

# %%
R, width, height = 1.0, 4.0, 1.5
MESH_OPTIONS = {
    "Mesh.MeshSizeFromPoints": 0,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeExtendFromBoundary": 0,
    "Mesh.Algorithm": 6,  # Frontal-Delaunay
}


def mesh_bodies() -> None:
    """The two bodies, their named groups and a size field, meshed (current gmsh model)."""
    geo = gmsh.model.geo
    centre = geo.addPoint(0.0, R, 0.0)
    left, bottom, right = (geo.addPoint(x, y, 0.0) for x, y in ((-R, R), (0.0, 0.0), (R, R)))
    arc = [geo.addCircleArc(left, centre, bottom), geo.addCircleArc(bottom, centre, right)]
    diameter = geo.addLine(right, left)
    disc = geo.addPlaneSurface([geo.addCurveLoop([*arc, diameter])])
    a = width / 2
    q = [geo.addPoint(x, y, 0.0) for x, y in ((-a, -height), (a, -height), (a, 0.0), (-a, 0.0))]
    base, right_side, top, left_side = (geo.addLine(q[i], q[(i + 1) % 4]) for i in range(4))
    block = geo.addPlaneSurface([geo.addCurveLoop([base, right_side, top, left_side])])
    geo.synchronize()
    parts = {
        "cylinder": (2, [disc]),
        "block": (2, [block]),
        "cylinder_contact": (1, arc),
        "cylinder_top": (1, [diameter]),
        "block_contact": (1, [top]),
        "block_bottom": (1, [base]),
        "block_sides": (1, [left_side, right_side]),
    }
    for name, (dim, entities) in parts.items():
        gmsh.model.addPhysicalGroup(dim, entities, name=name)
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", [bottom])
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    ramp = {"SizeMin": args.h, "SizeMax": args.h_far, "DistMin": 0.3 * R, "DistMax": 1.3 * R}
    for key, value in ramp.items():
        field.setNumber(threshold, key, value)
    field.setAsBackgroundMesh(threshold)
    gmsh.model.mesh.generate(2)


msh_file = out / "adaptive_hertz.msh"
if comm.rank == 0:
    with gmsh_session("adaptive_hertz", MESH_OPTIONS):
        mesh_bodies()
        msh_file.parent.mkdir(parents=True, exist_ok=True)
        gmsh.write(str(msh_file))
comm.barrier()

# %% [markdown]
# ## The scene
# As in the Hertz demo: Neo-Hookean bodies ($E = 1$, $\nu = 0.3$), the bottom of the block
# clamped, the flat top of the disc moved down by `depth` (0.02: a contact zone about 0.23
# wide, four or five cells of the first mesh); the arc is the slave surface.

# %%
E, nu = 1.0, 0.3
scene = Scene.from_gmsh(
    msh_file,
    bodies=[Body("cylinder", NeoHookean(E, nu)), Body("block", NeoHookean(E, nu))],
    contacts=[ContactPair(slave="cylinder_contact", master="block_contact")],
    dirichlet=[
        Dirichlet("block_bottom", (0.0, 0.0)),
        Dirichlet("cylinder_top", lambda t: (0.0, -args.depth * t)),
    ],
)

# %% [markdown]
# ## What we compare with
# After each solve we fit Hertz's ellipse $p_0 \sqrt{1 - (x - x_c)^2/a^2}$ to the
# multiplier $\lambda_N$ at the reference positions of the slave points (the small-strain
# solution Hertz's is) and compare its peak with Hertz's $p_0$ for the computed load $P$.
# This is a check the loop knows nothing of: it sees only its own estimate.


# %%
def hertz_comparison(problem) -> tuple[float, Hertz2D]:
    """The relative error of the fitted peak pressure, and Hertz's solution for the load."""
    samples = contact_samples(problem)
    exact = Hertz2D(problem.contact_force()[1], R, plane_strain_modulus(E, nu, E, nu))
    _, p0, _ = fit_elliptic_profile(samples.X[:, 0], samples.lambda_N)
    return p0 / exact.p0 - 1.0, exact


def cell_sizes(problem) -> tuple[np.ndarray, np.ndarray]:
    """The size of every cell of every mesh (all ranks) and its distance from the first
    point of contact, the origin."""
    sizes, places = [], []
    for bulk in problem.bulks:
        mesh = bulk.V.mesh
        cells = np.arange(mesh.topology.index_map(2).size_local, dtype=np.int32)
        sizes.append(mesh.h(2, cells))
        midpoints = mesh.geometry.x[mesh.geometry.dofmaps[0][cells]].mean(axis=1)
        places.append(np.linalg.norm(midpoints, axis=1))
    h = np.concatenate(comm.allgather(np.concatenate(sizes)))
    return h, np.concatenate(comm.allgather(np.concatenate(places)))


# %% [markdown]
# ## The loop
# `refine_to_tolerance` solves the first mesh along the load path (`solve`), then each
# finer mesh from the last solution moved onto it. The new nodes Plaza's refinement puts
# on the arc are moved onto the circle (`boundaries`), else the disc would keep the coarse
# polygon. `on_level` is called after each solve: it prints a line of the table (the
# unknowns, the estimate and its relative value, the Newton iterations, where the solve
# started, the error of the peak pressure against Hertz) and draws the first mesh with its
# error indicators, `eta_K^2` per cell, on a log scale.
#
# The tolerance bounds the *estimate*, which is 1.6 to 1.8 times the true relative error
# in the energy norm on the calibration scenes (the guide's page on error estimates): a
# tolerance of 0.05 asks for a true error of about 0.03. The budget, `max_unknowns`, stops
# the loop before a mesh that would be too large for the machine.

# %%
centre = np.array([0.0, R, 0.0])


def onto_circle(x: np.ndarray) -> np.ndarray:
    """Points moved radially onto the disc's circle."""
    d = x - centre
    return centre + R * d / np.linalg.norm(d, axis=1)[:, None]


def draw(problem, indicators, name: str, a: float, clim, views: tuple[str, ...]) -> None:
    """The mesh with its indicators on the colour range ``clim``: ``"whole"``, zoomed on the
    contact zone (``"contact"``, about 3 a wide) or on its right edge (``"edge"``, a / 4
    wide), in the reference configuration."""
    zooms = {"whole": 1.0, "contact": 1.5 / a, "edge": 8.0 / a}
    for view in views:
        output.plot_mesh_with_indicator(
            problem,
            indicators,
            out / f"adaptive_hertz_{name}_{view}.png",
            zoom=zooms[view],
            focus=(a if view == "edge" else 0.0, 0.0, 0.0),
            clim=clim,
            title=f"{name} mesh: eta_K^2 ({view})",
        )


#: what the demo keeps of the first mesh, whose problem the loop closes: its cell sizes
#: and the colour range of its indicators (the last mesh is drawn on the same scale)
FIRST = {}


def on_level(problem, level) -> None:
    """A line of the table; on the first mesh, its pictures."""
    p0_error, exact = hertz_comparison(problem)
    if comm.rank == 0:
        print(
            f"{level.unknowns:9d} {level.estimate:10.3e} {level.relative:9.4f} "
            f"{level.newton_iterations:6d}  {level.start:11s} {p0_error:+8.2%}",
            flush=True,
        )
    if not FIRST:
        FIRST["sizes"] = cell_sizes(problem)
        indicators = problem.error_estimate().indicators
        top = comm.allreduce(max(i.x.array.max(initial=0.0) for i in indicators), MPI.MAX)
        FIRST["clim"] = (1e-6 * top, top)
        draw(problem, indicators, "first", exact.a, FIRST["clim"], ("whole", "contact"))


if comm.rank == 0:
    print(f"tolerance {args.tolerance} on the relative estimate, budget {args.max_unknowns}")
    print(" unknowns   estimate  relative Newton  start       p0 error")
begin = time.perf_counter()
result = cu.refine_to_tolerance(
    scene,
    solve=lambda problem: problem.solve(num_steps=args.steps),
    tolerance=args.tolerance,
    max_unknowns=args.max_unknowns,
    boundaries={"cylinder_contact": onto_circle},
    problem_options={"verbose": False},
    on_level=on_level,
)
wall = time.perf_counter() - begin

# %% [markdown]
# ## The last mesh
# `result.problem` is the problem on the last mesh, solved; `result.estimate` its error
# estimate. We draw the last mesh on the colour scale of the first (whole, the contact zone,
# and the right edge of the contact zone, where the pressure falls to zero), in the
# reference configuration, where the bodies touch at the origin only. Then its pressure
# profile against Hertz's ellipse.

# %%
problem = result.problem
p0_error, exact = hertz_comparison(problem)
views = ("whole", "contact", "edge")
draw(problem, result.estimate.indicators, "last", exact.a, FIRST["clim"], views)
samples = contact_samples(problem)
if comm.rank == 0:
    near = np.abs(samples.X[:, 0]) < 2.0 * exact.a
    xs = np.linspace(-1.2 * exact.a, 1.2 * exact.a, 200)
    output.plot_pressure_profile(
        samples.X[near, 0],
        samples.lambda_N[near],
        out / "adaptive_hertz_pressure.png",
        exact=(xs, exact.pressure(xs)),
        title="last mesh: contact pressure",
    )
    print(f"wrote the pictures adaptive_hertz_*.png in {out}")

# %% [markdown]
# ## The number you read, and its error
# The energy norm says how well the whole scene is resolved, not how far a number read off
# the solution is. For the normal contact force the multipliers carry,
# `problem.normal_force_error()` estimates that error itself, signed (dual-weighted
# residuals: one tangent with quadratic displacements on the same mesh, and one solve; see
# the guide *Error estimates*). `goal="normal_force"` in `refine_to_tolerance` refines to a
# tolerance on it instead.

# %%
force = problem.normal_force_error()
if comm.rank == 0:
    print(
        f"normal contact force {force.value:.5e}, estimated error {force.error:+.2e} "
        f"({force.relative:.2%} of it)"
    )

# %% [markdown]
# ## What we learnt
# - **The accuracy asked for**: the loop stops when the relative estimate meets the
#   tolerance (`reached`), else when the next mesh would exceed the budget or after
#   `max_levels` meshes (`stopped_by` says which). With the estimate's effectivity of 1.6
#   to 1.8, the true relative error in the energy norm is the estimate over about 1.7.
# - **Where the program refined**: where the first mesh's indicators were bright, at the
#   contact zone and the arc beside it; the smallest cells of the last mesh lie within the
#   contact zone, whose half-width $a$ the mesher was never told, and along the arc, whose
#   new nodes were put on the circle. The rest of both bodies was refined as well, less:
#   the error in the energy norm is spread over the bodies, not only at the contact.
# - **A check the loop never saw**: Hertz's peak pressure, off by about 10% on the first
#   mesh, is met to a small fraction of a percent on the last.
# - **The number you read**: the contact force comes with its own estimated error, signed:
#   negative, as a linear element's stiffness, too high, gives too large a force at a
#   prescribed depth.
# - **Cost**: only the first mesh ran the load path; each finer one started from the last
#   solution moved onto it and took 2 to 4 Newton iterations (the table's `start`).

# %%
first, last = result.levels[0], result.levels[-1]
h, distance = cell_sizes(problem)
finest = np.argsort(h)[:20]
h_first, distance_first = FIRST["sizes"]
if comm.rank == 0:
    print(
        f"{len(result.levels)} meshes, {first.unknowns} to {last.unknowns} unknowns in "
        f"{wall:.1f} s, stopped by the {result.stopped_by}"
    )
    print(
        f"relative estimate {first.relative:.3f} -> {last.relative:.4f} "
        f"(tolerance {args.tolerance}): a true relative error of about {last.relative / 1.7:.3f}"
    )
    print(f"peak pressure against Hertz: {p0_error:+.2%} on the last mesh")
    print(
        f"smallest cell {h.min():.4f} (first mesh: {h_first.min():.4f}); the 20 smallest within "
        f"{distance[finest].max():.3f} of the first point of contact (Hertz's a = {exact.a:.3f})"
    )
    for low, high in ((0.0, 2.0 * exact.a), (0.5, np.inf)):
        now, then = (
            np.median(h[(distance >= low) & (distance < high)]),
            np.median(h_first[(distance_first >= low) & (distance_first < high)]),
        )
        print(f"median cell size at {low:.2f} to {high:.2f} from it: {then:.4f} -> {now:.4f}")
    print(f"reached: {result.reached}")
