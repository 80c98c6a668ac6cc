# Two commands on a fresh machine: `make test` and `make bench`.
# Both create (or reuse) .venv and install the project from pyproject.toml.

PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)
SUITE  ?= default
JOBS   ?= 2

# Point the dataset setting at the local copies when they sit beside the repo
# and the user has not chosen a folder already.
ifeq ($(ALBOT1_DATA_DIR),)
ifneq ($(wildcard ../shared/datasets/README.md),)
export ALBOT1_DATA_DIR := $(abspath ../shared/datasets)
endif
endif
export MPLBACKEND := Agg

.PHONY: venv test test-fast bench bench-timing lint wheel-check clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	rm -f $(VENV)/.installed-*
	touch $@

test: $(STAMP)
	$(BIN)/python -m pytest -q

bench: $(STAMP)
	$(BIN)/albot1 bench $(SUITE) -j $(JOBS)
	$(BIN)/albot1 report results/$(SUITE)

# pytest-benchmark timing suite (short real sequences); JSON kept for CI.
bench-timing: $(STAMP)
	$(BIN)/python -m pytest benchmarks -q --benchmark-only --benchmark-json=reports/timing.json

# Static checks: style (ruff), types (mypy, config in pyproject.toml) and the
# import layers of docs/architecture.md (import-linter).
lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy
	$(BIN)/lint-imports

# Build the wheel, install it with its dependencies into a fresh venv outside
# the clone and run the CLI from there (.ci/wheel-check).
wheel-check:
	PYTHON=$(PYTHON) .ci/wheel-check

clean:
	rm -rf $(VENV) .pytest_cache .benchmarks build dist
