"""Experiment layer: sweeps (local processes or Dask), simulated trials ("validate": plans
executed in MuJoCo), the sensitivity study, the EE + IK comparison (compare-ik), the solve
scaling and what the speed comparisons share (:mod:`~flipkit.experiments.speed`). The
benchmarks that only measure are the repository's ``bench/``, not the package's."""
