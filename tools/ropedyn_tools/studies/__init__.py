"""The studies behind docs/: each module has `main(argv=None)`, runs as
`python -m ropedyn_tools.studies.NAME` and is the code of the command scripts/NAME.

| module | command | writes |
|---|---|---|
| work_precision | scripts/work_precision | docs/validation/work-precision.md, docs/data/rope_*.csv, figures |
| work_precision_testset | scripts/work_precision_testset | docs/validation/testset.md, testset_wp.csv, wp_*.png |
| validation | scripts/validation | docs/validation/statics-modes.md |
| stability_report | scripts/stability_report | docs/validation/hard-scenes.md, cvode-order.md, long-horizon.md, order-safety.md (measures: stability_metrics) |
| bench_rfem, bench_models | scripts/bench_rfem, bench_models | docs/performance/cost-vs-n.md |
| bench_step, bench_kernels | scripts/bench_step, bench_kernels | docs/performance/step.md |
| bench_effects, bench_sweep, bench_peers | scripts/bench_* | docs/performance/effects.md, sweeps.md, peers.md |
| auto_table, auto_accuracy, cost_model | scripts/auto_table, ... | docs/performance/auto.md |
| profile_step | scripts/profile_step | docs/performance/step.md (callgrind split of a step) |
| fig5 | scripts/fig5 | docs/figures/fig5_energy.png, docs/data/fig5_energy.csv |
| calibrate | scripts/calibrate | prints the fitted MPP damping factors |
| readme_figures | scripts/readme_figures | docs/figures/rope_motion.png, energy.png |
| mebdf_stability | scripts/mebdf_stability.py | prints the MEBDF / BDF stability table |

Without `--exe` a study builds the Release configuration (scripts/build) and uses it.
Shared helpers: `ropedyn_tools.repo` (paths, executable, `--set`),
`ropedyn_tools.studies.common` (machine, time stamp, generated sections of docs/ pages).
"""
