"""The public API: `import contact_ufl as cu` gives the scene pieces, the problem and its
solve, the results and output helpers; a scene is written with names only."""

import inspect
import subprocess
import sys

import gmsh
import pytest
from mpi4py import MPI

import contact_ufl as cu
from contact_ufl.gmshio import gmsh_session


def test_all_names_exist_and_are_documented():
    assert len(set(cu.__all__)) == len(cu.__all__)
    for name in cu.__all__:
        item = getattr(cu, name)
        assert inspect.getdoc(item), f"contact_ufl.{name} has no docstring"
    for name in ("Scene", "Body", "ContactPair", "ContactProblem", "Dirichlet", "read_gmsh"):
        assert name in cu.__all__


@pytest.mark.serial
def test_import_needs_neither_gmsh_nor_pyvista():
    code = (
        "import sys, contact_ufl as cu; "
        "print('gmsh' in sys.modules, 'pyvista' in sys.modules, 'contact_ufl.verification' "
        "in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False", "False"]


def two_squares() -> None:
    """A unit square on a wider block, non-matching meshes, named groups."""
    occ = gmsh.model.occ
    upper = occ.addRectangle(0.0, 0.0, 0.0, 1.0, 1.0)
    lower = occ.addRectangle(-0.5, -1.0, 0.0, 2.0, 1.0)
    occ.synchronize()
    gmsh.model.mesh.setSize(gmsh.model.getBoundary([(2, upper)], recursive=True), 0.2)
    gmsh.model.mesh.setSize(gmsh.model.getBoundary([(2, lower)], recursive=True), 0.3)

    def side(surface, y):
        curves = gmsh.model.getBoundary([(2, surface)], oriented=False)
        for _, c in curves:
            lo = gmsh.model.getBoundingBox(1, c)
            if abs(lo[1] - y) < 1e-6 and abs(lo[4] - y) < 1e-6:
                return c
        raise RuntimeError(f"no side at y = {y}")

    for dim, tags, name in (
        (2, [upper], "upper"),
        (2, [lower], "lower"),
        (1, [side(upper, 0.0)], "upper_bottom"),
        (1, [side(upper, 1.0)], "upper_top"),
        (1, [side(lower, 0.0)], "lower_top"),
        (1, [side(lower, -1.0)], "lower_bottom"),
    ):
        gmsh.model.addPhysicalGroup(dim, tags, name=name)
    gmsh.model.mesh.generate(2)


def test_a_scene_written_with_names_only():
    """Press a square onto a block, with names and the default eps_N: the steps converge
    without cut-back, and the contact force is the reaction of the pressed side."""
    comm = MPI.COMM_WORLD
    with gmsh_session("api"):
        if comm.rank == 0:
            two_squares()
        material = cu.NeoHookean(E=1.0, nu=0.3)
        scene = cu.Scene.from_gmsh(
            gmsh.model if comm.rank == 0 else None,
            bodies=[cu.Body("upper", material), cu.Body("lower", material)],
            dirichlet=[
                cu.Dirichlet("lower_bottom", (0.0, 0.0)),
                cu.Dirichlet("upper_top", lambda t: (0.0, -0.01 * t)),
            ],
            contacts=[cu.ContactPair(slave="upper_bottom", master="lower_top")],
            gdim=2,
        )
    problem = cu.ContactProblem(scene, verbose=False)
    history = problem.solve(num_steps=2)
    assert len(history.steps) == 2 and not history.cutbacks
    force = problem.contact_force()
    assert force[1] > 0.0
    top = problem.reaction("upper_top")
    assert abs(top[1] + force[1]) < 1e-8 * force[1]


@pytest.mark.serial  # gmsh runs on this rank alone
@pytest.mark.parametrize("verbose", [False, True])
def test_gmsh_messages_are_passed_on_request(capfd, verbose):
    """gmsh_session silences gmsh by default and passes its messages with verbose=True."""
    with gmsh_session("talk", verbose=verbose):
        two_squares()
    out = capfd.readouterr()
    assert ("Meshing" in out.out + out.err) == verbose
