"""The section of the report on the cost of checkpoints: a solve with a checkpoint at every
step against the same solve without (``benchmarks/checkpoint.py``).
"""

from report_sections.tables import Column, Section, Table, fixed, integer, significant


def _ratio(record: dict) -> str:
    """The median ratio of the wall times with its smallest and largest: ``1.16
    (1.06-1.18)``."""
    return f"{record['ratio_median']:.2f} ({record['ratio_min']:.2f}-{record['ratio_max']:.2f})"


SECTIONS = (
    Section(
        "The cost of checkpoints",
        "A load-stepped solve with a checkpoint at every step (`Checkpoints(folder, every=1, "
        "keep=2)`) against the same solve without, run in turn (without, with) several "
        "times, each on a problem made anew: the median wall time of either, the median "
        "ratio of each pair's wall times with the smallest and largest, and the median ratio "
        "of their CPU times (less disturbed by the machine's other work). The step after a "
        "checkpoint starts afresh as a restart would (`fresh_start`: the pairing and the "
        "sparsity plan made anew; the step's first tangent makes the solver matrix and its "
        "factorisation's analysis); *write* and *fresh start* are the milliseconds per call "
        "spent in each (the new matrix and analysis are in the ratio only). "
        "*Bytes/unknown*: the last checkpoint's `state.npz` "
        "and `meta.json` over the solver's unknowns (`meta.json` holds the step records, "
        "so it grows with the steps; the meshes, written once with the first checkpoint, "
        "are not counted). The frictional ironing in 2D and 3D, mu = 0.3 (mesh: "
        "h of the indenter / of the block); the target is a ratio below 1.05.",
        "python benchmarks/checkpoint.py [--quick] [--cases ironing_2d ironing_3d] "
        "[--pairs N] [--folder DIR] --json FILE",
        (
            Table(
                "A checkpoint at every step",
                ("checkpoint.json", "checkpoint_quick.json"),
                (
                    Column("case", "label"),
                    Column("mesh", "mesh"),
                    Column("unknowns", "unknowns", integer),
                    Column("steps", "steps", integer),
                    Column("pairs", "pairs", integer),
                    Column("without, s", "wall_without_s", significant),
                    Column("with, s", "wall_with_s", significant),
                    Column("ratio (min-max)", _ratio),
                    Column("CPU ratio", "cpu_ratio_median", fixed(2)),
                    Column("bytes/unknown", "bytes_per_unknown", fixed(0)),
                    Column("write ms/step", "write_ms_per_step", significant),
                    Column("fresh start ms/step", "fresh_start_ms_per_step", significant),
                ),
            ),
        ),
    ),
)
