"""Solver layer: the SQP (cvxpy subproblems solved by OSQP) and CasADi's IPOPT, on the
:class:`~flipkit.transcription.nlp.NLP` interface. Knows nothing of behaviours or plans."""
