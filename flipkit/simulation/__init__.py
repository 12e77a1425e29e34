"""Simulation layer: PD tracking, the cell in MuJoCo, closed-loop execution, the burger's run
record and the paper's Sec. V judges, and animations."""
