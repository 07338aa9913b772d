# ddwmmr: two commands set everything up on a fresh machine with python3 and make.
#   make demo   creates .venv, installs the package (runtime dependencies only), runs the
#               main job (writes runs/demo/)
#   make test   creates .venv, installs with the test extras, runs the suite
#   make lint   ruff check, ruff format --check, mypy on the user's view of the API and
#               mypy --strict on the whole package (CI runs make lint test docs-site)
#   make docs-site  the HTML documentation site in site/ (MkDocs, strict; the docs extra)
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
# Two install stamps: the demo needs only the runtime dependencies; test, lint and docs
# need the test extras (pytest, ruff, hypothesis, the optional QP backends, dask).
STAMP_RUN := $(VENV)/.installed-run
STAMP_TEST := $(VENV)/.installed-test

.PHONY: demo test lint format bench docs docs-site docs-timings clean gui-check

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

# Worker processes of the test suite (pytest-xdist): the machine class has 2 cores.
TEST_JOBS ?= 2

test: $(STAMP_TEST)
	MPLBACKEND=Agg $(BIN)/python -m pytest -n $(TEST_JOBS)

LINTED := src tests examples benchmarks docs/*.py

# What a user's type checker sees (the package ships py.typed): the examples and a script
# using the public API as docs/api.md teaches it, strict; --follow-imports=silent checks
# them against the package's hints without reporting the package's own code (cache in
# .venv). About 6 s cold, under 1 s warm.
USER_TYPED := examples tests/typecheck/user_api.py
# The whole package, strict on its own code (same flags and cache).
STRICT_CORE := src/ddwmmr

lint: $(STAMP_TEST)
	$(BIN)/ruff check $(LINTED)
	$(BIN)/ruff format --check $(LINTED)
	$(BIN)/mypy --strict --follow-imports=silent --cache-dir $(VENV)/.mypy_cache $(USER_TYPED)
	$(BIN)/mypy --strict --follow-imports=silent --cache-dir $(VENV)/.mypy_cache $(STRICT_CORE)

format: $(STAMP_TEST)
	$(BIN)/ruff format $(LINTED)
	$(BIN)/ruff check --fix $(LINTED)

# The benchmark with its reference row (roboticstoolbox-python, the bench extra); writes
# benchmarks/bench.json and regenerates the tables of docs/api.md and docs/qp.md from it.
STAMP_BENCH := $(VENV)/.installed-bench

$(STAMP_BENCH): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[bench]"
	touch $(STAMP_BENCH) $(STAMP_RUN)

bench: $(STAMP_BENCH)
	$(BIN)/python -m ddwmmr.bench --out benchmarks/bench.json
	$(BIN)/python benchmarks/bench_docs.py benchmarks/bench.json

# Regenerates docs/figures byte for byte (no time stamps, no wall-clock content).
docs: $(STAMP_TEST)
	MPLBACKEND=Agg $(BIN)/python docs/make_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/qp_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/make_run_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/physics_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/support_loads.py validate plot
	MPLBACKEND=Agg $(BIN)/python -m ddwmmr.gui --force --snapshot docs/figures/gui_qp_obstacle.png \
		--method qp --payload 3 --option obstacles=trajectories/obstacles/ellipse_post.toml \
		--compare clrrmc-ts --traj ellipse
	MPLBACKEND=Agg $(BIN)/python -m ddwmmr.gui --force --snapshot docs/figures/gui_figure8.png \
		--method clrrmc-cs --traj figure8 --beta 0.5 --x0 0.5 --T 80 --N 4000 --compare ap
	MPLBACKEND=Agg $(BIN)/python -m ddwmmr.gui --force --snapshot docs/figures/gui_rectangle.png \
		--method clrrmc-ts --traj rectangle
	MPLBACKEND=Agg $(BIN)/python docs/competitive_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/bounds_figures.py

# The documentation site: docs/*.md plus the API reference generated from the docstrings
# (mkdocs.yml), built into site/ in strict mode (a broken link or anchor fails the build).
STAMP_DOCS := $(VENV)/.installed-docs

$(STAMP_DOCS): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	touch $(STAMP_DOCS) $(STAMP_RUN)

docs-site: $(STAMP_DOCS)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

# The figures of measured step times (machine-dependent: they change on every run), and the
# MPC's figures (its horizon study plots step times; about 10 minutes).
docs-timings: $(STAMP_TEST)
	MPLBACKEND=Agg $(BIN)/python docs/qp_figures.py --timings
	MPLBACKEND=Agg $(BIN)/python docs/mpc_figures.py

clean:
	rm -rf $(VENV) runs site .pytest_cache .ruff_cache

# Real Tk window of python -m ddwmmr.gui under a virtual X display: clicks Run, types into a
# field, plays the run back, saves a screenshot to runs/gui-check/. Needs xvfb-run.
gui-check: $(STAMP_RUN)
	@if command -v xvfb-run >/dev/null 2>&1; then \
		xvfb-run -a -s "-screen 0 1920x1080x24" $(BIN)/python -m ddwmmr.gui.check runs/gui-check; \
	else \
		echo "gui-check skipped: xvfb-run is not installed (Debian/Ubuntu: apt install xvfb)."; \
		echo "The window is still tested headless (Agg) by tests/test_gui*.py in make test."; \
	fi
