"""The section of the report on the node-to-node oscillation of the contact multipliers
(``benchmarks/pressure_oscillation.py``): its cause, one factor at a time, and the pressure
recovered from the bulk, in 2D and 3D."""

from report_sections.tables import Column, Section, Table, fixed, significant

#: the 3D table's fields, in the words of its rows (the results hold more: the projections of
#: the stress of the displacement itself, ``recovered_ufl``, ``recovered_p2_ufl``)
FIELD_NAMES = {
    "lambda": "lambda",
    "force": "force",
    "recovered": "recovered",
    "recovered_p2": "recovered P2",
}

SECTIONS = (
    Section(
        "The multipliers' oscillation on non-matching meshes",
        "The 2D Hertz scene of the Hertz demo (Neo-Hookean, depth 0.005 in 4 steps, the "
        "default eps, the master 1.3 times coarser than the slave), one factor changed at a "
        "time: *matching* (the same contact-line nodes on both surfaces), *ratio 2.0* (the "
        "master twice coarser), *sub16* (the contact rule on 16 sub-segments of each slave "
        "facet), *eps10* (ten times the default eps), *p2* (P2 displacements). Nodal "
        "pressures along the slave surface against Hertz's profile at the computed force: "
        "*L2* is `||p_h - p|| / (p0 a^1/2)` over `|x| < 1.5 a`; *oscillation* the rms of the "
        "second difference of the nodes' error over `|x| < 0.8 a`, over p0, of the "
        "multipliers (*lambda*), of the nodal forces over the nodal lengths (*force*: what a "
        "dual, lumped, basis reads from the same solution) and of the pressure recovered "
        "from the bulk (`results.recovered_pressure`); *period*: the wavelength of the "
        "error's largest Fourier mode, in node spacings (2: a zig-zag).",
        "python benchmarks/pressure_oscillation.py [--variants ...] [--h ...] --json FILE",
        (
            Table(
                "By variant and mesh",
                ("pressure_oscillation.json",),
                (
                    Column("variant", "variant"),
                    Column("a/h", "a_over_h", fixed(1)),
                    Column("L2 (lambda)", "l2_error", fixed(3)),
                    Column("L2 (recovered)", "recovered_l2_error", fixed(3)),
                    Column("oscillation (lambda)", "osc_rms", fixed(4)),
                    Column("oscillation (force)", "force_osc_rms", fixed(4)),
                    Column("oscillation (recovered)", "recovered_osc_rms", fixed(4)),
                    Column("period", "period", fixed(1)),
                    Column("wall s", "wall_s", significant),
                ),
            ),
        ),
    ),
    Section(
        "The multipliers' oscillation in 3D, P1 and P2",
        "The 3D Hertz quarter model (the sphere on a block of the 3D Hertz benchmark: linear "
        "elastic, depth 0.01 in 2 steps, the default eps, the block's mesh as fine as the "
        "ball's but not matching it); P2: P2 displacements on the curved mesh, the "
        "multipliers P1 (the package's default). Nominal pressures at the reference "
        "positions against Hertz's profile at the computed force: *L2* is "
        "`||p_h - p|| / (p0 A^1/2)` over `r < 1.5 a`, `A = pi a^2 / 4` the quarter model's "
        "contact area; the oscillation of a node is `|p_i - mean of its edge neighbours|` "
        "over p0 (the neighbours of a node on a symmetry plane off it counted twice), "
        "*largest* over the nodes in contact with their neighbours (`r < a`, the profile's "
        "own curvature included), *core* the largest and *rms* the root mean square of the "
        "same of the error `p_i - p(r_i)` over `r < 0.8 a`; *mid-side*: the largest of "
        "`e_m - (e_a + e_b) / 2` over the edges `ab` in `r < 0.8 a`, of a P2 field's "
        "mid-side nodes `m`. Fields: *lambda* the multipliers, *force* the nodal forces "
        "over the nodal areas, *recovered* `results.recovered_pressure` (the L2 projection of "
        "`nu . P N` onto the P1 multiplier space), *recovered P2* the same projection onto "
        "Lagrange P2 on the slave surface (the oscillation at its vertices).",
        "python benchmarks/pressure_oscillation.py --dim 3 [--degrees 1 2] [--h ...] --json FILE",
        (
            Table(
                "By degree, mesh and field",
                ("pressure_oscillation_3d.json",),
                (
                    Column("P", "degree"),
                    Column("field", lambda r: FIELD_NAMES[r["field"]]),
                    Column("a/h", "a_over_h", fixed(1)),
                    Column("L2", "l2_error", fixed(3)),
                    Column("oscillation, largest", "osc", fixed(3)),
                    Column("core, largest", "osc_core", fixed(3)),
                    Column("core, rms", "osc_rms", fixed(4)),
                    Column("mid-side, largest", "osc_mid_core", fixed(3)),
                    Column("wall s", "wall_s", significant),
                ),
                where=lambda r: r["field"] in FIELD_NAMES,
            ),
        ),
    ),
)
