"""The core installs and works alone: ``pip install .`` without extras into a fresh venv, then
``flipkit plan flip``, ``verify`` and ``export`` there (the README's commands), and a command
that needs an extra says which.

The venv is made from this Python; pip installs the core's dependencies at the versions of
``environment.lock`` (as constraints: the lock's hashes are for the full set), from PyPI.
No extra's package may arrive with them (MeshCat does: placo requires it).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import flipkit
from flipkit.extras import EXTRAS

REPO = Path(flipkit.__file__).resolve().parents[1]
# Extras' packages that a core dependency installs anyway: placo requires meshcat (which
# brings Pillow, the GIF writer, too).
BROUGHT_BY_THE_CORE = {"meshcat"}

pytestmark = pytest.mark.slow


def lock_pins(lock: Path) -> str:
    """``name==version`` of every package of a ``--generate-hashes`` lock, one a line."""
    pins = re.findall(r"^([A-Za-z0-9][A-Za-z0-9._-]*)(?:\[[^\]]*\])?==([^\s\\;]+)",
                      lock.read_text(), re.M)
    return "".join(f"{name}=={version}\n" for name, version in pins)


def test_lock_pins_read_every_package_without_its_hashes(tmp_path):
    lock = tmp_path / "l.txt"
    lock.write_text("dask[distributed]==2026.8.0 \\\n    --hash=sha256:ab\n    # via x\n"
                    "pin==3.8.0 \\\n    --hash=sha256:cd\n")
    assert lock_pins(lock) == "dask==2026.8.0\npin==3.8.0\n"
    assert "pin==3.8.0\n" in lock_pins(REPO / "environment.lock")


def run(argv, cwd, env, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=timeout)


def test_the_core_alone_plans_verifies_and_exports_a_flip(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, src / name)
    shutil.copytree(REPO / "flipkit", src / "flipkit",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    constraints = tmp_path / "constraints.txt"
    constraints.write_text(lock_pins(REPO / "environment.lock"))
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env["MPLBACKEND"] = "Agg"

    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=120)
    python, flipkit_bin = venv / "bin" / "python", venv / "bin" / "flipkit"
    # --no-compile: the commands below compile the few modules they import, not all of scipy
    pip = run([str(python), "-m", "pip", "install", "-q", "--no-compile", "-c", str(constraints),
               str(src)], tmp_path, env, timeout=600)
    assert pip.returncode == 0, pip.stderr[-3000:]

    probe = run([str(python), "-c",
                 "import importlib.util as u, sys, flipkit; print(flipkit.__file__); "
                 "print(' '.join(n for n in sys.argv[1:] if u.find_spec(n)))",
                 *sorted({n for names in EXTRAS.values() for n in names})], tmp_path, env)
    assert probe.returncode == 0, probe.stderr
    where, present = probe.stdout.splitlines()
    assert Path(where).is_relative_to(venv)  # the installed copy, not the checkout
    assert set(present.split()) <= BROUGHT_BY_THE_CORE, present

    work = tmp_path / "work"
    work.mkdir()
    plan = run([str(flipkit_bin), "plan", "flip", "--burger", "0.69", "-0.16", "0.072",
                "--json", "f.json"], work, env)
    assert plan.returncode == 0, plan.stdout + plan.stderr
    assert "flipkit plan: flip solved" in plan.stdout
    verify = run([str(flipkit_bin), "verify", "f.json"], work, env)
    assert verify.returncode == 0, verify.stdout + verify.stderr
    assert "flipkit verify:" in verify.stdout
    export = run([str(flipkit_bin), "export", "f.json", "--format", "urscript", "--out",
                  "f.script"], work, env)
    assert export.returncode == 0, export.stdout + export.stderr
    assert "servoj(" in (work / "f.script").read_text()

    animate = run([str(flipkit_bin), "animate", "f.json", "--out", "f.gif"], work, env)
    assert animate.returncode == 1
    lines = animate.stderr.strip().splitlines()
    assert len(lines) == 1 and re.fullmatch(
        r"flipkit: error: flipkit animate needs the 'sim' extra \(no module named "
        r"'(mujoco|matplotlib)'\): pip install 'flipkit\[sim\]'", lines[0]), lines
    assert not (work / "f.gif").exists()
