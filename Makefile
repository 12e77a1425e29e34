# flipkit: `make test` and `make figures` set everything up themselves on a fresh machine.
SHELL := /bin/bash
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.flipkit-installed
APT_PACKAGES := libosmesa6 chromium
export MPLBACKEND := Agg
export OMP_NUM_THREADS := 1

.PHONY: test figures figures-quick lab paper bench venv lock clean

venv: $(STAMP)

$(STAMP): environment.lock pyproject.toml
	@if [ -n "$(APT_PACKAGES)" ]; then \
	  missing=$$(for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || echo $$p; done); \
	  if [ -n "$$missing" ]; then apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; fi; fi
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --disable-pip-version-check --require-hashes -r environment.lock
	$(PY) -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation -e .
	@touch $(STAMP)

test: $(STAMP)
	$(PY) -m pytest -n 2 -q

# Only notebooks whose inputs changed run (flipkit.figures.inputs); FIGURES_ARGS=--force runs all.
figures: $(STAMP)
	$(VENV)/bin/flipkit figures $(FIGURES_ARGS)

figures-quick: $(STAMP)
	$(VENV)/bin/flipkit figures --quick $(FIGURES_ARGS)

# JupyterLab on notebooks/ with this venv's kernel, registered as "Python 3 (flipkit)"
# (--allow-root in a root container); e.g. LAB_ARGS="--no-browser --port 8890".
lab: $(STAMP)
	$(PY) -m ipykernel install --sys-prefix --name flipkit-python3 --display-name "Python 3 (flipkit)"
	$(VENV)/bin/jupyter lab --notebook-dir=notebooks $$([ "$$(id -u)" = 0 ] && echo --allow-root) $(LAB_ARGS)

# The reproduction report: LaTeX (installed with apt-get if latexmk is missing), the number
# macros regenerated from figures/manifest.json, then latexmk in paper/.
paper: $(STAMP)
	@command -v latexmk >/dev/null 2>&1 || { apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
	  latexmk texlive-latex-recommended texlive-latex-extra; }
	@test -f figures/manifest.json || { echo "make paper: no figures/manifest.json; run make figures first" >&2; exit 1; }
	$(PY) -c "from flipkit.figures import write_macros; write_macros('figures/manifest.json', 'paper/numbers.tex')"
	cd paper && latexmk -pdf -interaction=nonstopmode -halt-on-error main.tex

bench: $(STAMP)
	$(PY) -m bench.bench translate

# Regenerate the lock from requirements.in (needs uv: pip install uv).
lock:
	uv pip compile requirements.in --python-version 3.11 --generate-hashes -o environment.lock

clean:
	rm -rf build figures/*.pdf figures/*.png figures/manifest.json
