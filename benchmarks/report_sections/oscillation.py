"""The section of the report on the node-to-node oscillation of the contact multipliers
(``benchmarks/pressure_oscillation.py``): its cause, one factor at a time, and the pressure
recovered from the bulk."""

from report_sections.tables import Column, Section, Table, fixed, significant

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
)
