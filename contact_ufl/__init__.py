"""contact_ufl: large-deformation frictional contact for FEniCSx.

Augmented-Lagrangian mixed weak form (displacements of all bodies plus contact multipliers
on the slave surface), closest-point projection onto the master surface, Newton (PETSc SNES)
with the tangent from UFL's Gateaux derivative chained through the master side.

A scene is read from a gmsh mesh with named physical groups, and solved::

    import contact_ufl as cu

    scene = cu.Scene.from_gmsh(
        "two_blocks.msh",
        bodies=[cu.Body("upper", cu.NeoHookean(E=1.0, nu=0.3)),
                cu.Body("lower", cu.NeoHookean(E=1.0, nu=0.3))],
        dirichlet=[cu.Dirichlet("lower_bottom", (0.0, 0.0)),
                   cu.Dirichlet("upper_top", lambda t: (0.0, -0.01 * t))],
        contacts=[cu.ContactPair(slave="upper_contact", master="lower_contact")],
    )
    problem = cu.ContactProblem(scene)
    problem.solve(num_steps=4)
    print(problem.contact_force())

Bodies on meshes of their own are the domains (:class:`Domain`) of one scene
(``Scene(domains=[...], contacts=[...])``), each with its own displacement field.

The parts, as modules: :mod:`.scene` (bodies, domains, supports, loads, pairs),
:mod:`.gmshio` (meshes from gmsh), :mod:`.materials`, :mod:`.plasticity`, :mod:`.loads`,
:mod:`.membranes` (membranes and strings), :mod:`.contact` (the contact pair as composed
parts), :mod:`.bulk` (the displacement and bulk
weak form of one mesh), :mod:`.problem` (fields, forms and results), :mod:`.operator` (the
discrete operator: residual and tangent of an iterate), :mod:`.newton` (the SNES driver),
:mod:`.strategies` (how a load step is tried), :mod:`.diagnosis` (why it failed),
:mod:`.stepping` (load stepping with cut-back), :mod:`.results`, :mod:`.output`,
:mod:`.taylor`. Verification scenes and references live in :mod:`.verification`, which the
library never imports.
"""

from contact_ufl import (
    _stack,  # noqa: F401  (loads the MPI/PETSc libraries first)
    output,
    results,
)
from contact_ufl.adapt import refine_to_tolerance
from contact_ufl.checkpoint import Checkpoints
from contact_ufl.contact import ContactPair, RigidCylinder, RigidPlane, RigidSphere
from contact_ufl.control import VolumeControl
from contact_ufl.errors import (
    ContactInputError,
    ConvergenceError,
    CrackWarning,
    NonUniqueSolutionWarning,
)
from contact_ufl.loads import (
    BodyForce,
    DeadForce,
    DeadTraction,
    Dirichlet,
    FollowerForce,
    FollowerPressure,
    RigidMotion,
)
from contact_ufl.materials import (
    LinearElastic,
    NearlyIncompressibleWarning,
    NeoHookean,
    SaintVenantKirchhoff,
)
from contact_ufl.membranes import (
    MembraneCompressibleNeoHookean,
    MembraneNeoHookean,
    MembraneSVK,
)
from contact_ufl.newton import FIELD_SPLIT_PETSC_OPTIONS, NewtonDriver
from contact_ufl.operator import ContactOperator
from contact_ufl.output import ResultWriter
from contact_ufl.plasticity import J2Plasticity
from contact_ufl.problem import ContactProblem
from contact_ufl.scene import Body, Domain, Scene
from contact_ufl.stepping import History, LoadStepper, StepRecord
from contact_ufl.strategies import StepSolver, default_strategies
from contact_ufl.taylor import taylor_test
from contact_ufl.timings import NewtonTimings

__version__ = "0.1.0"

__all__ = [
    "FIELD_SPLIT_PETSC_OPTIONS",
    "Body",
    "BodyForce",
    "ContactInputError",
    "ContactOperator",
    "ContactPair",
    "ContactProblem",
    "ConvergenceError",
    "CrackWarning",
    "DeadForce",
    "DeadTraction",
    "Dirichlet",
    "Domain",
    "FollowerForce",
    "FollowerPressure",
    "Checkpoints",
    "History",
    "J2Plasticity",
    "LinearElastic",
    "LoadStepper",
    "MembraneCompressibleNeoHookean",
    "MembraneNeoHookean",
    "MembraneSVK",
    "MeshData",
    "NearlyIncompressibleWarning",
    "NeoHookean",
    "NewtonDriver",
    "NewtonTimings",
    "NonUniqueSolutionWarning",
    "ResultWriter",
    "RigidCylinder",
    "RigidMotion",
    "RigidPlane",
    "RigidSphere",
    "SaintVenantKirchhoff",
    "Scene",
    "StepRecord",
    "StepSolver",
    "VolumeControl",
    "default_strategies",
    "output",
    "read_gmsh",
    "refine_to_tolerance",
    "results",
    "taylor_test",
]

_GMSH = {"read_gmsh", "MeshData"}  # gmsh is imported when they are first used


def __getattr__(name: str):
    if name in _GMSH:
        from contact_ufl import gmshio

        return getattr(gmshio, name)
    raise AttributeError(f"module 'contact_ufl' has no attribute {name!r}")
