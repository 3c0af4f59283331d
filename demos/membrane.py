# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # An inflated membrane tube, squeezed by a rubber block and slid over a rigid plate
#
# A Neo-Hookean membrane tube (radius $R = 1$, length 3, thickness $t_0 = 0.01$), its two
# end circles clamped, is inflated by a *follower* pressure: the pressure acts along the
# current normal of the membrane, on its current area. A Neo-Hookean block, on a mesh of its
# own, is then pressed down onto the tube while a rigid plate below rises against it; last,
# the plate slides sideways under the squeezed tube. The membrane is the slave surface of
# both contact pairs (its cells carry the multipliers); the block's underside and the
# analytic plane are the masters. Without friction the plate slides freely under the tube;
# with Coulomb friction ($\mu = 0.3$) it drags the tube's underside along, and the tube,
# held at its ends, leans over.
#
# A membrane has no bending stiffness and, flat and unstressed, no stiffness normal to
# itself: the tube is curved and the pressure comes first, so the membrane is tensioned
# before anything touches it.
#
# Run it as `python demos/membrane.py`, `mpirun -n 2 python demos/membrane.py`, or as a
# notebook; `--h` sets the mesh size, `--mu` the friction coefficients.

# %%
import argparse
import time
from pathlib import Path

import gmsh
import numpy as np
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl import output
from contact_ufl.gmshio import gmsh_session
from contact_ufl.results import coulomb_law

parser = argparse.ArgumentParser(description="An inflated membrane tube squeezed and slid")
parser.add_argument("--h", type=float, default=0.2, help="mesh size of the tube")
parser.add_argument("--mu", type=float, nargs="+", default=[0.0, 0.3], help="friction")
parser.add_argument("--steps", type=int, default=12, help="load steps")
parser.add_argument("--out", default="output", help="folder for pictures and VTX files")
args, _ = parser.parse_known_args()
comm = MPI.COMM_WORLD
out = Path(args.out)

say = cu.output.say  # progress on rank 0


# %% [markdown]
# ## The tube, with gmsh
# The tube's axis is the $y$ axis, $-L/2 \le y \le L/2$. Its cross-section at $y = -L/2$ is
# four quarter circles; extruding them along $y$ gives four cylindrical patches of
# quadrilaterals (a structured mesh: `h` around and along). The upper half (`tube_top`) and
# the lower half (`tube_bottom`) are two named cell groups, so each can be the contact
# surface of its own pair; `tube_ends`, the two end circles, is an edge group. The mesh is a
# surface in 3D: `contact_ufl` makes it a membrane (topological dimension 2).

# %%
R, L = 1.0, 3.0
MESH_OPTIONS = {"Mesh.MeshSizeFromPoints": 0, "Mesh.MeshSizeFromCurvature": 0}


def tube_geometry(h: float) -> dict[str, tuple[int, list[int]]]:
    """The tube in the current gmsh model (quadrilaterals of size about ``h``): the parts
    to name, as (dimension, entities)."""
    geo = gmsh.model.geo
    centre = geo.addPoint(0.0, -L / 2, 0.0)
    angles = np.pi / 2 * np.arange(4)  # right, top, left, bottom
    points = [geo.addPoint(R * np.cos(a), -L / 2, R * np.sin(a)) for a in angles]
    arcs = [geo.addCircleArc(points[k], centre, points[(k + 1) % 4]) for k in range(4)]
    around, along = max(int(np.ceil(np.pi / 2 * R / h)), 2), max(int(np.ceil(L / h)), 2)
    for arc in arcs:
        geo.mesh.setTransfiniteCurve(arc, around + 1)
    extruded = geo.extrude([(1, a) for a in arcs], 0.0, L, 0.0, [along], recombine=True)
    geo.synchronize()
    surfaces = [tag for dim, tag in extruded if dim == 2]
    far_arcs = [extruded[4 * k][1] for k in range(4)]  # each extrusion: top curve, surface, sides
    return {
        "tube_top": (2, surfaces[:2]),
        "tube_bottom": (2, surfaces[2:]),
        "tube_ends": (1, arcs + far_arcs),
    }


# %% [markdown]
# ## The block, with gmsh
# A box $1.6 \times 1.6 \times 0.6$ of tetrahedra, centred above the tube, its underside
# (`block_bottom`) at $z = 1.3$, clear of the inflated tube. Its faces are found by their
# bounding boxes.

# %%
BLOCK = {"half": 0.8, "bottom": 1.3, "height": 0.6}


def block_geometry(h: float) -> dict[str, tuple[int, list[int]]]:
    """The block in the current gmsh model: the parts to name."""
    a, z0, hz = BLOCK["half"], BLOCK["bottom"], BLOCK["height"]
    box = gmsh.model.occ.addBox(-a, -a, z0, 2 * a, 2 * a, hz)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    eps = 1e-6

    def face_at(z: float) -> list[int]:
        found = gmsh.model.getEntitiesInBoundingBox(
            -a - eps, -a - eps, z - eps, a + eps, a + eps, z + eps, 2
        )
        return [tag for _, tag in found]

    return {
        "block": (3, [box]),
        "block_bottom": (2, face_at(z0)),
        "block_top": (2, face_at(z0 + hz)),
    }


def mesh_to_file(name: str, geometry, h: float, dim: int) -> Path:
    """Mesh ``geometry`` with named groups in gmsh (rank 0) and write ``<out>/<name>.msh``."""
    path = out / f"{name}.msh"
    if comm.rank == 0:
        with gmsh_session(name, MESH_OPTIONS):
            for group, (d, entities) in geometry(h).items():
                gmsh.model.addPhysicalGroup(d, entities, name=group)
            gmsh.model.mesh.generate(dim)
            path.parent.mkdir(parents=True, exist_ok=True)
            gmsh.write(str(path))
    comm.barrier()
    return path


tube_msh = mesh_to_file("tube", tube_geometry, args.h, 2)
block_msh = mesh_to_file("block", block_geometry, 1.5 * args.h, 3)

# %% [markdown]
# ## Pseudo-time: inflate, squeeze, slide
# Over $0 \le t \le 0.3$ the pressure grows to $p = 0.4\,\mu t_0 / R$ (the free long tube's
# limit pressure is $\mu t_0 / R$); over $0.3 \le t \le 0.6$ the block moves down by 0.5 and
# the plate, first at $z = -1.3$, up by 0.3; over $0.6 \le t \le 1$ the plate slides by 0.6
# along $x$, across the tube.

# %%
MU_SHEAR, T0 = 1.0, 0.01
P = 0.4 * MU_SHEAR * T0 / R
T_INFLATE, T_SQUEEZE = 0.3, 0.6


def ramp(t: float, start: float, end: float) -> float:
    """0 before ``start``, 1 after ``end``, linear in between."""
    return min(max((t - start) / (end - start), 0.0), 1.0)


def pressure(t: float) -> float:
    return P * ramp(t, 0.0, T_INFLATE)


def block_motion(t: float) -> tuple[float, float, float]:
    return (0.0, 0.0, -0.5 * ramp(t, T_INFLATE, T_SQUEEZE))


def plate_motion(t: float) -> tuple[float, float, float]:
    return (0.6 * ramp(t, T_SQUEEZE, 1.0), 0.0, 0.3 * ramp(t, T_INFLATE, T_SQUEEZE))


# %% [markdown]
# ## The scene: two meshes, two pairs, one rigid plate
# Each mesh is a `Domain` with its bodies, supports and loads. The tube's two halves are two
# membrane bodies of the same material, on one mesh (one displacement field); the
# follower pressure acts on both, along the membrane's oriented normal $n_0$, which by
# default points away from the centroid of the tube: out, so the pressure inflates it. The
# block (Neo-Hookean, $E = 0.05$, soft enough to flatten visibly) is moved by its top face.
# The plate is a `RigidPlane`, an analytic master with no mesh and no unknowns, its normal
# towards the tube.
#
# The penalty-like parameter `eps_N` of the augmented Lagrangian is set, for both pairs, to
# the transverse stiffness of the tensioned membrane at the scale of its cells: the hoop
# tension $T = p R$ over $h^2$ (a membrane resists a normal load through $T \Delta w$).
# The default, the softer body's modulus over the size $L$ of the slave surface (for a
# membrane the modulus is $E t_0 / L$), is $\varepsilon_N = 2 \cdot 10^{-3}$ here, fifty
# times less than $T / h^2 = 0.1$: with it, Newton 2-cycles as the block first touches the
# tube (the residual alternates between two values at $10^{-7}$ of its start, down to the
# last cut-back), the first points in contact toggling in and out.

# %%
# the tube: a surface mesh in 3D, read with its group names (`MeshData`)
tube_data = cu.read_gmsh(tube_msh, comm, gdim=3, require_names=True)
membrane = cu.MembraneNeoHookean(MU_SHEAR, T0)
rubber = cu.NeoHookean(E=0.05, nu=0.3)


def make_scene(mu: float) -> tuple[cu.Scene, cu.RigidPlane]:
    tube = cu.Domain.from_mesh_data(
        tube_data,
        bodies=[cu.Body("tube_top", membrane), cu.Body("tube_bottom", membrane)],
        dirichlet=[cu.Dirichlet("tube_ends", (0.0, 0.0, 0.0))],
        loads=[cu.FollowerPressure(half, pressure) for half in ("tube_top", "tube_bottom")],
        name="tube",
    )
    block = cu.Domain.from_gmsh(
        block_msh,
        bodies=[cu.Body("block", rubber)],
        dirichlet=[cu.Dirichlet("block_top", block_motion)],
        name="block",
    )
    plate = cu.RigidPlane((0.0, 0.0, -1.3), (0.0, 0.0, 1.0), motion=plate_motion)
    eps_N = P * R / args.h**2
    contacts = [
        cu.ContactPair(slave="tube_top", master="block_bottom", mu=mu, eps_N=eps_N),
        cu.ContactPair(slave="tube_bottom", master=plate, mu=mu, eps_N=eps_N),
    ]
    return cu.Scene(domains=[tube, block], contacts=contacts), plate


problems, plates = {}, {}
for mu in args.mu:
    scene, plates[mu] = make_scene(mu)
    problems[mu] = cu.ContactProblem(scene, verbose=False)
say(f"{problems[args.mu[0]].layout.global_size} unknowns for mu = {args.mu[0]:g}")

# %% [markdown]
# ## Load stepping
# Every step is one Newton solve (PETSc SNES) of both displacement fields and the
# multipliers of both pairs; a step that fails is cut back. The callback prints the
# progress and writes the displacements of both meshes and the multipliers of both pairs
# to VTX files for ParaView (`displacement_0.bp` the tube, `displacement_1.bp` the block).

# %%
walls, laws = {}, {mu: [] for mu in problems if mu > 0}
for mu, problem in problems.items():
    say(f"\n--- mu = {mu:g} ---")
    writer = output.ResultWriter(problem, out / f"membrane_mu{mu:g}")

    def record(problem, step, writer=writer, mu=mu):
        writer(problem, step)
        forces = [problem.contact_force(k) for k in range(len(problem.contacts))]
        say(
            f"step {step.step:2d}  t = {step.t:.3f}  Newton {step.newton_iterations:2d}  "
            f"points in contact {step.active_points:4d}  "
            f"block force {np.array2string(forces[0], precision=4)}  "
            f"plate force {np.array2string(forces[1], precision=4)}"
        )
        if mu > 0 and step.t > T_SQUEEZE:
            laws[mu].append(coulomb_law(problem, pair=1, floor=1e-3))

    start = time.perf_counter()
    problem.solve(num_steps=args.steps, callback=record)
    walls[mu] = time.perf_counter() - start
    writer.close()

# %% [markdown]
# ## Results
# Global equilibrium: the reaction at the clamped ends, the block's top support, the plate
# and the pressure balance (the contact forces are internal to each pair). The plate's
# force on the tube has a sideways part: zero without friction; with friction,
# $\mu$ times the normal part where the whole underside slips.


# %%
def underside_shift(problem: cu.ContactProblem) -> float:
    """Mean x-displacement of the tube's nodes within 0.25 of the middle of its underside
    (reference ``z < -0.9 R``, ``|y| < 0.25``), all ranks."""
    bulk = problem.bulks[0]
    owned = bulk.V.dofmap.index_map.size_local
    X = bulk.V.tabulate_dof_coordinates()[:owned]
    near = (X[:, 2] < -0.9 * R) & (np.abs(X[:, 1]) < 0.25)
    u_x = bulk.u.x.array.reshape(-1, 3)[:owned][near, 0]
    total = comm.allreduce(np.array([u_x.sum(), len(u_x)]))
    return float(total[0] / total[1])


for mu, problem in problems.items():
    plate_force = problem.obstacle_reaction(plates[mu])
    history = problem.history
    say(f"\nmu = {mu:g}: {len(history.steps)} steps, {len(history.cutbacks)} cut-backs")
    block_force = problem.contact_force(0)  # on the slave surface: the tube
    say(f"  force of the block on the tube {np.array2string(block_force, precision=4)}")
    say(f"  force of the plate on the tube {np.array2string(plate_force, precision=4)}")
    say(f"  sideways / normal plate force {plate_force[0] / plate_force[2]:+.3f}")
    say(f"  the tube's underside (middle) moved sideways by {underside_shift(problem):+.4f}")
    # the pressure on the whole tube balances itself nearly: measure against the plate force
    reactions = problem.reaction(["tube_ends", "block_top"]) + plate_force
    balance = np.linalg.norm(reactions + problem.load_resultant()) / np.linalg.norm(plate_force)
    say(f"  supports + plate + pressure: {balance:.1e} of the plate force")
    if mu > 0:
        excess = max(law.excess for law in laws[mu])
        say(f"  sliding: max(|lambda_T| - mu lambda_N) = {excess:+.1e} max(mu lambda_N)")
    say(f"  wall time {walls[mu]:.1f} s (search {problem.search_time:.2f} s)")

# %% [markdown]
# ## Pictures
# The deformed tube and block at the end, from above and from below (through the plate).
# The membrane is coloured by its contact pressure
# $t_N = \lambda_N$ from both pairs (the block above, the plate below; grey where open);
# the block is translucent and the plate is drawn at its final position.

# %%
for mu, problem in problems.items():
    for view, camera in (("above", (0.7, -1.0, 0.6)), ("below", (0.5, -1.0, -0.7))):
        name = out / f"membrane_mu{mu:g}_{view}.png"
        title = f"mu = {mu:g}, last step"
        output.plot_membrane_contact(problem, name, camera, title, obstacles=[plates[mu]])
        say(f"wrote {name}")
