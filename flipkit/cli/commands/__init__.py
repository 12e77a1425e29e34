"""The work of each sub-command, imported by :func:`flipkit.cli.common.deferred` only when that
sub-command runs, after the checks in ``flipkit.cli.<command>``: these modules import the
models (pinocchio, CasADi, cvxpy, MuJoCo) at their top."""
