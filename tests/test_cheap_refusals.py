"""Cheap refusals are cheap: an argument or input-file error is refused before the heavy
modules are imported (docs/usage.md, "Refusals").

Each case runs the command line in a fresh interpreter and asserts exit 2, one line on
stderr, no traceback, no output written, and that none of :data:`HEAVY` was imported by
the time of the refusal. Wall times are in docs/benchmarks/2026-11-29-cheap-refusals.md;
the test asserts on the imports, which do not depend on the machine's load.
"""

import json
import subprocess
import sys

import pytest

# The modules that make a command slow to start (each 0.1-1 s to import): the models and
# solvers, the simulator, the plots, the schema validator, the schedulers and the viewers.
HEAVY = ("pinocchio", "casadi", "cvxpy", "osqp", "clarabel", "scs", "scipy", "mujoco",
         "matplotlib", "jsonschema", "ortools", "dask", "distributed", "meshcat", "papermill",
         "placo", "coal", "hppfcl")

# Runs the command line in-process, then prints the heavy modules loaded as one JSON line.
HARNESS = (
    "import json, sys\n"
    "from flipkit.cli import main\n"
    "rc = main(sys.argv[2:])\n"
    "heavy = set(json.loads(sys.argv[1]))\n"
    "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules} & heavy)))\n"
    "sys.exit(rc)\n")

GOOD_ORDER = "burger,t_drop,x,y\nb1,0,0.70,-0.20\n"
TOP_KEYS = ("behavior", "status", "robot", "gravity", "grill_height", "spatula", "burger",
            "cone", "created_by")


def plan_doc(t) -> str:
    """A plan file's top level, all but its one segment's node times ``t`` left empty."""
    return json.dumps({"format": "flipkit-plan/2", **dict.fromkeys(TOP_KEYS),
                       "segments": [{"t": t}]})


FILES = {
    "bad.json": "{oops",
    "list.json": "[1, 2]",
    "order_short.csv": "burger,t_drop,x\nb1,0,0.7\n",
    "order_extra.csv": "burger,t_drop,x,y,note\nb1,0,0.70,-0.20,rare\n",
    "order_nan.csv": "burger,t_drop,x,y\nb1,0,nan,-0.20\n",
    "order.csv": GOOD_ORDER,
    "batch_short.csv": "x,y\n0.75,0.0\n",
    "batch_extra.csv": "px,py,pz,scoop\n0.64,-0.33,0.073,7\n",
    "batch_six.csv": "x,y,z\n" + "0.75,0.0,0.072\n" * 6,
    "batch_close.csv": "x,y,z\n0.70,-0.20,0.072\n0.72,-0.20,0.072\n",
    "cell.json": '{"cell_geometry": {}, "cell_geometry": {}}',
    "swapped.json": plan_doc([0.0, 0.2, 0.1]),
    "nodes.json": plan_doc([i * 1e-3 for i in range(1003)]),
    "atlas.npz": "not a zip",
}
FLIP = ["plan", "flip", "--burger", "0.69", "-0.16", "0.072", "--json", "{d}/o.json"]

CASES = {
    "validate seed": (["validate", "--plan", "{d}/bad.json", "--trials", "1", "--seed", "-1",
                       "--json", "{d}/o.json"], "seed"),
    "validate trials": (["validate", "--locations", "table1", "--trials", "0", "--json",
                         "{d}/o.json"], "--trials"),
    "validate rate": (["validate", "--locations", "table1", "--trials", "1", "--rate", "nan",
                       "--json", "{d}/o.json"], "--rate"),
    "validate plan": (["validate", "--plan", "{d}/bad.json", "--trials", "1", "--json",
                       "{d}/o.json"], "not a JSON file"),
    "schedule header": (["schedule", "{d}/order_short.csv", "--json", "{d}/o.json"],
                        "missing column 'y'"),
    "schedule extra column": (["schedule", "{d}/order_extra.csv", "--json", "{d}/o.json"],
                              "unknown column 'note'"),
    "schedule nan": (["schedule", "{d}/order_nan.csv", "--json", "{d}/o.json"], "finite"),
    "schedule missing": (["schedule", "{d}/none.csv", "--json", "{d}/o.json"], "not found"),
    "schedule time limit": (["schedule", "{d}/order.csv", "--json", "{d}/o.json",
                             "--time-limit", "0"], "--time-limit"),
    "flip nan": (["plan", "flip", "--burger", "nan", "0", "0", "--json", "{d}/o.json"],
                 "finite"),
    "flip separator": (["plan", "flip", "--burger", "0.6_9", "-0.16", "0.072", "--json",
                        "{d}/o.json"], "not a decimal number"),
    "flip height": (["plan", "flip", "--burger", "0.69", "-0.16", "0.3", "--json",
                     "{d}/o.json"], "grill surface"),
    "flip r_land": ([*FLIP, "--r-land", "1e-9"], "--r-land"),
    "flip diameter": ([*FLIP, "--burger-diameter", "0.2"], "--burger-diameter must be in"),
    "serve diameter": (["plan", "serve", "--burger", "0.69", "-0.16", "0.072", "--table-spot",
                        "0.3", "0.6", "--burger-diameter", "nan", "--json", "{d}/o.json"],
                       "--burger-diameter"),
    "flip start count": ([*FLIP, "--start-q", "0", "0", "0"], "--start-q takes 6"),
    "flip atlas": ([*FLIP, "--atlas", "{d}/atlas.npz"], "not an .npz archive"),
    "translate nan": (["plan", "translate", "--from", "nan", "0", "0.2", "--to", "0.7", "0",
                       "0.2", "--json", "{d}/o.json"], "--from"),
    "serve off table": (["plan", "serve", "--burger", "0.69", "-0.16", "0.072",
                         "--table-spot", "0.1", "0.6", "--json", "{d}/o.json"],
                        "off the table"),
    "batch header": (["plan", "batch", "--burgers", "{d}/batch_short.csv", "--out",
                      "{d}/out"], "missing column 'z'"),
    "batch extra column": (["plan", "batch", "--burgers", "{d}/batch_extra.csv", "--out",
                            "{d}/out"], "unknown column 'scoop'"),
    "batch rows": (["plan", "batch", "--burgers", "{d}/batch_six.csv", "--out", "{d}/out"],
                   "1 to 5"),
    "batch spacing": (["plan", "batch", "--burgers", "{d}/batch_close.csv", "--out",
                       "{d}/out"], "one burger diameter"),
    "batch workers": (["plan", "batch", "--burgers", "{d}/batch_close.csv", "--out",
                       "{d}/out", "--workers", "0"], "--workers"),
    "export missing": (["export", "{d}/missing.json", "--out", "{d}/o.csv"], "not found"),
    "export rate": (["export", "{d}/bad.json", "--out", "{d}/o.csv", "--rate", "7"],
                    "--rate"),
    "verify malformed": (["verify", "{d}/bad.json"], "not a JSON file"),
    "verify not an object": (["verify", "{d}/list.json"], "expected a JSON object"),
    "verify swapped times": (["verify", "{d}/swapped.json"],
                             "segments[0].t: node times must increase strictly"),
    "verify node count": (["verify", "{d}/nodes.json"], "segments[0].t: expected N+1"),
    "export swapped times": (["export", "{d}/swapped.json", "--out", "{d}/o.csv"],
                             "segments[0].t"),
    "verify tol": (["verify", "{d}/bad.json", "--tol", "1"], "--tol"),
    "verify cell": (["verify", "{d}/list.json", "--cell", "{d}/cell.json"], "duplicate key"),
    "animate": (["animate", "{d}/bad.json", "--out", "{d}/a.gif"], "not a JSON file"),
    "animate fps": (["animate", "{d}/bad.json", "--out", "{d}/a.gif", "--fps", "0"], "--fps"),
    "view": (["view", "{d}/bad.json", "--html", "{d}/v.html"], "not a JSON file"),
    "compare-ik": (["compare-ik", "--grid", "0", "3", "--json", "{d}/o.json"], "--grid"),
    "atlas build grid": (["atlas", "build", "--grid", "0", "3", "--out", "{d}/a.npz"],
                         "--grid"),
    "atlas build out": (["atlas", "build", "--out", "{d}/a.txt"], ".npz"),
    "atlas info": (["atlas", "info", "{d}/atlas.npz"], "not an .npz archive"),
    "figures": (["figures", "--only", "nonsense", "--out", "{d}/figs"], "unknown figure id"),
}


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("refusals")
    for name, text in FILES.items():
        (d / name).write_text(text)
    return d


def refuse(argv: list[str], d) -> tuple[int, str, list[str]]:
    """Exit status, stderr and the heavy modules imported of ``flipkit ARGV`` in a fresh
    interpreter."""
    argv = [a.format(d=d) for a in argv]
    run = subprocess.run([sys.executable, "-c", HARNESS, json.dumps(HEAVY), *argv],
                         capture_output=True, text=True, timeout=120)
    return run.returncode, run.stderr, json.loads(run.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("name", CASES)
def test_a_refusal_imports_no_heavy_module(inputs, name):
    argv, text = CASES[name]
    before = sorted(p.name for p in inputs.iterdir())
    code, err, heavy = refuse(argv, inputs)
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith("flipkit: error:"), err
    assert text in lines[0], lines[0]
    assert heavy == [], f"imported before refusing: {heavy}"
    assert sorted(p.name for p in inputs.iterdir()) == before  # nothing written


def test_the_harness_sees_a_heavy_import(tmp_path):
    """The same harness on a command that gets past its cheap checks: it reports the heavy
    modules, so an empty list above means they were not imported."""
    plan = tmp_path / "no_segments.json"
    plan.write_text(json.dumps({"format": "flipkit-plan/2", **dict.fromkeys(TOP_KEYS),
                                "segments": None}))
    code, err, heavy = refuse(["verify", str(plan)], tmp_path)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "scipy" in heavy
