"""The kitchen: cook orders and table spots (``cook``), the motions a schedule uses
(``motions``), the event windows (``windows``), the side table over time (``table``), the
greedy cook-window scheduler (``schedule``), the CP-SAT model (``cpsat``) solved in a child
process (``cpsat_process``), the optimising scheduler built on it (``optimal``), planning
ahead (``prefetch``), streams of drops (``stream``), the motion-duration model
(``durations``) and throughput (``throughput``)."""
