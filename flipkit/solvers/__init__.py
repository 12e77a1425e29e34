"""Solver layer: the SQP (cvxpy subproblems solved by OSQP) and CasADi's IPOPT, on the
:class:`~flipkit.transcription.nlp.NLP` interface; FATROP and exact-Hessian IPOPT on its
stage-wise SX graph (:mod:`flipkit.solvers.exact`). Knows nothing of behaviours or plans."""
