"""Scenes from a user's own gmsh mesh: a .msh file or a live model, tags by group name."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import gmsh
import numpy as np
import pytest
from mpi4py import MPI

import contact_ufl  # noqa: F401  (loads the MPI/PETSc libraries before dolfinx)
from contact_ufl.contact import ContactPair
from contact_ufl.errors import ContactInputError, collective_check
from contact_ufl.gmshio import gmsh_session, read_gmsh
from contact_ufl.loads import BodyForce, DeadTraction, Dirichlet, FollowerPressure
from contact_ufl.materials import NeoHookean
from contact_ufl.problem import ContactProblem
from contact_ufl.results import equilibrium_error, lowest_displacement, section_motion
from contact_ufl.scene import Body, Scene

COMM = MPI.COMM_WORLD
PRESSURE = 0.01
MATERIAL = NeoHookean(1.0, 0.3)
#: Physical groups of :func:`two_blocks`: name -> (dimension, tag).
GROUPS = {
    "upper": (2, 1),
    "lower": (2, 2),
    "upper_contact": (1, 1),
    "lower_contact": (1, 2),
    "upper_top": (1, 3),
    "lower_bottom": (1, 4),
    "left": (1, 5),
}


def two_blocks(names: bool = True) -> None:
    """Mesh two stacked rectangles in the current gmsh model (non-matching interface).

    Upper ``[0, 1] x [0, 0.5]`` (h = 0.1), lower ``[0, 1] x [-0.5, 0]`` (h = 1/7); facet
    and cell groups share tag values (1, 2, ...), as gmsh numbers each dimension apart.
    """
    geo = gmsh.model.geo
    curves = {}
    surfaces = {}
    for body, y0, h in (("upper", 0.0, 0.1), ("lower", -0.5, 1.0 / 7.0)):
        p = [
            geo.addPoint(x, y, 0.0, h) for x, y in ((0, y0), (1, y0), (1, y0 + 0.5), (0, y0 + 0.5))
        ]
        lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
        curves[body] = dict(zip(("bottom", "right", "top", "left"), lines, strict=True))
        surfaces[body] = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    geo.synchronize()
    entities = {
        "upper": [surfaces["upper"]],
        "lower": [surfaces["lower"]],
        "upper_contact": [curves["upper"]["bottom"]],
        "lower_contact": [curves["lower"]["top"]],
        "upper_top": [curves["upper"]["top"]],
        "lower_bottom": [curves["lower"]["bottom"]],
        "left": [curves["upper"]["left"], curves["lower"]["left"]],
    }
    for name, (dim, tag) in GROUPS.items():
        gmsh.model.addPhysicalGroup(dim, entities[name], tag=tag, name=name if names else "")
    gmsh.model.mesh.generate(2)


def write_msh(path: Path, build: Callable[[], None]) -> None:
    """Build a model on rank 0 and write it to ``path``; all ranks wait for the file."""
    if COMM.rank == 0:
        with gmsh_session("written"):
            build()
            gmsh.write(str(path))
    COMM.barrier()


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """A folder that all ranks see (that of rank 0)."""
    return COMM.bcast(tmp_path_factory.mktemp("msh") if COMM.rank == 0 else None, root=0)


@pytest.fixture(scope="module")
def msh(folder) -> Path:
    path = folder / "two_blocks.msh"
    write_msh(path, two_blocks)
    return path


def global_count(mesh, meshtags, value: int) -> int:
    """Number of owned entities with ``value`` over all ranks."""
    size_local = mesh.topology.index_map(meshtags.dim).size_local
    owned = meshtags.indices[meshtags.values == value] < size_local
    return COMM.allreduce(int(owned.sum()), MPI.SUM)


def sizes(data) -> dict[str, int]:
    """Global cell count and the global size of every group."""
    tdim = data.mesh.topology.dim
    counts = {"cells": data.mesh.topology.index_map(tdim).size_global}
    for name, (dim, tag) in data.groups.items():
        counts[name] = global_count(
            data.mesh, data.cell_tags if dim == tdim else data.facet_tags, tag
        )
    return counts


def raises_everywhere(match: str, action: Callable[[], object]) -> None:
    """``action`` raises a ContactInputError matching ``match`` on every rank."""
    try:
        action()
        message = None
    except ContactInputError as error:
        message = str(error)
    ok = message is not None and re.search(match, message) is not None
    collective_check(
        COMM, ok, f"expected an error matching {match!r}, got {message!r}", AssertionError
    )


def named_parts(traction: float = PRESSURE):
    """Bodies, pair, supports and load of the two blocks, every tag by name."""
    return dict(
        bodies=[Body("upper", MATERIAL), Body("lower", MATERIAL)],
        contacts=[ContactPair("upper_contact", "lower_contact", eps_N=10.0)],
        dirichlet=[
            Dirichlet("lower_bottom", 0.0, component=1),
            Dirichlet("left", 0.0, component=0),
        ],
        loads=[DeadTraction("upper_top", lambda t: (0.0, -traction * t))],
    )


def test_file_and_live_model_agree(msh):
    from_file = read_gmsh(msh)
    if COMM.rank == 0:
        with gmsh_session("live"):
            two_blocks()
            from_model = read_gmsh(gmsh.model)
    else:
        from_model = read_gmsh(None)
    assert from_file.groups == GROUPS and from_model.groups == GROUPS
    assert from_file.mesh.geometry.dim == from_model.mesh.geometry.dim == 2
    counts = sizes(from_file)
    assert counts == sizes(from_model)
    assert counts["upper_contact"] == 10 and counts["lower_contact"] == 7
    assert counts["left"] == 5 + 4 and counts["cells"] > 100


def test_names_resolved_everywhere(msh):
    parts = named_parts()
    parts["loads"] += [BodyForce("lower", (0.0, 0.0)), FollowerPressure("upper_top", 0.0)]
    scene = Scene.from_gmsh(msh, **parts)
    tag = {name: t for name, (_, t) in GROUPS.items()}
    assert [b.tag for b in scene.bodies] == [tag["upper"], tag["lower"]]
    assert [b.name for b in scene.bodies] == ["upper", "lower"]
    assert (scene.contacts[0].slave, scene.contacts[0].master) == (1, 2)
    assert [d.tag for d in scene.dirichlet] == [tag["lower_bottom"], tag["left"]]
    assert [ld.tag for ld in scene.loads] == [tag["upper_top"], tag["lower"], tag["upper_top"]]
    every = [b.tag for b in scene.bodies] + [d.tag for d in scene.dirichlet]
    every += [ld.tag for ld in scene.loads] + [scene.contacts[0].slave, scene.contacts[0].master]
    assert all(type(t) is int for t in every)
    assert scene.facet_tag("left") == 5 and scene.facet_tag(7) == 7
    assert scene.cell_tag("lower") == 2
    scene.validate()


def test_legacy_tags_resolve_by_the_values_present(msh):
    """A scene given only ``tags`` (name -> int) finds the dimension of each name."""
    data = read_gmsh(msh)
    cells = {"upper": 1, "lower": 2}
    scene = Scene(data.mesh, data.cell_tags, data.facet_tags, [Body("upper", MATERIAL)], tags=cells)
    assert scene.bodies[0].tag == 1
    raises_everywhere(
        "no physical group is named 'upper_top'", lambda: scene.facet_tag("upper_top")
    )


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (
            dict(bodies=[Body("uper", MATERIAL)]),
            r"body 'uper': no physical group is named 'uper'; cell groups: \['lower', 'upper'\], "
            r"facet groups: \['left', 'lower_bottom', 'lower_contact', 'upper_contact', "
            r"'upper_top'\]",
        ),
        (
            dict(contacts=[ContactPair("upper", "lower_contact", eps_N=10.0)]),
            r"contact pair 0, slave surface: physical group 'upper' has dimension 2 \(cell "
            r"group \(a body\)\), but a facet group \(a boundary part\) of dimension 1",
        ),
        (
            dict(contacts=[ContactPair("upper_contact", "lowr_contact", eps_N=10.0)]),
            "contact pair 0, master surface: no physical group is named 'lowr_contact'",
        ),
        (
            dict(bodies=[Body("upper_contact", MATERIAL)]),
            r"physical group 'upper_contact' has dimension 1 \(facet group",
        ),
        (
            dict(dirichlet=[Dirichlet("lower", 0.0)]),
            r"Dirichlet 'lower': physical group 'lower' has dimension 2",
        ),
        (dict(loads=[BodyForce("upper_top", (0.0, 1.0))]), "BodyForce 'upper_top': physical"),
        (dict(loads=[DeadTraction("nowhere", (0.0, 1.0))]), "no physical group is named"),
    ],
)
def test_bad_names(msh, change, match):
    parts = {**named_parts(), **change}
    raises_everywhere(match, lambda: Scene.from_gmsh(msh, **parts))


def test_results_helpers_refuse_a_cell_group(msh):
    scene = Scene.from_gmsh(msh, **named_parts())
    raises_everywhere(
        "facet tag 'upper': physical group 'upper' has dimension 2",
        lambda: scene.facet_tag("upper"),
    )


def test_missing_file(folder):
    raises_everywhere(
        r"mesh file '.*nowhere\.msh' does not exist", lambda: read_gmsh(folder / "nowhere.msh")
    )


def test_dimension_mismatch(msh):
    raises_everywhere(
        r"holds a mesh of dimension 2, but 3D cells are needed",
        lambda: Scene.from_gmsh(msh, gdim=3, **named_parts()),
    )
    raises_everywhere("gdim = 1 is too small", lambda: read_gmsh(msh, gdim=1))


def test_unnamed_groups(folder):
    path = folder / "unnamed.msh"
    write_msh(path, lambda: two_blocks(names=False))
    raises_everywhere(
        r"physical groups without a name, \(dim, tag\) = \[",
        lambda: Scene.from_gmsh(path, **named_parts()),
    )
    # integer tags need no names
    integers = Scene.from_gmsh(path, bodies=[Body(1, MATERIAL), Body(2, MATERIAL)])
    assert integers.groups == {} and [b.tag for b in integers.bodies] == [1, 2]


def test_name_used_twice(folder):
    path = folder / "twice.msh"

    def build():
        two_blocks()
        gmsh.model.addPhysicalGroup(1, [1], name="upper")

    write_msh(path, build)
    raises_everywhere(r"the name 'upper' is used by two physical groups", lambda: read_gmsh(path))


def test_plane_mesh_off_its_plane(folder):
    """A 2D mesh at z = 1: reading it as gdim = 2 would drop z."""
    path = folder / "lifted.msh"

    def build():
        two_blocks()
        gmsh.model.mesh.affineTransform([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1])

    write_msh(path, build)
    raises_everywhere("the mesh is not in the first 2 coordinate axes", lambda: read_gmsh(path))
    assert read_gmsh(path, gdim=3).mesh.geometry.dim == 3


def test_model_without_mesh():
    def action():
        if COMM.rank == 0:
            with gmsh_session("empty"):
                gmsh.model.geo.addPoint(0.0, 0.0, 0.0)
                gmsh.model.geo.synchronize()
                return read_gmsh(gmsh.model)
        return read_gmsh(None)

    raises_everywhere("holds no mesh: generate it first", action)


@pytest.fixture(scope="module")
def solved(msh):
    """The pressed blocks solved with tags by name and by integer (one load step)."""
    integer_parts = dict(
        bodies=[Body(1, MATERIAL), Body(2, MATERIAL)],
        contacts=[ContactPair(1, 2, eps_N=10.0)],
        dirichlet=[Dirichlet(4, 0.0, component=1), Dirichlet(5, 0.0, component=0)],
        loads=[DeadTraction(3, lambda t: (0.0, -PRESSURE * t))],
    )
    problems = []
    for parts in (named_parts(), integer_parts):
        problem = ContactProblem(Scene.from_gmsh(msh, **parts), verbose=False)
        problem.solve(num_steps=1)
        problems.append(problem)
    return problems


#: the scene of :func:`solved`
BLOCKS = "two blocks from a gmsh file, pressed by p = 0.01 (Neo-Hookean, one step)"
#: The bound of the force balance of the converged solve, relative to the load: the Newton
#: iterations end at round-off here (measured <= 6.2e-15 on 1 and 2 ranks), far below their
#: tolerance.
BALANCE = 1e-12
#: The bound of the same scene solved with tags by name and by integer, relative: equal on
#: one rank, round-off apart on two (measured 1.4e-15).
SAME = 1e-14
EQUILIBRIUM = "equilibrium of the converged solve (force-driven: the load passes through)"
INTEGER_TAGS = "the same scene with integer tags"


def test_named_scene_solves_like_integer_tags(solved, verification):
    """The same contact force, which carries the applied load (width 1) through the
    interface (consistency)."""
    named, integer = (problem.contact_force() for problem in solved)
    error = abs(named[1] / PRESSURE - 1.0)
    verification(BLOCKS, "|F_y / (p w) - 1|", error, 0.0, BALANCE, EQUILIBRIUM, kind="consistency")
    assert error <= BALANCE
    same = np.abs(named - integer).max() / np.linalg.norm(integer)
    quantity = "max |F - F_integer tags| / |F|"
    verification(BLOCKS, quantity, same, 0.0, SAME, INTEGER_TAGS, kind="consistency")
    assert same <= SAME


def test_results_helpers_take_names(solved, verification):
    """The results helpers take group names and give what they give with integer tags;
    the support's reaction balances the load, as does the sum of all reactions
    (consistency)."""
    named, integer = solved
    support = named.reaction("lower_bottom")
    error = abs(support[1] / PRESSURE - 1.0)
    quantity = "|R_y / (p w) - 1| (lower_bottom)"
    verification(BLOCKS, quantity, error, 0.0, BALANCE, EQUILIBRIUM, kind="consistency")
    assert error <= BALANCE
    reaction = integer.reaction(4)
    assert np.abs(support - reaction).max() <= SAME * np.linalg.norm(reaction)
    errors = [equilibrium_error(named, ["lower_bottom", "left"])]
    errors.append(equilibrium_error(integer, [4, 5]))
    quantity = "equilibrium_error (tags by name, by integer)"
    verification(BLOCKS, quantity, errors, 0.0, BALANCE, EQUILIBRIUM, kind="consistency")
    assert max(errors) <= BALANCE
    sunk = lowest_displacement(named, "upper_top")
    assert sunk < 0.0 and sunk == pytest.approx(lowest_displacement(integer, 3), rel=SAME)
    motion, normal = section_motion(named, "upper_top")
    moved = section_motion(integer, 3)[0]
    assert np.abs(motion - moved).max() <= SAME * np.abs(moved).max()
    # the top stays flat under the uniform pressure: its normal +y to the solve's tolerance
    # (measured 1.8e-9 off)
    assert abs(normal[0]) < 1e-8 and normal[1] > 0.0
    raises_everywhere(
        "facet tag 'upper': physical group 'upper' has dimension 2", lambda: named.reaction("upper")
    )
