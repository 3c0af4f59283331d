"""The command that makes each results file again, shown where its stamp has none (stamps
rebuilt from the repository's history).
"""

#: the command that makes each file again, shown where its stamp has none (stamps rebuilt from
#: the history); a run's stamp has its own
COMMANDS = {
    "cattaneo_mindlin.json": "python benchmarks/cattaneo_mindlin.py --json {path}",
    "checkpoint.json": "python benchmarks/checkpoint.py --json {path}",
    "checkpoint_quick.json": "python benchmarks/checkpoint.py --quick --json {path}",
    "eps_default_2d.json": "python benchmarks/eps_default.py --json {path}",
    "eps_default_2d_p2.json": "python benchmarks/eps_default.py --degree 2 --json {path}",
    "eps_default_3d.json": "python benchmarks/eps_default.py --dim 3 --json {path}",
    "eps_default_3d_p2.json": "python benchmarks/eps_default.py --dim 3 --degree 2 --json {path}",
    "eps_default_3d_p2_fine.json": (
        "python benchmarks/eps_default.py --dim 3 --degree 2 --h 0.0175 --json {path}"
    ),
    "eps_friction.json": "python benchmarks/eps_friction.py --json {path}",
    "hard_cases.json": "python benchmarks/hard_cases.py --json {path}",
    "hard_cases_quick.json": "python benchmarks/hard_cases.py --quick --json {path}",
    "hertz.json": "python benchmarks/hertz.py --json {path}",
    "hertz_linear.json": "python benchmarks/hertz.py --material linear --json {path}",
    "hertz_2d_linear_1step_p1_wall.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree 1"
        " --repeat 3 --h 0.02 0.015 0.01 0.0075 0.005 0.0035 --json {path}"
    ),
    "hertz_2d_linear_1step_p1_graded_wall.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree 1"
        " --refine-radius 0.1 --repeat 3 --h 0.01 0.0075 0.005 0.0035 0.0025 0.00175"
        " --json {path}"
    ),
    "hertz_2d_linear_1step_p2_wall.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree 2"
        " --repeat 3 --h 0.04 0.03 0.025 0.0225 0.02 0.015 0.01 --json {path}"
    ),
    "hertz_2d_linear_1step_p2_graded_wall.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --eps default --degree 2"
        " --refine-radius 0.1 --repeat 3 --h 0.03 0.025 0.02 0.015 0.01 0.0075 --json {path}"
    ),
    "hertz_2d_linear_1step_p1_eps_h.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1"
        " --h 0.02 0.015 0.01 0.0075 0.005 0.0035 --json {path}"
    ),
    "hertz_2d_linear_1step_p1_graded_eps_h.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1 --refine-radius 0.1"
        " --h 0.01 0.0075 0.005 0.0035 0.0025 0.00175 --json {path}"
    ),
    "hertz_2d_linear_1step_p2_eps_h.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2"
        " --h 0.04 0.03 0.025 0.0225 0.02 0.015 0.01 --json {path}"
    ),
    "hertz_2d_linear_1step_p2_graded_eps_h.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --refine-radius 0.1"
        " --h 0.03 0.025 0.02 0.015 0.01 0.0075 --json {path}"
    ),
    "hertz_3d.json": "python benchmarks/hertz.py --dim 3 --json {path}",
    "hertz_3d_rigid.json": "python benchmarks/hertz.py --dim 3 --flat rigid --json {path}",
    "hertz_3d_p2.json": "python benchmarks/hertz.py --dim 3 --degree 2 --json {path}",
    "hertz_3d_p2_iso.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 [--multiplier-degree iso] --h 0.05 0.035"
        " --json {path}"
    ),
    "hertz_3d_1step_p1_wall.json": (
        "python benchmarks/hertz.py --dim 3 --steps 1 --eps default --json {path}"
    ),
    "hertz_3d_1step_p2_wall.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default --json {path}"
    ),
    "hertz_3d_1step_p2.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default"
        " --h 0.1 0.07 0.05 0.04 --json {path}  (now on the curved mesh)"
    ),
    "hertz_3d_1step_p2_ranks1.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default --h 0.025"
        " --h-edge 0.01 --json {path}"
    ),
    "hertz_3d_1step_p2_ranks2.json": (
        "mpirun -n 2 python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default"
        " --h 0.025 --h-edge 0.01 --json {path}"
    ),
    "hertz_3d_1step_p2_field_split_ranks1.json": (
        "python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default --h 0.025"
        " --h-edge 0.01 --field-split --json {path}"
    ),
    "hertz_3d_1step_p2_field_split_ranks2.json": (
        "mpirun -n 2 python benchmarks/hertz.py --dim 3 --degree 2 --steps 1 --eps default"
        " --h 0.025 --h-edge 0.01 --field-split --json {path}"
    ),
    "hertz_linear_1step_p1_s1.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1"
        " --h 0.02 0.01 0.0075 0.005 0.0025 --json {path}"
    ),
    "hertz_linear_1step_p1_s4.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1 --subdivisions 4"
        " --h 0.02 0.01 0.0075 0.005 --json {path}"
    ),
    "hertz_linear_1step_p2_s1.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2"
        " --h 0.04 0.03 0.025 0.02 0.01 --json {path}"
    ),
    "hertz_linear_1step_p2_s4.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --subdivisions 4"
        " --h 0.04 0.03 0.025 0.02 0.01 --json {path}"
    ),
    "hertz_linear_1step_refine01_p1_s1.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 1 --refine-radius 0.1"
        " --h 0.01 0.005 0.0035 0.0025 --json {path}"
    ),
    "hertz_linear_1step_refine01_p2_s1.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --refine-radius 0.1"
        " --h 0.02 0.015 0.01 0.0075 --json {path}"
    ),
    "hertz_linear_1step_p2_iso_eps_default.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --eps default"
        " [--multiplier-degree iso] [--subdivisions 4] [--refine-radius 0.1] --h ... --json {path}"
    ),
    "hertz_linear_1step_p2_iso_h002.json": (
        "python benchmarks/hertz.py --material linear --steps 1 --degree 2 --h 0.02"
        " [--multiplier-degree iso] [--subdivisions 8] --json {path}"
    ),
    "ironing.json": "python benchmarks/ironing.py --json {path}",
    "ironing_quick.json": "python benchmarks/ironing.py --quick --json {path}",
    "ironing_3d_quick.json": (
        "python benchmarks/ironing_3d.py --quick --json {path} --png docs/ironing_3d_forces.png"
    ),
    "ironing_plane_strain_quick.json": (
        "python benchmarks/ironing_plane_strain.py --quick --json {path}"
    ),
    "membrane.json": "python benchmarks/membrane.py --json {path}",
    "newton_cost.json": "python benchmarks/newton_cost.py --repeat 2 --json {path}",
    "newton_cost_2d_glued.json": (
        "python benchmarks/newton_cost.py --scenes hertz --sizes 0.01 0.005 0.0025 --glued"
        " --repeat 3 --json {path}"
    ),
    "newton_cost_2d_107k_parts.json": (
        "python benchmarks/newton_cost.py --scenes hertz --sizes 0.0023 --glued --repeat 2"
        " --json {path}"
    ),
    "newton_cost_50k_engaged_eps_h.json": (
        "python benchmarks/newton_cost.py --scenes hertz3d --sizes 0.00625 --glued --json {path}"
    ),
    "newton_cost_ranks_11k.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 2 --scenes hertz3d --sizes 0.0125"
        " --glued --json {path}"
    ),
    "newton_cost_ranks_50k_split.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 2 --scenes hertz3d"
        " --sizes 0.00625 --glued --eps default --json {path}"
    ),
    "newton_cost_ranks_113k_fixed.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 1 --scenes hertz3d --sizes 0.0045"
        " --glued --eps default --json {path}"
    ),
    "search.json": (
        "python benchmarks/search.py --sweeps graded self_contact radius distance points"
        " --json {path}"
    ),
    "search_points.json": "python benchmarks/search.py --sweeps points --json {path}",
    "search_quadratic.json": "python benchmarks/search.py --sweeps quadratic --json {path}",
    "search_scenes.json": "python benchmarks/search.py --sweeps scenes --json {path}",
    "smoothed_normal_3d.json": "python benchmarks/smoothed_normal_3d.py --json {path}",
    "solvers_3d_mumps.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --scenes hertz3d"
        " --sizes 0.0125 0.00625 0.0045 --eps default --json {path}"
    ),
    "solvers_3d_field_split.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --scenes hertz3d"
        " --sizes 0.0125 0.00625 0.0045 --eps default --field-split --json {path}"
    ),
    "solvers_3d_115k_mumps_best_of_2.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 2 --scenes hertz3d --sizes 0.0045"
        " --eps default --json {path}"
    ),
    "solvers_3d_115k_field_split_best_of_2.json": (
        "python benchmarks/newton_cost.py --ranks 1 2 --repeat 2 --scenes hertz3d --sizes 0.0045"
        " --eps default --field-split --json {path}"
    ),
    "taylor.json": "python benchmarks/taylor.py --json {path}",
}
