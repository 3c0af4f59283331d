# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Indentation of an elastoplastic block, and lift-off (plane strain)
#
# A stiff Neo-Hookean half disc ($R = 1$, $E = 10$) is pressed $0.02$ into a block and
# lifted off again. The block is either Neo-Hookean ($E = 1$) or made of finite-strain
# J2 plasticity (`contact_ufl.plasticity.J2Plasticity`: the same small-strain elasticity, von Mises
# yield stress $\sigma_y = 0.01$, no hardening). The contact is the augmented-Lagrangian
# mixed form of `contact_ufl`, frictionless; the tangent of the plastic return map comes
# from `ufl.derivative` like the rest.
#
# What to expect: the elastic block follows Hertz and springs back when the disc lifts off.
# The plastic block yields under the contact: its peak pressure cannot exceed the
# plane-strain indentation hardness, Prandtl's $(2 + \pi) k = 2.97 \sigma_y$ with
# $k = \sigma_y / \sqrt{3}$, and it keeps an imprint.
#
# Run it as `python demos/plastic_indentation.py`, with `mpirun -n 2`, or as a notebook.

# %%
import argparse
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from contact_ufl import output
from contact_ufl.loads import evaluate
from contact_ufl.problem import ContactProblem
from contact_ufl.results import contact_samples, lowest_displacement
from contact_ufl.verification import scenes

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--h", type=float, default=0.01, help="element size at the contact")
parser.add_argument("--depth", type=float, default=0.02, help="deepest position of the disc")
parser.add_argument("--yield-stress", type=float, default=0.01, help="sigma_y of the block")
parser.add_argument("--steps", type=int, default=8, help="load steps down (and as many up)")
parser.add_argument("--out", default="output", help="folder for pictures and VTX files")
args, _ = parser.parse_known_args()
comm = MPI.COMM_WORLD
out = Path(args.out)
say = print if comm.rank == 0 else (lambda *a, **k: None)
blocks = {"elastic": None, "plastic": args.yield_stress}

# %% [markdown]
# ## Down and up again
# `scenes.plastic_indentation` is the Hertz geometry with the block's material swapped
# and the disc's top moved down from t = 0 to 1 and back up from t = 1 to 2. Each step
# records the disc's depth and the contact force; at the deepest point we keep the peak
# contact pressure (Cauchy). The plastic history moves only when a step has converged.

# %%
problems, curves, peaks = {}, {}, {}
for name, yield_stress in blocks.items():
    scene = scenes.plastic_indentation(
        depth=args.depth, yield_stress=yield_stress, h_contact=args.h
    )
    problem = ContactProblem(scene, verbose=False)
    (disc,) = [d for d in scene.dirichlet if d.tag == scene.tags["cylinder_top"]]
    writer = output.ResultWriter(problem, out / f"indentation_{name}")
    curve = [(0.0, 0.0)]

    def record(problem, step, curve=curve, disc=disc, writer=writer):
        curve.append((-evaluate(disc.value, step.t)[1], problem.contact_force()[1]))
        writer(problem, step)

    start = time.perf_counter()
    problem.solve(num_steps=args.steps, t_end=1.0, callback=record)
    peaks[name] = contact_samples(problem).pressure.max()
    problem.solve(num_steps=args.steps, t_end=2.0, callback=record)
    writer.close()
    say(f"{name}: {len(problem.history.steps)} steps, {time.perf_counter() - start:.1f} s")
    problems[name], curves[name] = problem, np.array(curve)

# %% [markdown]
# ## Force, peak pressure and imprint
# The imprint is the depth of the lowest point of the block's top once the disc has lifted
# off.

# %%
say(f"{'depth':>8} " + " ".join(f"{name + ' force':>14}" for name in blocks))
for k in range(len(curves["elastic"])):
    say(f"{curves['elastic'][k, 0]:8.4f} " + " ".join(f"{curves[n][k, 1]:14.4e}" for n in blocks))
hardness = (2.0 + np.pi) / np.sqrt(3.0)
for name, problem in problems.items():
    imprint = -lowest_displacement(problem, "block_contact")
    say(
        f"{name}: peak pressure {peaks[name] / args.yield_stress:.2f} sigma_y "
        f"(Prandtl {hardness:.2f} sigma_y), imprint {imprint:.2e} = "
        f"{imprint / args.depth:.0%} of the depth"
    )

# %% [markdown]
# ## Pictures
# The force against the depth (the plastic block's unloading branch is stiff and ends at
# the imprint) and the equivalent plastic strain left in the block.

# %%
if comm.rank == 0:
    output.plot_curves(
        {name: (c[:, 0], c[:, 1]) for name, c in curves.items()},
        out / "indentation_force.png",
        "depth of the disc",
        "contact force",
        "indentation and lift-off",
    )
    say(f"wrote {out / 'indentation_force.png'}")
if comm.size == 1:
    plastic = problems["plastic"]
    (history,) = plastic.histories.values()
    output.plot_deformed(
        plastic,
        out / "indentation_plastic_strain.png",
        zoom=3.0,
        focus=(0.0, 0.0, 0.0),
        cell_field=history.update_plastic_strain(),
        label="equivalent plastic strain",
    )
    say(f"wrote {out / 'indentation_plastic_strain.png'}")
