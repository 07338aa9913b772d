# ddwmmr: two commands set everything up on a fresh machine with python3 and make.
#   make demo   creates .venv, installs, runs the main job (writes runs/demo/)
#   make test   creates .venv, installs with test extras, runs the suite
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint format bench docs clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m ddwmmr.compare --out runs/demo

test: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest

lint: $(STAMP)
	$(BIN)/ruff check src tests examples docs/*.py
	$(BIN)/ruff format --check src tests examples docs/*.py

format: $(STAMP)
	$(BIN)/ruff format src tests examples docs/*.py
	$(BIN)/ruff check --fix src tests examples docs/*.py

bench: $(STAMP)
	$(BIN)/python -m ddwmmr.bench

docs: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python docs/make_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/qp_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/make_run_figures.py
	MPLBACKEND=Agg $(BIN)/python docs/competitive_figures.py

clean:
	rm -rf $(VENV) runs .pytest_cache .ruff_cache
