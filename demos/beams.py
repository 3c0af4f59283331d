# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Two hyperelastic beams, one pushed at its tip by a follower force
#
# The showcase of the founding abstract: two Neo-Hookean cantilevers, clamped at the same
# end, overlap in plan with a gap between them; the lower one is shorter on the clamped
# side. The free tip of the upper beam carries a *follower* force: it stays perpendicular
# to the deformed end section, so the load turns with the beam. The upper beam bends into
# large rotations, its tip corner lands on the lower beam and presses it down. The lower
# beam, pressed near its own free end by a shorter lever, turns faster than the upper one:
# the upper beam's underside bends onto it and slides along it over a contact zone half
# the overlap long. Coulomb friction ($\mu = 0.3$) holds it back, and the beams end in a
# different state.
#
# The two beams have their own, non-matching hexahedral meshes. The unknowns are the
# displacements of both beams and the contact multipliers $\lambda_N$ (and, with friction,
# $\lambda_T$) on the slave surface, the bottom of the upper beam. The contact integrals use
# a Gauss-Lobatto rule, whose points include the vertices of the slave facets: the tip
# corner, where the beams first touch, is itself a contact point.
#
# Run it as `python demos/beams.py`, `mpirun -n 2 python demos/beams.py`, or as a notebook;
# `--divisions` sets the mesh (elements through the height), `--mu` the friction
# coefficients.

# %%
import argparse
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from contact_ufl import output
from contact_ufl.problem import ContactProblem
from contact_ufl.results import coulomb_law, equilibrium_error, section_motion
from contact_ufl.verification import scenes

parser = argparse.ArgumentParser(description="Two beams in contact, follower tip force")
parser.add_argument("--divisions", type=int, default=3, help="elements through the height")
parser.add_argument("--mu", type=float, nargs="+", default=[0.0, 0.3], help="friction")
parser.add_argument("--load", type=float, default=6.0, help="final tip force in EI / L^2")
parser.add_argument("--steps", type=int, default=20, help="load steps")
parser.add_argument("--out", default="output", help="folder for pictures and VTX files")
args, _ = parser.parse_known_args()
comm = MPI.COMM_WORLD
out = Path(args.out)

say = output.say  # progress on rank 0


# %% [markdown]
# ## The scene
# `scenes.beams` meshes the pair with gmsh (`contact_ufl.verification.geometries.beams_3d`):
# the upper beam (length 10, section 1 x 1, 0.5 above the lower one) is clamped at its right
# end; the lower one (length 10, section 1.5 wide x 1 high, wider, with elements 1.25 times
# longer) at its right end too, 2 short of the upper clamp, so that the upper tip is 8 from
# it. The follower force grows linearly in pseudo-time to `load` EI/L^2. The reference
# configuration, in 3D and in the plane of bending:

# %%
problems = {
    mu: ContactProblem(scenes.beams(mu=mu, divisions=args.divisions, load=args.load).scene)
    for mu in args.mu
}
first = problems[args.mu[0]]
output.plot_reference(first, out / "beams_reference.png", "iso", "reference configuration")
output.plot_reference(first, out / "beams_reference_xz.png", "xz", "reference, in-plane view")
say(f"{first.layout.global_size} unknowns for mu = {args.mu[0]}")

# %% [markdown]
# ## Load stepping
# Every step is a Newton solve of the whole system (PETSc SNES); the tangent is the UFL
# derivative of the residual, chained through the closest-point projection onto the lower
# beam. A step that fails is cut back. Displacements and multipliers of every step go to
# VTX files for ParaView.

# %%
walls, coulomb = {}, {mu: [] for mu in problems if mu > 0}
FLOOR = 1e-3  # the Coulomb check leaves out lambda_N <= FLOOR max(lambda_N): the zone's edge
for mu, problem in problems.items():
    say(f"\n--- mu = {mu} ---")
    writer = output.ResultWriter(problem, out / f"beams_mu{mu:g}")

    def record(problem, step, writer=writer, mu=mu):
        writer(problem, step)
        if mu > 0:  # the Coulomb law at every converged step
            coulomb[mu].append(coulomb_law(problem, floor=FLOOR))

    start = time.perf_counter()
    problem.solve(num_steps=args.steps, callback=record)
    walls[mu] = time.perf_counter() - start
    writer.close()

# %% [markdown]
# ## Results
# The tip displacement is the mean displacement of the free end section; its rotation the
# angle of the deformed section's normal. Global equilibrium: the clamp reactions balance
# the follower force (the contact forces are internal to the pair). With friction the
# frictional traction must lie in the Coulomb disc at every slave point, with the slip
# along it. The check reads the P1 multipliers, which equal the applied traction weakly:
# at the edge of the contact zone a point in contact can carry $\lambda_N \approx 0$ (even
# slightly negative), where the disc has no radius and $\lambda_T$ no direction; those
# points, with $\lambda_N$ below $10^{-3}$ of its peak, are left out.

# %%
for mu, problem in problems.items():
    tags = problem.scene.tags
    u_tip, n_tip = section_motion(problem, tags["upper_tip"])
    rotation = np.degrees(np.arctan2(-n_tip[2], -n_tip[0]))
    history = problem.history
    say(f"\nmu = {mu}: {len(history.steps)} steps, {len(history.cutbacks)} cut-backs")
    tip = np.array2string(u_tip, precision=4)
    say(f"  tip displacement  {tip}, rotation {rotation:.1f} deg")
    force = np.array2string(problem.contact_force(), precision=4)
    say(f"  contact force on the upper beam  {force}")
    balance = equilibrium_error(problem, ["upper_clamp", "lower_clamp"])
    say(f"  clamp reactions + follower force: {balance:.1e} of the force")
    if mu > 0:
        excess = max(law.excess for law in coulomb[mu])
        alignment = min(law.alignment for law in coulomb[mu])
        slipping = sum(law.slipping > 0 for law in coulomb[mu])
        slip_excess = max(law.slip_excess for law in coulomb[mu])
        say(
            f"  Coulomb law over all steps: max(|lambda_T| - mu lambda_N) = {excess:+.1e} "
            f"max(mu lambda_N); slip in {slipping} steps, cos(slip, lambda_T) >= {alignment:.4f}, "
            f"|lambda_T| = mu lambda_N where slipping to {slip_excess:.1e}"
        )
    say(f"  wall time {walls[mu]:.1f} s (search {problem.search_time:.2f} s)")

# %% [markdown]
# ## Pictures
# The deformed beams at the last step, translucent. The slave surface (the underside of the
# upper beam) is coloured by the normal traction $t_N = \lambda_N$ where it is in contact,
# grey where open: a 3D view through the upper beam, and the in-plane view, where the
# contact tractions on the upper beam are arrows. The tip corner, pushed in by the follower
# force, carries a peak several times the pressure over the rest of the zone: colours and
# arrow lengths saturate at the 80th percentile (the colour bar gives the peak). With
# friction, the black arrows are the frictional tractions on the upper beam.

# %%
for mu, problem in problems.items():
    pair = problem.contacts[0]  # the reference x of the slave points in contact
    x = np.concatenate(comm.allgather(pair.slave.X.reshape(-1, 3)[pair.active(), 0]))
    zone = f", {x.min():.2f} <= X <= {x.max():.2f}" if len(x) else ""
    say(f"mu = {mu}: {len(x)} slave points in contact{zone}")
    for view, camera in (("iso", (-0.6, -1.0, 0.8)), ("xz", "xz")):
        name = out / f"beams_mu{mu:g}_{view}.png"
        title = f"mu = {mu:g}, last step"
        output.plot_contact_state(problem, name, camera, title, saturate=80.0, zoom=1.3)
        say(f"wrote {name}")
