"""Experiment layer: sweeps (local processes or Dask), simulated trials ("validate": plans
executed in MuJoCo), the sensitivity study, the EE + IK comparison (compare-ik) and benchmarks."""
