# ddwmmr: two commands set everything up on a fresh machine with python3 and make.
#   make demo   creates .venv, installs the package (runtime dependencies only), runs the
#               main job (writes runs/demo/)
#   make test   creates .venv, installs with the test extras, runs the suite
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
# Two install stamps: the demo needs only the runtime dependencies; test, lint and docs
# need the test extras (pytest, ruff, hypothesis, the optional QP backends, dask).
STAMP_RUN := $(VENV)/.installed-run
STAMP_TEST := $(VENV)/.installed-test

.PHONY: demo test lint format bench docs docs-timings clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP_RUN): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e .
	touch $(STAMP_RUN)

$(STAMP_TEST): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP_TEST) $(STAMP_RUN)

demo: $(STAMP_RUN)
	MPLBACKEND=Agg $(BIN)/python -m ddwmmr.compare --out runs/demo

test: $(STAMP_TEST)
	MPLBACKEND=Agg $(BIN)/python -m pytest

lint: $(STAMP_TEST)
	$(BIN)/ruff check src tests examples docs/*.py
	$(BIN)/ruff format --check src tests examples docs/*.py

format: $(STAMP_TEST)
	$(BIN)/ruff format src tests examples docs/*.py
	$(BIN)/ruff check --fix src tests examples docs/*.py

bench: $(STAMP_RUN)
	$(BIN)/python -m ddwmmr.bench

# Regenerates docs/figures byte for byte (no time stamps, no wall-clock content).
docs: $(STAMP_TEST)
	MPLBACKEND=Agg $(BIN)/python docs/make_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/qp_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/make_run_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/physics_figures.py

# The figures of measured step times (machine-dependent: they change on every run).
docs-timings: $(STAMP_TEST)
	MPLBACKEND=Agg $(BIN)/python docs/qp_figures.py --timings

clean:
	rm -rf $(VENV) runs .pytest_cache .ruff_cache

# Real Tk window of python -m ddwmmr.gui under a virtual X display: clicks Run, types into a
# field, plays the run back, saves a screenshot to runs/gui-check/. Needs xvfb-run.
.PHONY: gui-check
gui-check: $(STAMP)
	@if command -v xvfb-run >/dev/null 2>&1; then \
		xvfb-run -a -s "-screen 0 1920x1080x24" $(BIN)/python -m ddwmmr.gui.check runs/gui-check; \
	else \
		echo "gui-check skipped: xvfb-run is not installed (Debian/Ubuntu: apt install xvfb)."; \
		echo "The window is still tested headless (Agg) by tests/test_gui*.py in make test."; \
	fi
