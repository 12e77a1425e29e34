"""Planning layer: the plan file (``flipkit-plan/2``), the planner that chains segments, the
independent verification of a plan ("verify": its arrays against its constraints) and the
export of a verified plan to a controller."""
