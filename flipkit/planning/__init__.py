"""Planning layer, in three parts:

* :mod:`~flipkit.planning.plans`: the plan file (``flipkit-plan/2``: format, schema, the
  segments, the cell record), its independent verification ("verify": its arrays against its
  constraints) and its export to a controller (resampled, or as compensated position
  commands);
* :mod:`~flipkit.planning.planners`: the :class:`~flipkit.planning.planners.chain.Planner`
  that chains any behaviour, the entry points (translate, flip, batch, serve, replanning),
  their input checks and the warm-start atlas;
* :mod:`~flipkit.planning.kitchen`: cook orders and table spots, the motions a schedule uses,
  the cook-window scheduler and the planning ahead in worker processes.
"""
