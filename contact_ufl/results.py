"""Results of a solved problem: contact tractions at the slave points, resultants."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import basix
import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contact_ufl import jit, keysets
from contact_ufl.errors import ContactInputError

#: The abscissae of a profile along the slave surface (:meth:`ContactSamples.abscissa`).
ALONG = ("x", "arc length", "current arc length")


@dataclass
class ContactSamples:
    """Contact quantities at the slave quadrature points of all ranks.

    The arrays hold the points of rank 0, then those of rank 1, ... (each rank's facet by
    facet): :meth:`ordered` sorts them along the slave surface.

    Attributes
    ----------
    x
        Current positions ``(n, gdim)``.
    lambda_N
        Normal multiplier (nominal pressure, per unit reference area).
    pressure
        Cauchy contact pressure (per unit current area): ``lambda_N dA / da``.
    gap
        Proximity g (> 0 penetration; -inf where no master facet was found).
    in_contact
        Whether the point is in contact: the formulation's active set, where the bracket of
        the normal traction ``t_N = <lambda_N + eps_N g>`` is positive (within the
        round-off band of the bracket, ``eps_N`` times ``1e-12`` of the surfaces' size;
        False where no master facet was found). Open points next to a contact edge carry a
        small multiplier of either sign (the tail of the continuous multiplier beyond the
        edge), so ``lambda_N > 0`` is not a test of contact.
    stick
        (friction) Whether the point is in contact and sticks: its trial tangential traction
        ``q = lambda_T + eps_T s_T`` (``s_T`` the slip increment of the step) lies in the
        Coulomb disc, ``|q| <= mu t_N`` (within the round-off band ``eps_T`` times ``1e-12``
        of the surfaces' size), the rule of the formulation's disc projection; the points
        in contact that do not stick slip (:attr:`slip`). ``None`` without friction.
    X
        Reference positions ``(n, gdim)``.
    arc_length
        (2D) Distance from the start of the point's curve of the slave surface, along the
        reference (undeformed) surface: along its straight facets (exact for a degree-1
        geometry; through the vertices of a curved, degree-2 facet). ``None`` in 3D.
    arc_length_current
        (2D) The same along the current (deformed) surface: each facet's length is the
        integral of ``da/dA`` over it; a point's place on its facet is its reference place,
        scaled (exact for a degree-1 displacement, whose facets stay straight). ``None`` in
        3D.
    curve
        (2D) Index of the connected curve of the slave surface the point is on, in the order
        of their starting points. An open curve starts at its end of smallest x (of smallest
        y where two have the same x), a closed one at its vertex of smallest x (then y) and
        runs counter-clockwise. A curve with a branch (a vertex of more than two facets) has
        index -1 and NaN arc lengths. ``None`` in 3D.
    """

    x: np.ndarray
    lambda_N: np.ndarray
    pressure: np.ndarray
    gap: np.ndarray
    in_contact: np.ndarray | None = None
    stick: np.ndarray | None = None
    X: np.ndarray | None = None
    arc_length: np.ndarray | None = None
    arc_length_current: np.ndarray | None = None
    curve: np.ndarray | None = None

    @property
    def slip(self) -> np.ndarray | None:
        """(friction) Whether the point is in contact and slips (``None`` without friction)."""
        if self.stick is None or self.in_contact is None:
            return None
        return self.in_contact & ~self.stick

    def abscissa(self, along: str = "x") -> np.ndarray:
        """The points' abscissa of a profile: ``"x"``, the first coordinate of the current
        position; ``"arc length"``, :attr:`arc_length` (reference); ``"current arc
        length"``, :attr:`arc_length_current`."""
        if along not in ALONG:
            raise ValueError(f"along must be one of {list(ALONG)}, got {along!r}")
        if along == "x":
            return self.x[:, 0]
        values = self.arc_length if along == "arc length" else self.arc_length_current
        if values is None:
            raise ValueError(f"along={along!r} needs a 2D slave surface (a curve)")
        return values

    def order(self, along: str = "arc length") -> np.ndarray:
        """The indices that sort the points along the surface: by curve, then arc length
        (``along`` one of :data:`ALONG`; ``"x"``: by x)."""
        s = self.abscissa(along)
        if along == "x":
            return np.argsort(s, kind="stable")
        return np.lexsort((s, self.curve))

    def ordered(self, along: str = "arc length") -> ContactSamples:
        """These samples sorted along the surface (:meth:`order`)."""
        index = self.order(along)
        values = {
            f.name: None if getattr(self, f.name) is None else getattr(self, f.name)[index]
            for f in dataclasses.fields(self)
        }
        return ContactSamples(**values)


def contact_samples(problem, pair: int = 0, recovered: bool = False) -> ContactSamples:
    """Gather the contact quantities of contact pair ``pair`` on every rank (collective).

    ``recovered``: ``lambda_N`` and ``pressure`` are those of :func:`recovered_pressure`
    (the bulk's traction, smooth on non-matching meshes) instead of the multipliers'.

    The in-contact flag is the formulation's active set (``lambda_N + eps_N g > 0``), the
    stick flag (friction) its Coulomb disc (``|lambda_T + eps_T s_T| <= mu t_N``); see
    :class:`ContactSamples`. Call it after a solve (or in a step's callback): with friction,
    the slip is then that of the converged step. Before the first contact search (before a
    solve) no point has a master facet: every gap is ``-inf`` and every point open.
    """
    c = problem.contacts[pair]
    comm = problem.comm
    gdim = c.gdim
    x = c.slave.positions(c.u).reshape(-1, gdim)
    if recovered:
        lam = c.slave.p1_at_points(recovered_pressure(problem, pair))
    else:
        lam = c.multiplier_at_points()
    ratio = c.slave.area_ratio(c.u).ravel()
    if c.projection is None:  # not searched yet
        gap, active = np.full(len(lam), -np.inf), np.zeros(len(lam), dtype=bool)
        stick = active.copy() if c.friction else None
    else:
        gap = np.where(c.projection.facet >= 0, c.projection.gap, -np.inf)
        active = c.active()
        stick = c.stick() if c.friction else None

    def gather(a):
        return np.concatenate(comm.allgather(a))

    arcs = _arc_lengths(c, comm, ratio)
    return ContactSamples(
        gather(x).reshape(-1, gdim),
        gather(lam),
        gather(lam / ratio),
        gather(gap),
        in_contact=gather(active),
        stick=None if stick is None else gather(stick),
        X=gather(c.slave.X.reshape(-1, gdim)).reshape(-1, gdim),
        arc_length=arcs[0],
        arc_length_current=arcs[1],
        curve=arcs[2],
    )


def _arc_lengths(c, comm, ratio: np.ndarray) -> tuple[np.ndarray | None, ...]:
    """The reference and current arc lengths and the curve index of the slave points of all
    ranks (order of :func:`contact_samples`), or three ``None`` if the slave surface is not
    a curve. Collective.

    The facets are chained through their vertices' input (mesh file) indices, which are
    the same on any number of ranks; a point's place on its facet is the projection of its
    reference position onto the facet's chord.
    """
    slave = c.slave
    if slave.submesh.topology.dim != 1:
        return None, None, None
    gdim = c.gdim
    mesh = slave.V.mesh
    nc, nq = slave.num_cells, slave.num_points
    keys = slave.vertex_keys[:, :2]
    inputs = mesh.geometry.input_global_indices
    by_input = np.argsort(inputs)
    nodes = by_input[np.searchsorted(inputs, keys.ravel(), sorter=by_input)]
    ends = mesh.geometry.x[nodes, :gdim].reshape(nc, 2, gdim)
    chord = ends[:, 1] - ends[:, 0]
    length = np.linalg.norm(chord, axis=1)
    X = slave.X.reshape(nc, nq, gdim)
    place = np.einsum("cqd,cd->cq", X - ends[:, None, 0], chord) / length[:, None] ** 2
    current = (slave.point_weights * ratio).reshape(nc, nq).sum(axis=1)
    parts = comm.allgather((keys, ends, length, current, place))
    keys, ends, length, current, place = (np.concatenate([p[k] for p in parts]) for k in range(5))
    return _walk_curves(keys, ends, length, current, place)


def _walk_curves(
    keys: np.ndarray,
    ends: np.ndarray,
    length: np.ndarray,
    current: np.ndarray,
    place: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Chain the segments (vertex ``keys`` ``(F, 2)`` at ``ends`` ``(F, 2, gdim)``, reference
    and current lengths, the places ``(F, nq)`` of their points from the first end, in
    [0, 1]) into curves; the points' reference and current arc lengths and curve indices
    (the rules of :class:`ContactSamples`), flattened facet by facet."""
    from scipy.sparse import coo_array
    from scipy.sparse.csgraph import connected_components

    nf, nq = place.shape
    vertices, edges = np.unique(keys.ravel(), return_inverse=True)
    edges = edges.reshape(nf, 2)
    coords = np.zeros((len(vertices), ends.shape[2]))
    coords[edges.ravel()] = ends.reshape(-1, ends.shape[2])
    degree = np.bincount(edges.ravel(), minlength=len(vertices))
    graph = coo_array((np.ones(nf), (edges[:, 0], edges[:, 1])), shape=(len(vertices),) * 2)
    _, component = connected_components(graph, directed=False)
    incident: dict[int, list[int]] = {}
    for f, (a, b) in enumerate(edges):
        incident.setdefault(int(a), []).append(f)
        incident.setdefault(int(b), []).append(f)

    s_ref = np.full((nf, nq), np.nan)
    s_cur = np.full((nf, nq), np.nan)
    curve = np.full((nf, nq), -1, dtype=np.int64)
    starts = []
    for k in np.unique(component[edges[:, 0]]):
        members = np.flatnonzero(component == k)
        if degree[members].max() > 2:
            continue  # a branch: no arc length
        ends_ = members[degree[members] == 1]
        candidates = ends_ if len(ends_) else members
        start = candidates[np.lexsort(coords[candidates].T[::-1])[0]]
        chain = _chain(int(start), edges, incident)
        if not len(ends_) and _signed_area(coords, edges, chain) < 0.0:
            chain = [(f, not forward) for f, forward in reversed(chain)]
        starts.append((coords[start], chain))
    starts.sort(key=lambda item: tuple(item[0]))
    for index, (_, chain) in enumerate(starts):
        facets = np.array([f for f, _ in chain])
        forward = np.array([fw for _, fw in chain])
        along = np.where(forward[:, None], place[facets], 1.0 - place[facets])
        for s, lengths in ((s_ref, length), (s_cur, current)):
            before = np.concatenate([[0.0], np.cumsum(lengths[facets])[:-1]])
            s[facets] = before[:, None] + along * lengths[facets, None]
        curve[facets] = index
    return s_ref.ravel(), s_cur.ravel(), curve.ravel()


def _chain(start: int, edges: np.ndarray, incident: dict[int, list[int]]) -> list[tuple]:
    """The facets of a curve in order from the vertex ``start``: ``(facet, forward)``,
    ``forward`` when the facet runs from its first end to its second."""
    chain, vertex, previous = [], start, -1
    while True:
        following = [f for f in incident[vertex] if f != previous]
        if not following or (chain and following[0] == chain[0][0]):
            return chain  # the other end of an open curve, or back at the start
        f = following[0]
        forward = edges[f, 0] == vertex
        chain.append((f, bool(forward)))
        vertex, previous = int(edges[f, 1] if forward else edges[f, 0]), f


def _signed_area(coords: np.ndarray, edges: np.ndarray, chain: list[tuple]) -> float:
    """Twice the signed area enclosed by the closed chain (> 0: counter-clockwise)."""
    first = np.array([edges[f, 0] if fw else edges[f, 1] for f, fw in chain])
    p, q = coords[first], coords[np.roll(first, -1)]
    return float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def slave_body(problem, pair: int = 0):
    """The body that owns the slave facets of contact pair ``pair``."""
    c = problem.contacts[pair]
    bulk = problem.bulk_of(c)
    tags = bulk.domain.cell_tags
    order = np.argsort(tags.indices)
    pos = np.searchsorted(tags.indices, c.slave.parent_cells, sorter=order)
    local = set(tags.values[order[pos]].tolist()) if len(pos) else set()
    found = problem.comm.allreduce(local, MPI.BOR)
    bodies = [b for b in bulk.bodies if b.tag in found]
    if len(bodies) != 1:
        raise ValueError(f"slave facets of pair {pair} belong to {len(bodies)} bodies")
    return bodies[0]


def traction_mismatch(problem, pair: int = 0) -> float:
    """Relative L2 distance on the slave surface between the bulk traction ``Pi N`` and the
    contact traction of the multipliers ``lambda_N nu`` (property (c) of the formulation)."""
    c = problem.contacts[pair]
    body = slave_body(problem, pair)
    bulk = problem.bulk_of(c)
    if body.tag in bulk.histories:
        # its stress lives at the cell quadrature points, not on the facets
        raise NotImplementedError(
            f"traction_mismatch needs a hyperelastic slave body; body {body.tag} is elastoplastic"
        )
    Pi = bulk.first_piola(body)
    N = ufl.FacetNormal(bulk.V.mesh)
    diff = Pi * N - c.lambda_N * c.kinematics.nu
    forms = [ufl.dot(diff, diff) * c.ds, c.lambda_N**2 * c.ds]
    values = [
        problem.comm.allreduce(
            dolfinx.fem.assemble_scalar(jit.form(f, entity_maps=[c.slave.entity_map])),
            MPI.SUM,
        )
        for f in forms
    ]
    return float(np.sqrt(values[0] / values[1]))


def body_resultants(problem, vector) -> dict[int, np.ndarray]:
    """Sum of the displacement components of a vector over the dofs of each body.

    ``vector`` is a vector of the unknowns (for instance a residual); the result maps each
    body's cell tag to its resultant ``(gdim,)`` (bodies of all meshes; their tags must then
    differ).
    """
    out = {}
    for k, bulk in enumerate(problem.bulks):
        V = bulk.V
        owned = V.dofmap.index_map.size_local
        values = vector.array[problem.block_rows(k)].reshape(-1, problem.gdim)
        for body in bulk.bodies:
            if body.tag in out:
                raise ValueError(f"two bodies have the cell tag {body.tag} (on two meshes)")
            blocks = keysets.unique(V.dofmap.list[bulk.domain.cell_tags.find(body.tag)])
            blocks = blocks[blocks < owned]
            local = values[blocks].sum(axis=0) if len(blocks) else np.zeros(problem.gdim)
            out[body.tag] = problem.comm.allreduce(local, MPI.SUM)
    return out


def weak_contact_law(problem, pair: int = 0) -> tuple[float, float]:
    """The contact law as the multiplier equation imposes it, node by node.

    For a multiplier node whose whole support is in contact the equation reads
    ``int g phi_i = 0`` (the gap is closed in the weak sense); where the whole support is
    open it reads ``int lambda_N phi_i = 0``. Returns the largest ``|int g phi_i| / int
    phi_i`` over the first kind of nodes and ``|int lambda_N phi_i| / int phi_i`` over the
    second (both zero up to solver tolerance).
    """
    c = problem.contacts[pair]
    slave = c.slave
    mu = ufl.TestFunction(slave.P1)
    owned = slave.P1.dofmap.index_map.size_local

    def nodal(expr):
        form = jit.form(expr * mu * c.ds, entity_maps=[c.slave.entity_map])
        return slave.assemble_nodal(form, slave.P1)[:owned]

    active = c.active()
    opened, touched = slave.count_at_nodes(~active), slave.count_at_nodes(active)
    mass = slave.nodal_mass
    closed = (opened == 0) & (touched > 0)
    open_ = (touched == 0) & (opened > 0)
    gap = np.abs(nodal(c.kinematics.gap)[closed] / mass[closed])
    lam = np.abs(nodal(c.lambda_N)[open_] / mass[open_])
    comm = problem.comm
    return (
        comm.allreduce(gap.max(initial=0.0), MPI.MAX),
        comm.allreduce(lam.max(initial=0.0), MPI.MAX),
    )


def stick_zone_half_width(problem, pair: int = 0) -> float:
    """Half-width of the stick zone of a 2D frictional pair at its last converged step.

    Its edges are placed half-way between the outermost sticking quadrature point and the
    next slipping one on either side (the zone is taken along x).
    """
    c = problem.contacts[pair]
    x = c.slave.positions(c.u).reshape(-1, c.gdim)[:, 0]
    active = c.active()
    stick = c.friction.last_stick & active
    slip = ~c.friction.last_stick & active
    comm = problem.comm
    xs = np.concatenate(comm.allgather(x[stick]))
    xl = np.concatenate(comm.allgather(x[slip]))
    if len(xs) == 0:
        return 0.0
    right, left = xs.max(), xs.min()
    beyond_right, beyond_left = xl[xl > right], xl[xl < left]
    if len(beyond_right):
        right = 0.5 * (right + beyond_right.min())
    if len(beyond_left):
        left = 0.5 * (left + beyond_left.max())
    return 0.5 * (right - left)


def _facet_integral(bulk, expr, tag: int) -> np.ndarray:
    """``int_{tag} expr dS_o`` (a vector expression) over the mesh of ``bulk``, summed over
    all ranks."""
    values = [
        dolfinx.fem.assemble_scalar(jit.form(expr[i] * bulk.ds(tag)))
        for i in range(expr.ufl_shape[0])
    ]
    return bulk.comm.allreduce(np.asarray(values), MPI.SUM)


def contact_force_parts(problem, pair: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The contact force on the slave body of pair ``pair``, split into its normal-pressure
    part ``int t_N nu dS_o`` and its frictional part ``-int P(q) dS_o`` (zero without
    friction), summed over all ranks.

    On a curved contact the normal part has a component along the sliding direction (the
    body in front of an indenter pushes back on it), so the global ratio of tangential to
    normal force exceeds mu even where every point slides with ``|lambda_T| = mu lambda_N``.
    Call it after a step (or from its callback): the slip is that of the converged step.

    Returns
    -------
    normal, frictional
        The two parts, ``(gdim,)`` each.
    """
    c = problem.contacts[pair]
    frictional = c.integrate("friction") if c.friction else np.zeros(c.gdim)
    return c.integrate("normal"), frictional


def stored_energy(problem) -> float:
    """Elastic energy ``sum_b int psi_b(F) dV`` of all bodies (reference volume); the
    hyperelastic bodies only (an elastoplastic one raises)."""
    return problem.stored_energy()


def frictional_dissipation(problem, pair: int = 0) -> float:
    """Energy dissipated by friction in the last converged step, ``int P(q) . s_T dS_o``
    (the frictional traction times the slip increment; >= 0 by the Coulomb law). Valid
    after the step and in its callback, before the next step moves the slip reference."""
    c = problem.contacts[pair]
    return float(c.integrate("dissipation")[0]) if c.friction else 0.0


def lowest_displacement(problem, tag: int | str, component: int = -1) -> float:
    """Smallest component of the displacement over the nodes of some facets, all ranks.

    Parameters
    ----------
    problem
        The contact problem.
    tag
        Facet tag, or the name of its physical group.
    component
        Displacement component (default: the last, vertical in 2D).

    Returns
    -------
    float
        The smallest value: e.g. the depth of an imprint is minus that of the indented
        surface.
    """
    bulk, tag = problem.locate(tag)
    mesh = bulk.V.mesh
    facets = bulk.domain.facet_tags.find(tag)
    dofs = dolfinx.fem.locate_dofs_topological(bulk.V, mesh.topology.dim - 1, facets)
    values = bulk.u.x.array.reshape(-1, mesh.geometry.dim)[dofs, component]
    return problem.comm.allreduce(values.min(initial=np.inf), op=MPI.MIN)


def section_motion(problem, tag: int | str) -> tuple[np.ndarray, np.ndarray]:
    """Mean displacement and deformed unit normal of the facets ``tag`` (e.g. a beam's end;
    an integer or the name of a physical group).

    Returns ``(u_mean, n)`` with ``u_mean = int u dS_o / int dS_o`` and ``n`` the direction of
    the deformed area vector ``int J F^-T N dS_o`` (the section's rotation is the angle
    between ``n`` and the reference normal).
    """
    bulk, tag = problem.locate(tag)
    u = bulk.u
    mesh = bulk.V.mesh
    area = _facet_integral(bulk, ufl.as_vector([dolfinx.fem.Constant(mesh, 1.0)]), tag)[0]
    if not area > 0.0:
        raise ValueError(f"facet tag {tag} has no facet")
    F = ufl.Identity(len(u)) + ufl.grad(u)
    n = _facet_integral(bulk, ufl.cofac(F) * ufl.FacetNormal(mesh), tag)
    return _facet_integral(bulk, u, tag) / area, n / np.linalg.norm(n)


def equilibrium_error(problem, supports: list[str | int], obstacles: Sequence = ()) -> float:
    """Global equilibrium: ``|sum of support and obstacle reactions + resultant of the
    loads|``, relative to the scene's force scale, the largest of the loads' resultant and
    each support's and obstacle's reaction (a scene driven by prescribed displacements alone
    has no load). The contact forces between bodies are internal to the scene and cancel.

    ``supports`` are facet tags (or the names of their physical groups) that carry all
    prescribed displacements; ``obstacles`` the rigid obstacles of the scene's pairs (their
    reactions, :meth:`~contact_ufl.problem.ContactProblem.obstacle_reaction`, count like the
    supports'). Collective.
    """
    # reaction() is the residual without the prescribed-displacement equations on the
    # support dofs, internal minus external forces: the force of the support on the body
    # (all supports at once: a node on two of them, a corner, counts once)
    reactions = problem.reaction(list(supports))
    parts = [problem.reaction(tag) for tag in supports]
    parts += [problem.obstacle_reaction(o) for o in obstacles]
    reactions = reactions + sum(parts[len(supports) :], np.zeros(problem.gdim))
    load = problem.load_resultant()
    scale = max(np.linalg.norm(f) for f in [load, *parts])
    return float(np.linalg.norm(load + reactions) / scale) if scale > 0.0 else 0.0


@dataclass
class CoulombCheck:
    """Property (d) of the formulation for the frictional multipliers at the slave points.

    Attributes
    ----------
    excess
        ``max(|lambda_T| - mu lambda_N)`` over the points in contact, relative to
        ``max(mu lambda_N)``: <= 0 up to discretisation and solver tolerance.
    alignment
        Smallest cosine between the slip increment of the last step and ``lambda_T`` over
        the slipping points (1: slip along the tangential traction, ``V_T . T_T >= 0``).
    slip_excess
        ``max |mu lambda_N - |lambda_T||`` over the slipping points, relative to
        ``max(mu lambda_N)``: where a point slips the traction is on the cone.
    slipping, active
        Numbers of slipping points and of points in contact (all ranks).
    """

    excess: float
    alignment: float
    slip_excess: float
    slipping: int
    active: int


def coulomb_law(problem, pair: int = 0, floor: float = 0.0) -> CoulombCheck:
    """Check the Coulomb law on the multipliers of a frictional pair at its last converged
    step (after :meth:`~contact_ufl.problem.ContactProblem.solve`, or from its callback):
    the slip and the stick/slip state are those the step was solved with.

    The traction applied to the bodies, ``P(q)`` on the disc of radius ``mu t_N``, obeys the
    law at every point by construction; the P1 multipliers equal it weakly (property (c)),
    so pointwise they obey it up to the error of that projection. Where the traction is
    smooth that is small (4e-6 of ``max mu lambda_N`` on the beams); next to a traction
    singularity, such as the corners of a flat punch, the excess does not vanish under
    refinement (about 10% of ``max mu lambda_N`` at the pushed block's edges).
    At the edge of a contact zone that ends inside the slave surface, a point in contact
    (``lambda_N + eps_N g > 0``) can carry a multiplier ``lambda_N`` that is zero to the
    projection error, even slightly negative: there ``|lambda_T| <= mu lambda_N`` fails by
    that error and the direction of ``lambda_T`` is meaningless. ``floor`` leaves out the
    points with ``lambda_N <= floor * max(lambda_N)`` (default 0: every point in contact).
    """
    c = problem.contacts[pair]
    comm = problem.comm
    if c.friction is None:
        raise ValueError(f"contact pair {pair} is frictionless")
    friction = c.friction
    if not 0.0 <= floor < 1.0:
        raise ValueError(f"floor is a fraction of max(lambda_N) in [0, 1), got {floor}")
    lam_N = c.multiplier_at_points()
    active = c.active()
    if floor > 0.0:
        active &= lam_N > floor * comm.allreduce(lam_N[active].max(initial=0.0), MPI.MAX)
    lam_T = friction.tangential_multiplier_at_points()
    radius = float(friction.mu.value) * lam_N
    excess = np.linalg.norm(lam_T, axis=1) - radius
    scale = comm.allreduce(radius[active].max(initial=0.0), MPI.MAX)
    scale = scale if scale > 0.0 else 1.0  # no contact pressure: report absolute values
    slip = friction.last_slip
    slip_norm = np.linalg.norm(slip, axis=1)
    slip_scale = comm.allreduce(slip_norm[active].max(initial=0.0), MPI.MAX)
    slipping = active & ~friction.last_stick & (slip_norm > 1e-6 * slip_scale)
    lam_norm = np.linalg.norm(lam_T, axis=1)
    cos = np.einsum("pd,pd->p", slip, lam_T)[slipping] / (
        slip_norm[slipping] * np.where(lam_norm[slipping] > 0, lam_norm[slipping], np.inf)
    )
    return CoulombCheck(
        comm.allreduce(excess[active].max(initial=-np.inf), MPI.MAX) / scale,
        comm.allreduce(cos.min(initial=1.0), MPI.MIN),
        comm.allreduce(np.abs(excess[slipping]).max(initial=0.0), MPI.MAX) / scale,
        comm.allreduce(int(slipping.sum()), MPI.SUM),
        comm.allreduce(int(active.sum()), MPI.SUM),
    )


def inverted_cells(problem) -> int:
    """Number of cells (all ranks) in which ``det F < 0`` at one of the cell's vertices or
    its midpoint, at the current displacement: the elements a Newton iterate has turned
    inside out. A sample, not a bound (``det F`` of a quadratic displacement is not linear
    in the cell), cheap enough to be called at a failed step.
    """
    return problem.comm.allreduce(sum(int(_inverted(b).sum()) for b in problem.bulks))


def inverted_cell_centres(problem) -> np.ndarray:
    """Reference centres of the cells counted by :func:`inverted_cells`, ``(n, gdim)``, the
    same on all ranks."""
    centres = []
    for bulk in problem.bulks:
        mesh = bulk.V.mesh
        cells = np.flatnonzero(_inverted(bulk)).astype(np.int32)
        nodes = mesh.geometry.dofmaps[0][cells]
        centres.append(mesh.geometry.x[nodes, : problem.gdim].mean(axis=1))
    local = np.concatenate(centres) if centres else np.zeros((0, problem.gdim))
    return np.concatenate(problem.comm.allgather(local)).reshape(-1, problem.gdim)


def _inverted(bulk) -> np.ndarray:
    """Which owned cells of the mesh of ``bulk`` have ``det F <= 0`` (or not a number) at a
    sample point (none on a membrane, whose ``det F`` is not a volume ratio)."""
    from contact_ufl.loads import deformation_gradient

    mesh = bulk.V.mesh
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    if bulk.membrane:
        return np.zeros(owned, dtype=bool)
    vertices = basix.geometry(basix.CellType[mesh.topology.cell_type.name])
    points = np.vstack([vertices, vertices.mean(axis=0)])
    J = jit.expression(ufl.det(deformation_gradient(bulk.u)), points)
    values = J.eval(mesh, np.arange(owned, dtype=np.int32)).reshape(owned, len(points))
    return ~np.all(values > 0.0, axis=1)  # (NaN too: an iterate beyond the material's domain)


def recovered_pressure(problem, pair: int = 0) -> dolfinx.fem.Function:
    """The nominal contact pressure the slave body carries, recovered from its stress: the
    L2 projection of ``nu . P N`` onto the P1 space of the slave surface (collective).

    By property (c) of the formulation it is the multiplier ``lambda_N`` in the limit. On
    non-matching meshes the standard multipliers oscillate node to node about the pressure
    (their mass matrix amplifies the mismatch of the two surfaces' nodes in the contact
    integrals); the traction of the bulk of a P1 displacement does not, and its projection
    is a smooth field to read and plot. The projection is onto the multipliers' space (P1
    unless ``multiplier_degree`` says otherwise). With P2 displacements the bulk's traction
    follows the multipliers' oscillation in part: :func:`nodal_pressure` is the smoother
    reading there (see the user guide, *Results*)."""
    from dolfinx.fem import petsc as fem_petsc
    from petsc4py import PETSc

    from contact_ufl.estimate import stress_field

    c = problem.contacts[pair]
    bulk = problem.bulk_of(c)
    P = stress_field(bulk)
    N = ufl.FacetNormal(bulk.V.mesh)
    space = c.slave.P1
    p, q = ufl.TrialFunction(space), ufl.TestFunction(space)
    maps = [c.slave.entity_map]
    mass = fem_petsc.assemble_matrix(jit.form(p * q * c.ds, entity_maps=maps))
    mass.assemble()
    traction = ufl.dot(c.kinematics.nu, ufl.dot(P, N))
    rhs = fem_petsc.assemble_vector(jit.form(traction * q * c.ds, entity_maps=maps))
    rhs.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    recovered = dolfinx.fem.Function(space, name="recovered_pressure")
    solver = PETSc.KSP().create(problem.comm)
    solver.setOperators(mass)
    solver.setType("cg")
    solver.getPC().setType("jacobi")
    solver.setTolerances(rtol=1e-12, atol=0.0, max_it=1000)
    solver.solve(rhs, recovered.x.petsc_vec)
    recovered.x.scatter_forward()
    for obj in (solver, mass, rhs):
        obj.destroy()
    return recovered


def nodal_pressure(problem, pair: int = 0) -> dolfinx.fem.Function:
    """The nominal contact pressure node by node as a nodal force over a nodal area,
    ``int lambda_N phi_i dS / int phi_i dS`` (collective): the reading a lumped (dual)
    multiplier basis would give of the same contact forces, its integral the contact's
    normal force.

    Smoother than the multipliers on non-matching meshes, and than
    :func:`recovered_pressure` with P2 displacements (see the user guide, *Results*).
    Multipliers whose shape functions do not all integrate to a positive area (P2 on
    triangles: the vertex ones integrate to zero) are refused."""
    c = problem.contacts[pair]
    area = c.slave.nodal_mass
    largest = problem.comm.allreduce(float(np.max(area, initial=0.0)), MPI.MAX)
    if problem.comm.allreduce(bool(np.any(area <= 1e-12 * largest)), MPI.LOR):
        raise ContactInputError(
            "nodal_pressure: some multiplier shape functions integrate to zero or less (P2 "
            "multipliers on triangles): they have no nodal area; use recovered_pressure"
        )
    space = c.slave.P1
    q = ufl.TestFunction(space)
    force = c.slave.assemble_nodal(
        jit.form(c.lambda_N * q * c.ds, entity_maps=[c.slave.entity_map]), space
    )
    owned = space.dofmap.index_map.size_local
    pressure = dolfinx.fem.Function(space, name="nodal_pressure")
    pressure.x.array[:owned] = force[:owned] / area
    pressure.x.scatter_forward()
    return pressure
