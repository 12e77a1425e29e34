"""The sweep cache shared by the figure notebooks (flipkit.figures.pipeline.sweep_cache): one
directory per code version, results reused only for identical jobs of identical code.

No trial is simulated and nothing is planned here: the workers are replaced by counters."""

import json
from dataclasses import asdict
from pathlib import Path

import nbformat
import pytest

from flipkit.experiments import sweep
from flipkit.experiments.perturbations import Perturbations
from flipkit.experiments.trial_jobs import trial_jobs, trial_key
from flipkit.figures import inputs, pipeline, runs

CALLS = []


def counted(job):
    """A sweep worker that records each call (executor None: it runs in this process)."""
    CALLS.append(job)
    return {"trial": job["trial"], "seed": job["seed"]}


def run_trials(jobs, cache_dir):
    CALLS.clear()
    results = sweep.run_sweep(counted, jobs, None, cache_dir, trial_key, progress=False,
                              name="flipkit.experiments.trials.run_trial")
    return results, len(CALLS)


PLAN = json.dumps({"behavior": "flip", "segments": [1, 2, 3]})


def test_an_identical_trial_hits_the_cache_and_any_changed_input_misses(tmp_path):
    jobs = trial_jobs(PLAN, 2, 0, Perturbations(), mode="position")
    first, calls = run_trials(jobs, tmp_path)
    assert calls == 2
    again, calls = run_trials(trial_jobs(PLAN, 2, 0, Perturbations(), mode="position"),
                              tmp_path)
    assert calls == 0 and again == first
    changed = [
        trial_jobs(PLAN.replace("3]", "4]"), 2, 0, Perturbations(), mode="position"),  # plan
        trial_jobs(PLAN, 2, 1, Perturbations(), mode="position"),  # seed
        trial_jobs(PLAN, 2, 0, Perturbations(position_sigma=0.0), mode="position"),
        trial_jobs(PLAN, 2, 0, Perturbations(), mode="feedforward"),
        trial_jobs(PLAN, 2, 0, Perturbations(), mode="position", replan=True),
        trial_jobs(PLAN, 2, 0, Perturbations(), mode="position", physics={"burger.mu": 0.2}),
        trial_jobs(PLAN, 2, 0, Perturbations(), rate_hz=500.0, mode="position"),
        trial_jobs(PLAN, 2, 0, Perturbations(), mode="position", command="compensated"),
    ]
    for other in changed:
        assert run_trials(other, tmp_path)[1] == 2, other[0]
    # trial 2 of a longer run is new work; trials 0 and 1 are the same jobs
    assert run_trials(trial_jobs(PLAN, 3, 0, Perturbations(), mode="position"),
                      tmp_path)[1] == 1


def test_the_sensitivity_nominal_is_the_table1_position_open_loop_run():
    """The jobs the notebooks share are equal, key for key (else they would be computed twice,
    which is correct but slow)."""
    table1 = trial_jobs(PLAN, 10, 0, Perturbations(), mode="position", replan=False)
    nominal = trial_jobs(PLAN, 10, 0, Perturbations(), 1000.0, "position", False, None)
    assert [trial_key(j) for j in table1] == [trial_key(j) for j in nominal]
    assert trial_key(table1[0])["perturbations"] == asdict(Perturbations())


def test_a_changed_simulated_physics_is_not_served_from_the_cache(tmp_path, monkeypatch):
    """Trial keys carry the digest of the simulated cell's default physics: a new patty model
    (another default strip count) recomputes every trial."""
    import flipkit.experiments.trial_jobs as tj
    from flipkit.config import PhysicsConfig

    jobs = trial_jobs(PLAN, 2, 0, Perturbations(), mode="position")
    assert run_trials(jobs, tmp_path)[1] == 2
    assert run_trials(jobs, tmp_path)[1] == 0
    monkeypatch.setattr(tj, "PhysicsConfig", lambda: PhysicsConfig(burger_strips=1))
    assert run_trials(jobs, tmp_path)[1] == 2


def test_plans_are_cached_by_location_and_solver(tmp_path, monkeypatch):
    planned = []

    def fake_plan_location(job):
        planned.append((tuple(job["location"]), job["solver"]))
        path = Path(job["plans_dir"]) / "plan.json"
        path.write_text(json.dumps({"at": job["location"], "solver": job["solver"]}))
        return {"status": "solved", "reason": None, "time_s": 1.0, "path": str(path)}

    monkeypatch.setattr(runs, "plan_location", fake_plan_location)
    locations = [(0.7, 0.0, 0.07), (0.8, 0.1, 0.07)]
    first = runs.plan_targets(locations, "auto", cache_dir=tmp_path)
    assert len(planned) == 2 and first[0][2] == json.dumps({"at": [0.7, 0.0, 0.07],
                                                            "solver": "auto"})
    assert runs.plan_targets(locations, "auto", cache_dir=tmp_path) == first
    assert len(planned) == 2
    runs.plan_targets(locations[:1], "sqp", cache_dir=tmp_path)
    runs.plan_targets([(0.7, 0.0, 0.071)], "auto", cache_dir=tmp_path)
    assert len(planned) == 4
    runs.plan_targets(locations, "auto")  # no cache: planned again
    assert len(planned) == 6


def test_the_code_digest_covers_every_package_file_and_the_lock(tmp_path):
    pkg = tmp_path / "flipkit"
    (pkg / "data").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sim.py").write_text("STEP = 1\n")
    (pkg / "data" / "atlas.json").write_text("{}")
    lock = tmp_path / "environment.lock"
    lock.write_text("numpy==2.0\n")
    seen = {inputs.code_digest(lock, pkg)}
    for path, text in ((pkg / "sim.py", "STEP = 2\n"), (pkg / "data" / "atlas.json", "[]"),
                       (lock, "numpy==2.1\n"), (pkg / "new.py", "")):
        path.write_text(text)
        seen.add(inputs.code_digest(lock, pkg))
    assert len(seen) == 5
    (pkg / "__pycache__").mkdir()
    (pkg / "__pycache__" / "sim.cpython-311.pyc").write_bytes(b"\0")
    assert inputs.code_digest(lock, pkg) in seen


def test_sweep_cache_keeps_only_the_current_version(tmp_path):
    root = tmp_path / "figure-cache"
    old = pipeline.sweep_cache(root, digest="a" * 64)
    (old / "result.json").write_text("{}")
    (root / "notes").mkdir()  # not a version directory: left alone
    current = pipeline.sweep_cache(root, digest="b" * 64)
    assert current == root / ("b" * 16) and current.is_dir()
    assert not old.exists() and (root / "notes").is_dir()
    (current / "result.json").write_text("{}")
    assert pipeline.sweep_cache(root, digest="b" * 64) == current
    assert (current / "result.json").is_file()  # same code: results kept
    assert pipeline.sweep_cache(root, fresh=True, digest="b" * 64) == current
    assert list(current.iterdir()) == []  # forced: computed again


def test_declared_parameters(tmp_path):
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell("x = 1"),
        nbformat.v4.new_code_cell("quick = False  # q\ncache_dir: str | None = None\n"
                                  "# comment = no\n  indented = 3",
                                  metadata={"tags": ["parameters"]})])
    nbformat.write(nb, tmp_path / "nb.ipynb")
    assert pipeline.declared_parameters(tmp_path / "nb.ipynb") == {"quick", "cache_dir"}


@pytest.fixture
def two_notebooks(tmp_path, monkeypatch):
    """``table1`` declares ``cache_dir``, ``cell`` does not; the executor only writes files."""
    notebooks = tmp_path / "notebooks"
    notebooks.mkdir()
    for name, params in (("table1", "quick = False\ncache_dir = None"), ("cell", "quick = False")):
        nbformat.write(nbformat.v4.new_notebook(cells=[
            nbformat.v4.new_code_cell(params, metadata={"tags": ["parameters"]}),
            nbformat.v4.new_code_cell("from flipkit.figures import catalog")]),
            notebooks / f"{name}.ipynb")
    calls = {}

    def fake_execute(notebook, executed, parameters, kernel, cwd):
        fig_id, out = Path(notebook).stem, Path(parameters["out_dir"])
        (out / f"{fig_id}.pdf").write_bytes(b"figure")
        (out / f"{fig_id}.json").write_text(json.dumps({"files": [f"{fig_id}.pdf"]}))
        if "cache_dir" in parameters:
            (Path(parameters["cache_dir"]) / f"{fig_id}-result.json").write_text("{}")
        calls[fig_id] = dict(parameters)

    monkeypatch.setattr(pipeline, "execute_notebook", fake_execute)
    monkeypatch.setattr(pipeline, "kernel_name", lambda: "python3")

    def run(**kwargs):
        calls.clear()
        pipeline.run_notebooks(only=["cell", "table1"], out_dir=tmp_path / "figures",
                               build_dir=tmp_path / "build" / "notebooks",
                               notebooks_dir=notebooks, **kwargs)
        return dict(calls)

    return run, tmp_path


def test_the_runner_passes_one_cache_per_code_version(two_notebooks):
    run, tmp_path = two_notebooks
    calls = run()
    cache = Path(calls["table1"]["cache_dir"])
    assert "cache_dir" not in calls["cell"]
    assert cache == tmp_path / "build" / "figure-cache" / inputs.code_digest(tmp_path / "environment.lock")[:16]
    assert (cache / "table1-result.json").is_file()
    # the manifest's parameters (and the inputs hash) do not depend on where the cache is
    entry = json.loads((tmp_path / "figures" / "table1.json").read_text())
    assert "cache_dir" not in entry["parameters"]
    assert run() == {}  # up to date: nothing runs, the cache is kept
    assert (cache / "table1-result.json").is_file()
    (cache / "other-result.json").write_text("{}")
    calls = run(force=True)
    assert Path(calls["table1"]["cache_dir"]) == cache
    assert not (cache / "other-result.json").exists()  # --force starts the version empty


def test_dedupe_computes_equal_keys_once(tmp_path):
    CALLS.clear()
    jobs = trial_jobs(PLAN, 2, 0, Perturbations()) * 2
    results = sweep.run_sweep(counted, jobs, None, None, trial_key, progress=False,
                              dedupe=True)
    assert len(CALLS) == 2 and results[:2] == results[2:]
    CALLS.clear()
    sweep.run_sweep(counted, jobs, None, None, trial_key, progress=False)
    assert len(CALLS) == 4  # without dedupe every item runs


def test_a_sensitivity_setting_at_the_nominal_value_runs_the_nominal_jobs(monkeypatch):
    from flipkit.config import CellConfig, PHYSICAL_RANGES
    from flipkit.experiments import sensitivity

    seen = []

    def fake_sweep(fn, jobs, *args, **kwargs):
        seen.extend(jobs)
        assert kwargs["dedupe"] is True
        return [{"trial": j["trial"], "ok": dict.fromkeys(("scoop", "pickup", "flip"), True),
                 "failure": None} for j in jobs]

    class FakePlan:
        @staticmethod
        def cell():
            return CellConfig()

    monkeypatch.setattr(sensitivity, "run_sweep", fake_sweep)
    monkeypatch.setattr(sensitivity, "plan_from_text", lambda text: FakePlan)
    rate = PHYSICAL_RANGES["physics.servo_rate_hz"]
    assert rate[0] == CellConfig().physics.servo_rate_hz  # the CB-series rate is nominal
    out = sensitivity.run_sensitivity([PLAN], 1, ["physics.servo_rate_hz"], mode="position")
    physics = [j.get("physics") for j in seen]
    assert physics == [None, None, {"physics.servo_rate_hz": rate[1]}]
    assert out["parameters"]["physics.servo_rate_hz"]["low"]["value"] == rate[0]
    assert out["parameters"]["physics.servo_rate_hz"]["low"]["trials"] == 1
