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

import numpy as np
from mpi4py import MPI

from contact_ufl import output
from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples, traction_mismatch
from contact_ufl.verification import scenes
from contact_ufl.verification.analytic import Hertz2D, fit_elliptic_profile

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--h", type=float, default=0.005, help="element size at the contact")
parser.add_argument("--depth", type=float, default=0.005, help="imposed displacement of the top")
parser.add_argument("--steps", type=int, default=4, help="load steps")
parser.add_argument("--out", default="output", help="folder for pictures and VTX files")
args, _ = parser.parse_known_args()
comm = MPI.COMM_WORLD
out = Path(args.out)

# %% [markdown]
# ## The scene
# `scenes.hertz_2d` meshes the two bodies with gmsh (refined near the contact, the block
# 1.3 times coarser than the disc), clamps the bottom of the block and moves the flat top
# of the disc down by `depth`. The slave surface is the arc, the master surface the top of
# the block, and $\varepsilon_N = E / h$.

# %%
hertz = scenes.hertz_2d(h_contact=args.h, depth=args.depth)
problem = ContactProblem(hertz.scene)
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
exact = Hertz2D(P, hertz.radius, hertz.E_star)
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
if comm.size == 1:
    output.plot_deformed(problem, out / "hertz_deformed.png", zoom=4.0, focus=(0.0, 0.0, 0.0))
    print(f"wrote {out / 'hertz_deformed.png'}")
