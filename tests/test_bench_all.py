"""The one-run summary of the benches (bench/bench_all.py)."""

from pytest import approx

from bench.bench import sqp_ratio
from bench.bench_all import print_summary, summarise


def _translate(times, cpus, solved):
    med = {name: {"time_s": t, "cpu_s": c, "iterations": 10.0, "ms_per_iteration": 1.0,
                  "solved": s} for name, t, c, s in zip(("sqp", "fatrop", "ipopt"), times,
                                                        cpus, solved)}
    return {"rows": [{}] * 6, "median": med, "sqp_ratio": sqp_ratio(med, 6)}


def _flip():
    row = {m: {"solve_s": s, "iterations": 10, "status": "solved"}
           for m, s in (("sqp", 0.5), ("sqp_atlas", 0.2), ("ipopt", 2.0))}
    med = {m: {"solve_s": r["solve_s"], "wall_s": r["solve_s"] + 0.1, "cpu_s": r["solve_s"],
               "iterations": 10, "solved": 1} for m, r in row.items()}
    batch = {"wall_s": 2.0, "wall_parallel_s": 1.2, "workers": 2,
             "plans": [{"status": "solved"}] * 5}
    return {"rows": [row], "median": med, "batch": batch, "batch_atlas": {**batch,
                                                                        "wall_parallel_s": 0.9}}


REPLAN = {"summary": {"replans": 4, "median_s": 0.01, "worst_s": 0.3, "median_solving_s": 0.2,
                      "solved_ok": 4}}


def test_ratio_is_to_the_fastest_peer_that_solved_every_segment(capsys):
    """A faster peer that missed a segment does not count; CPU and wall pick separately."""
    t = _translate((0.1, 0.05, 0.3), (0.1, 0.04, 0.2), (6, 5, 6))
    s = summarise(t, _flip(), REPLAN)
    r = s["sqp_ratio_translate"]
    assert r["best"] == r["best_cpu"] == "ipopt"
    assert r["ratio"] == approx(3.0) and r["ratio_cpu"] == approx(2.0)
    assert s["sqp_ratio_flip_cold"] == approx(4.0)
    assert s["flip"]["sqp_atlas"]["ms_per_iteration"] == approx(20.0)
    targets = s["targets"]
    assert not targets["translate"]["met"] and targets["flip_atlas"]["met"]
    assert targets["flip_cold"]["met"] and targets["batch_atlas"]["met"]
    print_summary(s)
    out = capsys.readouterr().out
    assert "takes 3.00 × the SQP's median time" in out and "target translate" in out


def test_no_ratio_when_the_sqp_missed_a_segment():
    t = _translate((0.1, 0.05, 0.3), (0.1, 0.04, 0.2), (5, 6, 6))
    assert t["sqp_ratio"] is None
    assert summarise(t, _flip(), REPLAN)["sqp_ratio_translate"] is None
