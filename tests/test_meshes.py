"""Tests of the two-body contact scene meshes (serial and ``mpirun -n 2``)."""

from __future__ import annotations

import functools
import math
from pathlib import Path

# isort: off
import contact_ufl  # noqa: F401  (loads the MPI/PETSc libraries before dolfinx)

# isort: on
import dolfinx
import dolfinx.fem
import dolfinx.mesh
import gmsh
import numpy as np
import numpy.typing as npt
import pytest
import ufl
from mpi4py import MPI

from contact_ufl.gmshio import MeshData
from contact_ufl.verification import geometries

COMM = MPI.COMM_WORLD
#: The bound of the flat groups' measures, relative: round-off of a sum over the cells
#: (measured <= 1e-14, on the hexahedra).
FLAT = 1e-13
#: The bounds of the curved groups' measures, relative: the chords of degree-1 meshes
#: (measured 2.4e-3 in 2D, 5.9e-3 in 3D, at their default sizes) and of degree 2 (8.4e-7).
CURVED = {(2, 1): 5e-3, (3, 1): 1e-2, (2, 2): 2e-6}
#: The bound of the distance of a contact node from its circle: round-off of coordinates of
#: size ~1 (measured <= 6.7e-15).
ON_CIRCLE = 2e-14
#: the source of the exact measures and surfaces
CLOSED_FORM = "closed form: the lengths, areas and volumes of the scene's geometry"

# scene key -> (generator, keyword arguments, (slave group, master group), (slave, master) body)
SCENES = {
    "hertz_2d": (geometries.hertz_2d, {}, ("cylinder", "block")),
    "hertz_2d_p2_gap": (geometries.hertz_2d, {"order": 2, "gap": 0.05}, ("cylinder", "block")),
    "curved_2d": (geometries.curved_2d, {}, ("cylinder", "block")),
    "curved_2d_concave": (
        geometries.curved_2d,
        {"lower_radius": -3.0, "gap": 0.02},
        ("cylinder", "block"),
    ),
    "patch_2d": (geometries.patch_2d, {}, ("upper", "lower")),
    "patch_2d_quad": (geometries.patch_2d, {"cell": "quadrilateral"}, ("upper", "lower")),
    "patch_3d": (geometries.patch_3d, {}, ("upper", "lower")),
    "patch_3d_hex": (geometries.patch_3d, {"cell": "hexahedron", "gap": 0.1}, ("upper", "lower")),
    "cylinders_3d": (geometries.cylinders_3d, {}, ("upper", "lower")),
    "cylinders_3d_gap": (
        geometries.cylinders_3d,
        {"lower_radius": 4.0, "gap": 0.05},
        ("upper", "lower"),
    ),
}


@functools.cache
def scene(key: str) -> MeshData:
    """Build each scene once (collectively: every rank runs the tests in the same order)."""
    generator, kwargs, _ = SCENES[key]
    return generator(**kwargs)


def contact_names(key: str) -> tuple[str, str]:
    slave, master = SCENES[key][2]
    return f"{slave}_contact", f"{master}_contact"


# --------------------------------------------------------------------------------------------
# exact measures: name -> (value, curved)
# --------------------------------------------------------------------------------------------


def _arch(R2: float, b: float, sign: float) -> tuple[float, float, float]:
    """Top ``sign * (sqrt(R2^2 - s^2) - R2)`` on ``[-b, b]``: (integral, arc length, top(b))."""
    integral = b * math.sqrt(R2 * R2 - b * b) + R2 * R2 * math.asin(b / R2) - 2.0 * b * R2
    top_b = math.sqrt(R2 * R2 - b * b) - R2
    return sign * integral, 2.0 * R2 * math.asin(b / R2), sign * top_b


def exact_measures(key: str) -> dict[str, tuple[float, bool]]:
    kwargs = SCENES[key][1]
    if key.startswith(("hertz", "curved")):
        R, (w, H) = 1.0, (4.0, 1.5)
        disc = {
            "cylinder": (0.5 * math.pi * R * R, True),
            "cylinder_contact": (math.pi * R, True),
            "cylinder_top": (2.0 * R, False),
            "block_bottom": (w, False),
        }
        if key.startswith("hertz"):
            return disc | {
                "block": (w * H, False),
                "block_contact": (w, False),
                "block_sides": (2.0 * H, False),
            }
        lower_radius = kwargs.get("lower_radius", 3.0 * R)
        integral, arc, top = _arch(abs(lower_radius), 0.5 * w, math.copysign(1.0, lower_radius))
        return disc | {
            "block": (w * H + integral, True),
            "block_contact": (arc, True),
            "block_sides": (2.0 * (H + top), False),
        }
    if key.startswith("patch_2d"):
        w, H = 1.0, 0.5
        values = {"upper": w * H, "lower": w * H, "upper_contact": w, "lower_contact": w}
        values |= {"upper_top": w, "lower_bottom": w}
        values |= {f"{b}_{s}": H for b in ("upper", "lower") for s in ("left", "right")}
        return {name: (value, False) for name, value in values.items()}
    if key.startswith("patch_3d"):
        w, H = 1.0, 0.5
        values = {"upper": w * w * H, "lower": w * w * H}
        values |= {
            n: w * w for n in ("upper_contact", "lower_contact", "upper_top", "lower_bottom")
        }
        values |= {f"{b}_{s}": w * H for b in ("upper", "lower") for s in ("x0", "x1", "y0", "y1")}
        return {name: (value, False) for name, value in values.items()}
    # cylinders_3d
    R, L = 1.0, 1.0
    wx, wy, H = 2.0 * R, 1.5 * L, 0.5 * R
    lower_radius = kwargs.get("lower_radius", 3.0 * R)
    integral, arc, top = _arch(abs(lower_radius), 0.5 * wy, math.copysign(1.0, lower_radius))
    return {
        "upper": (0.5 * math.pi * R * R * L, True),
        "lower": (wx * (wy * H + integral), True),
        "upper_contact": (math.pi * R * L, True),
        "lower_contact": (wx * arc, True),
        "upper_top": (2.0 * R * L, False),
        "lower_bottom": (wx * wy, False),
        "upper_ends": (math.pi * R * R, True),
        "lower_sides": (2.0 * (wy * H + integral) + 2.0 * wx * (H + top), True),
    }


# --------------------------------------------------------------------------------------------
# helpers (collective)
# --------------------------------------------------------------------------------------------


def measure(sm: MeshData, name: str) -> float:
    """Global length/area/volume of the group ``name``."""
    mesh = sm.mesh
    is_cell = sm.tags[name] < 10
    d = ufl.Measure(
        "dx" if is_cell else "ds",
        domain=mesh,
        subdomain_data=sm.cell_tags if is_cell else sm.facet_tags,
    )
    one = dolfinx.fem.Constant(mesh, dolfinx.default_scalar_type(1.0))
    local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * d(sm.tags[name])))
    return mesh.comm.allreduce(local, op=MPI.SUM)


def owned_count(sm: MeshData, name: str) -> int:
    """Global number of entities in the group ``name``."""
    mesh = sm.mesh
    is_cell = sm.tags[name] < 10
    dim = mesh.topology.dim - (0 if is_cell else 1)
    entities = sm.cells(name) if is_cell else sm.facets(name)
    n_owned = np.count_nonzero(entities < mesh.topology.index_map(dim).size_local)
    return mesh.comm.allreduce(int(n_owned), op=MPI.SUM)


def facet_nodes(sm: MeshData, name: str) -> npt.NDArray[np.float64]:
    """Coordinates of all geometry nodes of the facets ``name``, gathered on every rank."""
    mesh = sm.mesh
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    facets = sm.facets(name)
    if len(facets) > 0:
        nodes = dolfinx.mesh.entities_to_geometry(mesh, tdim - 1, facets).ravel()
        x = mesh.geometry.x[np.unique(nodes)]
    else:
        x = np.zeros((0, 3))
    x = np.vstack(mesh.comm.allgather(x))
    return np.unique(np.round(x, 14), axis=0)


def body_vertices(sm: MeshData, body: str) -> npt.NDArray[np.int64]:
    """Global indices of the vertices of the cells of ``body``, gathered on every rank."""
    mesh = sm.mesh
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim, 0)
    c2v = mesh.topology.connectivity(tdim, 0)
    cells = sm.cells(body)
    local = np.unique(np.concatenate([c2v.links(c) for c in cells])) if len(cells) else []
    glob = mesh.topology.index_map(0).local_to_global(np.asarray(local, dtype=np.int32))
    return np.unique(np.concatenate(mesh.comm.allgather(glob)))


# --------------------------------------------------------------------------------------------
# tests
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("key", list(SCENES))
def test_groups_named_and_nonempty(key: str) -> None:
    sm = scene(key)
    expected = sorted(exact_measures(key))  # same order on every rank (collectives below)
    assert sorted(sm.tags) == expected
    assert len(set(sm.tags.values())) == len(sm.tags)  # unambiguous values
    for name in expected:
        assert owned_count(sm, name) > 0, name
    # every cell belongs to exactly one body
    slave, master = SCENES[key][2]
    n_cells = sm.mesh.topology.index_map(sm.mesh.topology.dim).size_global
    assert owned_count(sm, slave) + owned_count(sm, master) == n_cells


@pytest.mark.parametrize("key", list(SCENES))
def test_measures_match_geometry(key: str, verification) -> None:
    """Verification: the lengths, areas and volumes of every group are the exact ones,
    to round-off where the group is flat, to the chord error of the mesh's degree where it
    is curved."""
    sm = scene(key)
    gdim, order = sm.mesh.geometry.dim, sm.mesh.geometry.cmaps[0].degree
    errors = {False: {}, True: {}}
    for name, (value, curved) in exact_measures(key).items():
        errors[curved][name] = abs(measure(sm, name) / value - 1.0)
    case = f"scene mesh {key} (geometry degree {order})"
    flat = max(errors[False].values())
    quantity = "max relative error of the flat groups' measures"
    verification(case, quantity, flat, 0.0, FLAT, CLOSED_FORM)
    assert flat <= FLAT, errors[False]
    if errors[True]:
        tol = CURVED[gdim, order]
        quantity = "max relative error of the curved groups' measures"
        verification(case, quantity, max(errors[True].values()), 0.0, tol, CLOSED_FORM)
        assert max(errors[True].values()) <= tol, errors[True]


@pytest.mark.parametrize("key", list(SCENES))
def test_bodies_share_no_vertex(key: str) -> None:
    sm = scene(key)
    slave, master = SCENES[key][2]
    v_slave, v_master = body_vertices(sm, slave), body_vertices(sm, master)
    assert len(v_slave) > 0 and len(v_master) > 0
    assert len(np.intersect1d(v_slave, v_master)) == 0
    assert len(v_slave) + len(v_master) == sm.mesh.topology.index_map(0).size_global


@pytest.mark.parametrize("key", [k for k in SCENES if SCENES[k][1].get("gap", 0.0) > 0.0])
def test_gap_separates_contact_surfaces(key: str) -> None:
    sm = scene(key)
    gap = SCENES[key][1]["gap"]
    xs, xm = (facet_nodes(sm, name) for name in contact_names(key))
    distance = np.linalg.norm(xs[:, None, :] - xm[None, :, :], axis=2).min()
    # the nearest nodes are the gap apart to round-off, or a little more where no node sits
    # at the point of closest approach (4.2% on the crossed cylinders)
    assert gap * (1.0 - 1e-13) <= distance < 1.1 * gap


@pytest.mark.parametrize("key", ["patch_2d", "patch_2d_quad", "patch_3d", "patch_3d_hex"])
def test_patch_interfaces_do_not_match(key: str) -> None:
    sm = scene(key)
    gdim = sm.mesh.geometry.dim
    xs, xm = (facet_nodes(sm, name)[:, : gdim - 1] for name in contact_names(key))
    assert len(xs) != len(xm)

    # the in-plane coordinates of the interior nodes of the two contact faces are disjoint
    def interior(x: npt.NDArray[np.float64]) -> set[tuple[float, ...]]:
        inside = np.all((x > 1e-10) & (x < 1.0 - 1e-10), axis=1)
        return {tuple(p) for p in np.round(x[inside], 10)}

    assert interior(xs) and interior(xm)
    assert not interior(xs) & interior(xm)


def test_patch_2d_divisions() -> None:
    sm = scene("patch_2d")
    xs, xm = (np.sort(facet_nodes(sm, name)[:, 0]) for name in contact_names("patch_2d"))
    # gmsh places the nodes of a curve by its parametrisation, to 1.8e-12 measured
    np.testing.assert_allclose(xs, np.linspace(0.0, 1.0, 11), rtol=0, atol=5e-12)
    np.testing.assert_allclose(xm, np.linspace(0.0, 1.0, 8), rtol=0, atol=5e-12)


@pytest.mark.parametrize("key", ["hertz_2d", "curved_2d", "hertz_2d_p2_gap"])
def test_contact_nodes_on_geometry(key: str, verification) -> None:
    """Verification: the nodes of the contact curves lie on the exact curves (the lower
    half of the cylinder's circle, the block's top line or circle) to round-off."""
    sm = scene(key)
    gap = SCENES[key][1].get("gap", 0.0)
    x = facet_nodes(sm, "cylinder_contact")
    errors = [np.abs(np.hypot(x[:, 0], x[:, 1] - (1.0 + gap)) - 1.0).max()]
    assert np.all(x[:, 1] <= 1.0 + gap + ON_CIRCLE)
    x = facet_nodes(sm, "block_contact")
    if key.startswith("hertz"):
        errors.append(np.abs(x[:, 1]).max())
    else:
        errors.append(np.abs(np.hypot(x[:, 0], x[:, 1] + 3.0) - 3.0).max())
    case = f"scene mesh {key} (geometry degree {sm.mesh.geometry.cmaps[0].degree})"
    quantity = "max distance of the contact nodes from the exact curves"
    verification(case, quantity, max(errors), 0.0, ON_CIRCLE, CLOSED_FORM)
    assert max(errors) <= ON_CIRCLE


def test_hertz_refinement_near_contact() -> None:
    sm = scene("hertz_2d")  # h_contact = 0.02, master_ratio = 1.3, h_far = 0.2
    for name, h in (("cylinder_contact", 0.02), ("block_contact", 0.026)):
        x = facet_nodes(sm, name)
        x = x[np.argsort(x[:, 0])]  # x is monotone along both contact curves
        length = np.linalg.norm(np.diff(x, axis=0), axis=1)
        middle = np.linalg.norm(0.5 * (x[1:] + x[:-1]), axis=1)
        assert np.allclose(length[middle < 0.25], h, rtol=0.05), name
        assert length.max() > 5.0 * h


def test_second_order_geometry() -> None:
    sm = scene("hertz_2d_p2_gap")
    assert sm.mesh.geometry.cmaps[0].degree == 2
    # midside nodes lie on the arc, so there are twice as many nodes as segments, plus one
    x = facet_nodes(sm, "cylinder_contact")
    n_segments = owned_count(sm, "cylinder_contact")
    assert len(x) == 2 * n_segments + 1


def test_cylinders_contact_is_curved_both_ways(verification) -> None:
    sm = scene("cylinders_3d")
    xs, xm = (facet_nodes(sm, name) for name in contact_names("cylinders_3d"))
    # upper: x^2 + (z - R)^2 = R^2; lower: y^2 + (z + R2)^2 = R2^2
    error = max(
        np.abs(np.hypot(xs[:, 0], xs[:, 2] - 1.0) - 1.0).max(),
        np.abs(np.hypot(xm[:, 1], xm[:, 2] + 3.0) - 3.0).max(),
    )
    case = "scene mesh cylinders_3d (geometry degree 1)"
    quantity = "max distance of the contact nodes from the exact cylinders"
    verification(case, quantity, error, 0.0, ON_CIRCLE, CLOSED_FORM)
    assert error <= ON_CIRCLE
    assert np.ptp(xs[:, 2]) > 0.5 and np.ptp(xm[:, 2]) > 0.05
    n_cells = sm.mesh.topology.index_map(3).size_global
    assert n_cells < 5000


def test_msh_file_written(tmp_path: Path) -> None:
    path = COMM.bcast(tmp_path / "meshes" / "patch.msh" if COMM.rank == 0 else None, root=0)
    sm = geometries.patch_2d(msh_file=path)
    assert owned_count(sm, "upper") > 0
    exists = COMM.bcast(path.exists() and path.stat().st_size > 0 if COMM.rank == 0 else None)
    assert exists


def test_gmsh_state_restored() -> None:
    was_initialised = gmsh.isInitialized()
    if not was_initialised:
        geometries.patch_2d()
        assert not gmsh.isInitialized()
        gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("user_model")
        gmsh.option.setNumber("Mesh.Algorithm", 5)
        geometries.patch_2d()
        assert gmsh.isInitialized()
        assert gmsh.model.getCurrent() == "user_model"
        assert gmsh.option.getNumber("Mesh.Algorithm") == 5
    finally:
        if not was_initialised:
            gmsh.finalize()


@pytest.mark.parametrize(
    ("generator", "kwargs"),
    [
        (geometries.hertz_2d, {"order": 3}),
        (geometries.hertz_2d, {"gap": -0.1}),
        (geometries.hertz_2d, {"h_contact": 0.0}),
        (geometries.curved_2d, {"lower_radius": 1.5}),  # width / 2 > lower radius
        (geometries.patch_2d, {"cell": "hexahedron"}),
        (geometries.patch_3d, {"cell": "quadrilateral"}),
        (geometries.cylinders_3d, {"block": (2.0, 8.0, 0.5)}),
        (geometries.cylinders_3d, {"lower_radius": -3.0}),
    ],
)
def test_invalid_input_raises_on_every_rank(generator, kwargs) -> None:
    with pytest.raises(ValueError):
        generator(**kwargs)
