"""The planners: the ``chain.Planner`` that chains any behaviour, the entry points
(``planner``: translate, flip, batch, replan; ``serve``), their input checks (``inputs``) and
the warm-start atlas (``atlas``)."""
