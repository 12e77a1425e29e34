"""Every speed claim in one run: the translates with every peer, the flips, the batch and the
replan, side by side, printed and returned for JSON.

    python -m bench.bench_all [--jit] [--locations N] [--json OUT]

Runs, one after the other in this process, :func:`~bench.bench.bench_translate`
(the six translates, the SQP beside FATROP, exact IPOPT, ``sqpmethod`` and L-BFGS IPOPT),
:func:`~bench.bench.bench_flip` (the first N Table I pickup-and-flips with the
SQP from the atlas and cold and with L-BFGS IPOPT, then the batch of five cold and from the
atlas, one after the other and on one worker per CPU) and
:func:`~bench.bench_replan.bench_replan` (a fresh sense-plan-act validation's
sensed places), then prints one summary: medians, iterations and milliseconds per
iteration, the SQP's ratio to the best peer, and each target of the speed work beside its
measurement.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import warnings

from bench.bench import bench_flip, bench_translate, machine, plain_json
from bench.bench_replan import bench_replan, run_validation
from flipkit.config import TABLE1_LOCATIONS, CellConfig
from flipkit.experiments.speed import TRANSLATE_SOLVERS
from flipkit.planning.planners.atlas import default_atlas

#: The speed targets (s): translate median, flip from the atlas (solve) and cold (solve),
#: the batch of five from the atlas on the machine's workers (wall).
TARGETS_S = {"translate": 0.04, "flip_atlas": 0.25, "flip_cold": 0.6, "batch_atlas": 1.0}

_FLIP_METHODS = {"sqp_atlas": "SQP, from the atlas", "sqp": "SQP, cold",
                 "ipopt": "IPOPT L-BFGS, cold"}


def _ms_per_iteration(rows, method: str) -> float:
    """Median over the locations of solve time / iterations (ms) of ``method``."""
    per = [1e3 * r[method]["solve_s"] / r[method]["iterations"] for r in rows
           if r[method]["iterations"]]
    return statistics.median(per) if per else float("nan")


def summarise(translate: dict, flip: dict, replan: dict) -> dict:
    """The summary of the three benches: per problem and solver the median time (s),
    iterations, ms per iteration and how many solved; the SQP's ratios; the targets."""
    n = len(translate["rows"])
    out = {"translate": {name: {k: m[k] for k in ("time_s", "cpu_s", "iterations",
                                                  "ms_per_iteration", "solved")}
                         for name, m in translate["median"].items()},
           "translate_segments": n, "flip_locations": len(flip["rows"])}
    out["flip"] = {m: {"solve_s": flip["median"][m]["solve_s"],
                       "wall_s": flip["median"][m]["wall_s"],
                       "cpu_s": flip["median"][m]["cpu_s"],
                       "iterations": flip["median"][m]["iterations"],
                       "ms_per_iteration": _ms_per_iteration(flip["rows"], m),
                       "solved": flip["median"][m]["solved"]}
                   for m in _FLIP_METHODS if m in flip["median"]}
    out["batch"] = {key: {"serial_s": flip[key]["wall_s"], "parallel_s": flip[key]["wall_parallel_s"],
                          "workers": flip[key]["workers"],
                          "solved": sum(p["status"] == "solved" for p in flip[key]["plans"])}
                    for key in ("batch", "batch_atlas") if key in flip}
    out["replan"] = {k: replan["summary"][k] for k in ("replans", "median_s", "worst_s",
                                                       "median_solving_s", "solved_ok")}
    out["sqp_ratio_translate"] = translate["sqp_ratio"]
    f = out["flip"]
    out["sqp_ratio_flip_cold"] = (f["ipopt"]["solve_s"] / f["sqp"]["solve_s"]
                                  if "ipopt" in f else None)
    got = {"translate": out["translate"]["sqp"]["time_s"],
           "flip_atlas": f.get("sqp_atlas", {}).get("solve_s"), "flip_cold": f["sqp"]["solve_s"],
           "batch_atlas": out["batch"].get("batch_atlas", {}).get("parallel_s")}
    out["targets"] = {k: {"target_s": TARGETS_S[k], "measured_s": got[k],
                          "met": got[k] is not None and got[k] <= TARGETS_S[k]} for k in TARGETS_S}
    return out


def print_summary(s: dict) -> None:
    """Print :func:`summarise`'s summary as one table and the lines under it."""
    print(f"\n=== one run, side by side ({machine()})")
    print(f"{'problem':<34}{'solver':<22}{'median s':>9}{'it':>6}{'ms/it':>7}{'solved':>8}"
          f"{'cpu s':>8}")
    n = s["translate_segments"]
    for name, m in s["translate"].items():
        print(f"{f'translate (median of {n})':<34}{TRANSLATE_SOLVERS[name]:<22}"
              f"{m['time_s']:9.3f}{m['iterations']:6.0f}{m['ms_per_iteration']:7.1f}"
              f"{m['solved']:>6}/{n}{m['cpu_s']:8.3f}")
    for method, label in _FLIP_METHODS.items():
        if method in s["flip"]:
            m = s["flip"][method]
            print(f"{'pickup-and-flip (solve; median)':<34}{label:<22}{m['solve_s']:9.3f}"
                  f"{m['iterations']:6.0f}{m['ms_per_iteration']:7.1f}"
                  f"{m['solved']:>6}/{s['flip_locations']}{m['cpu_s']:8.3f}")
    for key, b in s["batch"].items():
        start = "from the atlas" if key == "batch_atlas" else "cold"
        print(f"{'batch of five, ' + start:<34}{'SQP':<22}{b['parallel_s']:9.3f}"
              f"{'':>13}{b['solved']:>6}/5   ({b['workers']} workers; one after another "
              f"{b['serial_s']:.2f} s)")
    r = s["replan"]
    print(f"{'replan after the scoop':<34}{'SQP':<22}{r['median_s']:9.3f}{'':>13}"
          f"{r['solved_ok']:>6}/{r['replans']}   (worst {r['worst_s']:.3f} s)")
    ratio = s["sqp_ratio_translate"]
    if ratio:
        print(f"translate: the best peer ({TRANSLATE_SOLVERS[ratio['best']]}) takes "
              f"{ratio['ratio']:.2f} × the SQP's median time (> 1: the SQP is faster); in "
              f"CPU time {TRANSLATE_SOLVERS[ratio['best_cpu']]} {ratio['ratio_cpu']:.2f} ×")
    if s["sqp_ratio_flip_cold"]:
        print(f"pickup-and-flip, cold: IPOPT L-BFGS takes {s['sqp_ratio_flip_cold']:.2f} × the "
              f"SQP's median solve time")
    for k, t in s["targets"].items():
        got = "-" if t["measured_s"] is None else f"{t['measured_s']:.3f} s"
        print(f"target {k}: ≤ {t['target_s']} s, measured {got}: "
              f"{'met' if t['met'] else 'not met'}")


def bench_all(cell: CellConfig, jit: bool, n_locations: int) -> dict:
    """Run the three benches and print the summary; return everything for JSON."""
    translate = bench_translate(cell, False, jit)
    flip = bench_flip(cell, n_locations, 5, default_atlas(cell))
    replan = bench_replan(run_validation())
    summary = summarise(translate, flip, replan)
    print_summary(summary)
    return {"machine": machine(), "summary": summary, "translate": translate, "flip": flip,
            "replan": replan}


def main(argv=None) -> int:
    """Command-line entry point (see the module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m bench.bench_all",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--jit", action="store_true",
                        help="JIT-compile the exact-derivative peers' functions")
    parser.add_argument("--locations", type=int, default=len(TABLE1_LOCATIONS), metavar="N",
                        help="the first N Table I pickup-and-flips (default all ten)")
    parser.add_argument("--json", metavar="OUT", help="also write the results as JSON")
    args = parser.parse_args(argv)
    if not 1 <= args.locations <= len(TABLE1_LOCATIONS):
        parser.error(f"--locations must be 1..{len(TABLE1_LOCATIONS)}")
    warnings.filterwarnings("ignore", message="Solution may be inaccurate")
    result = bench_all(CellConfig(), args.jit, args.locations)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(plain_json(result), fh, indent=1)
    return 0


__all__ = ["TARGETS_S", "bench_all", "main", "print_summary", "summarise"]

if __name__ == "__main__":
    sys.exit(main())
