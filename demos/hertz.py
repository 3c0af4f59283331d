# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Hertz contact of a cylinder on a flat (plane strain)
#
# A Neo-Hookean half disc of radius $R = 1$ is pressed onto a Neo-Hookean block; the two
# bodies have their own, non-matching meshes. The contact is modelled with the
# augmented-Lagrangian mixed form of `contact_ufl`: the unknowns are the displacement of
# both bodies and the contact multiplier $\lambda_N$ on the slave surface (the disc's arc).
#
# Hertz's theory (Johnson, *Contact Mechanics*, 4.2) predicts, for a load $P$ per unit
# length and the contact modulus $E^*$, an elliptic pressure
# $p(x) = p_0 \sqrt{1 - x^2/a^2}$ with $a = \sqrt{4 P R / (\pi E^*)}$ and
# $p_0 = 2P / (\pi a)$. By property (c) of the formulation the multiplier *is* the contact
# traction, so we compare $\lambda_N$ (converted to a Cauchy pressure) with $p(x)$.
#
# Run it as `python demos/hertz.py`, `mpirun -n 2 python demos/hertz.py`, or as a notebook.

# %%
import argparse
import time
from pathlib import Path

import gmsh
import numpy as np
from mpi4py import MPI

from contact_ufl import output
from contact_ufl.contact import ContactPair
from contact_ufl.gmshio import gmsh_session
from contact_ufl.loads import Dirichlet
from contact_ufl.materials import NeoHookean
from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples, traction_mismatch
from contact_ufl.scene import Body, Scene
from contact_ufl.verification.analytic import Hertz2D, fit_elliptic_profile, plane_strain_modulus

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--h", type=float, default=0.005, help="element size at the contact")
parser.add_argument("--depth", type=float, default=0.005, help="imposed displacement of the top")
parser.add_argument("--steps", type=int, default=4, help="load steps")
parser.add_argument("--out", default="output", help="folder for pictures and VTX files")
args, _ = parser.parse_known_args()
comm = MPI.COMM_WORLD
out = Path(args.out)

# %% [markdown]
# ## The geometry, with gmsh
# The disc is the lower half of the circle of radius $R = 1$ and centre $(0, R)$, touching
# the block $[-2, 2] \times [-1.5, 0]$ at the origin. The two bodies are two separate
# surfaces of the gmsh model: they share no curve and no node, so each is meshed on its own
# and the meshes do not match at the interface.

# %%
R, width, height = 1.0, 4.0, 1.5


def add_geometry() -> tuple[dict[str, tuple[int, list[int]]], int]:
    """The two bodies in the current gmsh model: the parts to name, as (dimension,
    entities), and the point where the bodies touch."""
    geo = gmsh.model.geo
    centre = geo.addPoint(0.0, R, 0.0)
    left, bottom, right = (geo.addPoint(x, y, 0.0) for x, y in ((-R, R), (0.0, 0.0), (R, R)))
    arc_left = geo.addCircleArc(left, centre, bottom)
    arc_right = geo.addCircleArc(bottom, centre, right)
    diameter = geo.addLine(right, left)
    disc = geo.addPlaneSurface([geo.addCurveLoop([arc_left, arc_right, diameter])])
    a = width / 2
    q = [geo.addPoint(x, y, 0.0) for x, y in ((-a, -height), (a, -height), (a, 0.0), (-a, 0.0))]
    top = geo.addLine(q[2], q[3])
    base, right_side, left_side = (
        geo.addLine(q[0], q[1]),
        geo.addLine(q[1], q[2]),
        geo.addLine(q[3], q[0]),
    )
    block = geo.addPlaneSurface([geo.addCurveLoop([base, right_side, top, left_side])])
    geo.synchronize()
    parts = {
        "cylinder": (2, [disc]),
        "block": (2, [block]),
        "cylinder_contact": (1, [arc_left, arc_right]),
        "cylinder_top": (1, [diameter]),
        "block_contact": (1, [top]),
        "block_bottom": (1, [base]),
        "block_sides": (1, [left_side, right_side]),
    }
    return parts, bottom


# %% [markdown]
# ## Named physical groups
# Every part the scene refers to is a *named* physical group: the two bodies (cells) and
# the boundary parts (facets) that carry supports, loads and the contact pair. The names
# are all the scene needs: `contact_ufl` looks up their tags and dimensions.


# %%
def add_groups(parts: dict[str, tuple[int, list[int]]]) -> None:
    """One named physical group per part."""
    for name, (dim, entities) in parts.items():
        gmsh.model.addPhysicalGroup(dim, entities, name=name)


# %% [markdown]
# ## Refinement near the contact
# The element size is `h` within $0.3 R$ of the lowest point of the disc and grows to 0.2
# over a further $R$; the block is 1.3 times coarser there (the interface meshes do not
# match). The sizes come from these fields only, not from the points or the curvature.

# %%
h_contact, h_far, master_ratio, d_fine = args.h, 0.2, 1.3, 0.3 * R
MESH_OPTIONS = {
    "Mesh.MeshSizeFromPoints": 0,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeExtendFromBoundary": 0,
    "Mesh.Algorithm": 6,  # Frontal-Delaunay
}


def refine_near_contact(disc: int, block: int, contact_point: int) -> None:
    """Size fields: fine near ``contact_point`` in each body, coarser in the block."""
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", [contact_point])
    sizes = []
    for surface, h in ((disc, h_contact), (block, master_ratio * h_contact)):
        threshold = field.add("Threshold")
        ramp = {"SizeMin": h, "SizeMax": h_far, "DistMin": d_fine, "DistMax": d_fine + R}
        field.setNumber(threshold, "InField", distance)
        for key, value in ramp.items():
            field.setNumber(threshold, key, value)
        restrict = field.add("Restrict")
        field.setNumber(restrict, "InField", threshold)
        field.setNumbers(restrict, "SurfacesList", [surface])
        field.setNumber(restrict, "IncludeBoundary", 1)
        sizes.append(restrict)
    smallest = field.add("Min")
    field.setNumbers(smallest, "FieldsList", sizes)
    field.setAsBackgroundMesh(smallest)


# %% [markdown]
# ## Meshing and writing the `.msh` file
# gmsh runs on rank 0 only and writes `hertz.msh`; you can open it in gmsh to see the
# groups. Your own `.msh` file (from the gmsh GUI, a `.geo` script or the Python API) enters
# at the next step in the same way.

# %%
msh_file = out / "hertz.msh"
if comm.rank == 0:
    with gmsh_session("hertz", MESH_OPTIONS):
        parts, contact_point = add_geometry()
        add_groups(parts)
        (disc,), (block,) = parts["cylinder"][1], parts["block"][1]
        refine_near_contact(disc, block, contact_point)
        gmsh.model.mesh.generate(2)
        msh_file.parent.mkdir(parents=True, exist_ok=True)
        gmsh.write(str(msh_file))
comm.barrier()

# %% [markdown]
# ## The scene, by name
# `Scene.from_gmsh` reads the mesh on rank 0, distributes it over the ranks and resolves
# the group names to tags. The bodies are Neo-Hookean ($E = 1$, $\nu = 0.3$); the bottom of
# the block is clamped and the flat top of the disc is moved down by `depth` at $t = 1$.
# The slave surface is the arc (the finer mesh), the master surface the top of the block;
# $\varepsilon_N$ is the package's default, the softer body's modulus over the size of the
# slave surface (see the guide's page on choosing it). (A live model works as well: inside
# the gmsh session, pass `gmsh.model` on rank 0 and `None` on the others instead of the
# file.)

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
problem = ContactProblem(scene)
writer = output.ResultWriter(problem, out / "hertz")

# %% [markdown]
# ## Load stepping
# Each step is a Newton (PETSc SNES) solve of the whole system; the tangent is the UFL
# derivative of the residual, chained through the closest-point projection.

# %%
start = time.perf_counter()
problem.solve(num_steps=args.steps, callback=writer)
wall = time.perf_counter() - start
writer.close()

# %% [markdown]
# ## Comparison with Hertz
# The contact force $P$ is the integral of the multiplier; $a$ and $p_0$ are fitted to the
# computed pressure profile.

# %%
samples = contact_samples(problem)
P = problem.contact_force()[1]
exact = Hertz2D(P, R, plane_strain_modulus(E, nu, E, nu))
a, p0, xc = fit_elliptic_profile(samples.x[:, 0], samples.pressure)
mismatch = traction_mismatch(problem)
if comm.rank == 0:
    print(f"load per unit length P = {P:.5e}")
    print(f"half-width  a  = {a:.5f}   Hertz {exact.a:.5f}   error {a / exact.a - 1:+.2%}")
    print(f"peak        p0 = {p0:.5e} Hertz {exact.p0:.5e} error {p0 / exact.p0 - 1:+.2%}")
    print(f"|Pi N - lambda_N nu| / |lambda_N| on the slave surface: {mismatch:.3f}")
    print(f"solve {wall:.2f} s, of which search {problem.search_time:.2f} s")

# %% [markdown]
# ## Pictures
# The multiplier along the contact, with Hertz's ellipse, and the deformed bodies.

# %%
if comm.rank == 0:
    near = np.abs(samples.x[:, 0] - xc) < 2.0 * exact.a
    xs = np.linspace(-1.2 * exact.a, 1.2 * exact.a, 200)
    output.plot_pressure_profile(
        samples.x[near, 0],
        samples.pressure[near],
        out / "hertz_pressure.png",
        exact=(xs + xc, exact.pressure(xs)),
        title="Hertz: contact pressure",
    )
    print(f"wrote {out / 'hertz_pressure.png'}")

# %% [markdown]
# The multipliers of neighbouring nodes sit alternately a little above and below Hertz's
# curve: on non-matching meshes the mismatch of the two surfaces' nodes enters the contact
# integrals, and the multipliers' mass matrix amplifies it (the user guide's *Results* page
# says more). The pressure recovered from the disc's own stress, the L2 projection of
# $\nu \cdot P N$ onto the contact surface, is the same quantity by property (c), and smooth:

# %%
recovered = contact_samples(problem, recovered=True)
if comm.rank == 0:
    output.plot_pressure_profile(
        recovered.x[near, 0],
        recovered.pressure[near],
        out / "hertz_pressure_recovered.png",
        exact=(xs + xc, exact.pressure(xs)),
        title="Hertz: contact pressure recovered from the bulk",
        label="recovered (FE)",
    )
    print(f"wrote {out / 'hertz_pressure_recovered.png'}")
if comm.size == 1:
    output.plot_deformed(problem, out / "hertz_deformed.png", zoom=4.0, focus=(0.0, 0.0, 0.0))
    print(f"wrote {out / 'hertz_deformed.png'}")
