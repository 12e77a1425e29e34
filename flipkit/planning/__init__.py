"""Planning layer: the plan file (``flipkit-plan/2``), the planner that chains segments, the
independent verification of a plan ("verify": its arrays against its constraints), the
export of a verified plan to a controller, and the cook-window scheduler (``cook``: cook
orders and table spots; ``motions``: the planners a schedule uses, by motion kind;
``schedule``: one arm's flips and serves ordered, timed and planned ahead)."""
