"""Blocks as sums of forms compiled apart (``contact_ufl.assembly``): the same vectors and
matrices as DOLFINx's blocked assembly of the summed forms, and no contact data packed on the
bulk's cells."""

import dolfinx
import dolfinx.fem.petsc as fem_petsc
import numpy as np
import pytest
import scipy.sparse
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contact_ufl import assembly
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes

#: The bound of a sum assembled in another order, relative to the size of the result:
#: round-off (measured 2e-17 on the vector, the matrices equal).
ROUND_OFF = 1e-15
#: the scene of :func:`two_fields`
TWO_FIELDS = "a P2 vector field on the unit square and a P1 multiplier on its boundary"


@pytest.fixture(scope="module")
def two_fields():
    """A vector field on a mesh and a scalar field on its boundary, with a cell part and a
    boundary part in the first block, coupled on the boundary (as displacements and a
    multiplier on the slave submesh)."""
    mesh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 6, 5)
    mesh.topology.create_connectivity(1, 2)
    facets = dolfinx.mesh.exterior_facet_indices(mesh.topology)
    submesh, entity_map = dolfinx.mesh.create_submesh(mesh, 1, facets)[:2]
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 2, (2,)))
    Q = dolfinx.fem.functionspace(submesh, ("Lagrange", 1))
    u, lam = dolfinx.fem.Function(V), dolfinx.fem.Function(Q)
    u.interpolate(lambda x: np.stack([np.sin(3 * x[0]) * x[1], x[0] ** 2 + x[1]]))
    lam.interpolate(lambda x: 1.0 + x[0] - 2 * x[1] ** 2)
    v, q = ufl.TestFunction(V), ufl.TestFunction(Q)
    tags = dolfinx.mesh.meshtags(mesh, 1, facets, np.full(len(facets), 3, dtype=np.int32))
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=tags, subdomain_id=3)
    x = ufl.SpatialCoordinate(mesh)
    F_cell = ufl.inner(ufl.grad(u) + ufl.grad(u).T * (1 + u[0] ** 2), ufl.grad(v)) * ufl.dx
    F_facet = lam * ufl.dot(u + x, v) * ds
    G = (lam - ufl.dot(u, u)) * q * ds
    fields = [u, lam]

    def derivative(F, f):
        return ufl.derivative(F, f, ufl.TrialFunction(f.function_space))

    parts = [[F_cell, F_facet], [G]]
    blocks = [[[derivative(P, f) for P in row] for f in fields] for row in parts]
    blocks[1][1] = [derivative(G, lam)]
    blocks[0][1] = [derivative(F_facet, lam)]
    maps = [entity_map]
    whole_residual = dolfinx.fem.form([F_cell + F_facet, G], entity_maps=maps)
    whole_tangent = [[sum(b[1:], b[0]) for b in row] for row in blocks]
    whole_tangent = dolfinx.fem.form(whole_tangent, entity_maps=maps)
    return (
        dolfinx.fem.form(parts, entity_maps=maps),
        dolfinx.fem.form(blocks, entity_maps=maps),
        whole_residual,
        whole_tangent,
        [V, Q],
    )


def test_parts_add_up_to_the_summed_blocks(two_fields, verification):
    """Consistency: the residual and the tangent assembled part by part are DOLFINx's
    blocked assembly of the summed forms, to round-off."""
    parts, blocks, whole_residual, whole_tangent, spaces = two_fields
    b = fem_petsc.create_vector(spaces, kind="mpi")
    b.set(0.0)
    assembly.assemble_vector(b, parts)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    reference = fem_petsc.assemble_vector(whole_residual, kind="mpi")
    reference.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    assert reference.norm() > 1.0
    local = np.abs(b.array_r - reference.array_r).max(initial=0.0)
    error = MPI.COMM_WORLD.allreduce(local, MPI.MAX) / reference.norm()
    source = "DOLFINx's blocked assembly of the summed forms"
    quantity = "max |b - b_DOLFINx| / |b_DOLFINx| (residual)"
    verification(TWO_FIELDS, quantity, error, 0.0, ROUND_OFF, source, kind="consistency")
    assert error <= ROUND_OFF

    A = assembly.create_matrix(blocks)
    assembly.assemble_matrix(A, blocks)
    A.assemble()
    K = fem_petsc.assemble_matrix(whole_tangent, kind="mpi")
    K.assemble()
    assert K.norm() > 1.0
    K.axpy(-1.0, A, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    error = K.norm() / A.norm()
    quantity = "|K_DOLFINx - K| / |K| (tangent, Frobenius)"
    verification(TWO_FIELDS, quantity, error, 0.0, ROUND_OFF, source, kind="consistency")
    assert error <= ROUND_OFF


def test_a_part_outside_the_first_parts_cells_is_refused(two_fields):
    """The sparsity of a block is its first part's: a later part over cells the first does
    not cover is refused (DOLFINx's matrices would drop its values silently)."""
    _, blocks, *_ = two_fields
    swapped = [[list(reversed(blocks[0][0])), blocks[0][1]], [blocks[1][0], blocks[1][1]]]
    with pytest.raises(ValueError, match=r"block \(0, 0\): a part integrates over cells"):
        assembly.create_matrix(swapped)


def test_the_bulk_cells_pack_no_contact_data():
    """The cell integrals of the displacement rows pack the bulk's coefficients only, not
    the contact's point data on the slave surface (zeros on every cell), and the contact
    terms are a part of their own."""
    hertz = scenes.hertz_2d(h_contact=0.05, depth=0.01)
    problem = ContactProblem(hertz.scene, verbose=False)
    bulk = problem.bulks[0]
    alone = dolfinx.fem.form(bulk.residual(ufl.TestFunction(bulk.V)))
    width = {k: c.shape[1] for k, c in dolfinx.fem.pack_coefficients(alone).items()}
    first, *contact = problem.residual_form[0]
    packed = dolfinx.fem.pack_coefficients(first)
    assert {k: c.shape[1] for k, c in packed.items()} == width
    assert len(contact) == 1
    assert set(contact[0].integral_types) == {dolfinx.fem.IntegralType.exterior_facet}


def _move_off(operator) -> None:
    """Set the operator's state to its unknowns moved by up to 1e-3 (another state)."""
    x = operator.x.copy()
    x.array[:] += 1e-3 * np.sin(np.arange(len(x.array)))
    operator.set_state(x)


@pytest.mark.parametrize(
    "make, fixed, case",
    [
        pytest.param(
            scenes.hertz_3d,
            1,
            "Hertz 3D, linear-elastic bulk, depth 0.01",
            marks=pytest.mark.serial,  # 2 ranks: the 2D scene (the same assembly)
        ),
        (scenes.hertz_2d, 0, "Hertz 2D, Neo-Hookean bulk, depth 0.01"),
    ],
    ids=["hertz_3d", "hertz_2d"],
)
def test_a_fixed_bulk_stiffness_is_assembled_once_a_step(make, fixed, case, verification):
    """A part that depends on no coefficient or constant (the linear-elastic bulk of 3D
    Hertz; not the Neo-Hookean one of 2D Hertz, nor a contact term) is kept in ``B`` and
    added to every tangent of a load step: the tangent between the unknowns equals the one
    assembled part by part, at a state that is not the one ``B`` was assembled at, to
    round-off (consistency; measured equal)."""
    problem = ContactProblem(make(depth=0.01).scene, verbose=False)
    operator = problem.operator
    constant, varying = assembly.split_constant(operator._unknown_forms)
    assert sum(len(parts) for row in constant for parts in row) == fixed
    assert (operator._fixed_blocks is not None) == bool(fixed)
    assert all(
        p._cpp_object.coefficients or p._cpp_object.constants
        for row in varying
        for parts in row
        for p in parts
    )
    problem.solve(num_steps=1)  # B made on the step's first tangent, then reused
    _move_off(operator)
    J = operator.matrix.duplicate()
    operator._assemble_unknown_blocks(J)
    expected = operator.matrix.duplicate()
    expected.zeroEntries()
    assembly.assemble_matrix(expected, operator._unknown_forms)
    expected.assemble()
    (rows, columns, values), (rows_e, columns_e, values_e) = (
        J.getValuesCSR(),
        expected.getValuesCSR(),
    )
    np.testing.assert_array_equal(rows, rows_e)
    np.testing.assert_array_equal(columns, columns_e)  # the same pattern: duplicates
    comm = MPI.COMM_WORLD
    scale = comm.allreduce(np.abs(values_e).max(initial=0.0), MPI.MAX)
    assert scale > 0
    error = comm.allreduce(np.abs(values - values_e).max(initial=0.0), MPI.MAX) / scale
    quantity = "max |J - J_part by part| / max |J_part by part| (tangent of the unknowns)"
    source = "the tangent assembled part by part at the same state"
    verification(case, quantity, error, 0.0, ROUND_OFF, source, kind="consistency")
    assert error <= ROUND_OFF


@pytest.mark.parametrize("make", [scenes.hertz_3d, scenes.hertz_2d])
def test_the_gathered_blocks_drop_only_zeros_between_points(make):
    """The gathered blocks' matrix ``K`` holds no coupling between two points of the
    master-node data (a quadrature space) and assembles to DOLFINx's full pattern's matrix
    exactly: what it drops is zero."""
    operator = ContactProblem(make(depth=0.01).scene, verbose=False).operator
    _move_off(operator)
    full = assembly.create_matrix(operator._gathered_forms)
    matrices = []
    for K in (full, operator._gathered_tangent):
        K.zeroEntries()
        assembly.assemble_matrix(K, operator._gathered_forms)
        K.assemble()
        indptr, columns, values = K.getValuesCSR()
        shape = (len(indptr) - 1, K.getSize()[1])
        matrices.append(scipy.sparse.csr_array((values, columns, indptr), shape=shape))
    dense_pattern, kept = matrices
    assert MPI.COMM_WORLD.allreduce(kept.nnz, MPI.SUM) < MPI.COMM_WORLD.allreduce(
        dense_pattern.nnz, MPI.SUM
    )
    comm = MPI.COMM_WORLD
    assert comm.allreduce(abs(dense_pattern).max(), MPI.MAX) > 0
    assert comm.allreduce(abs(dense_pattern - kept).max(), MPI.MAX) == 0.0
