# Two commands on a fresh machine: `make test` and `make bench`.
# Both create (or reuse) .venv and install the project from pyproject.toml.

PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)
# `make bench` runs the three suites (the thesis page reads the default suite's results; generalisation: issue 21); SUITE=NAME runs one.
SUITE  ?= default thesis generalisation
JOBS   ?= 2
TEST_JOBS ?= auto

# Point the dataset setting at the local copies when they sit beside the repo
# and the user has not chosen a folder already.
ifeq ($(ALBOT1_DATA_DIR),)
ifneq ($(wildcard ../shared/datasets/README.md),)
export ALBOT1_DATA_DIR := $(abspath ../shared/datasets)
endif
endif
export MPLBACKEND := Agg

.PHONY: venv test test-whole-log test-end-to-end test-compile test-all test-fast bench bench-timing lint wheel-check clean mrpt chromium

venv: $(STAMP)

# The project is installed by uv (itself installed from PyPI into the venv): the same versions as pip picks
# for pyproject.toml, in ~12 s instead of pip's ~32 s (docs/benchmarking.md, "Installing"). Like pip, it
# compiles the bytecode at install (--compile-bytecode): with PYTHONDONTWRITEBYTECODE set, as on this machine,
# no process would ever write it, and each would compile every module it imports again. uv reads neither
# pip.conf nor pip's find-links, so where it cannot be installed or cannot reach its index the install falls
# back to pip, saying so; INSTALLER=pip chooses pip from the start (e.g. behind a private index).
INSTALLER ?= uv
# uv's own version is pinned (the one measured in docs/benchmarking.md, "Installing"), so that how the venv was
# made does not change under a fresh clone; the project's dependencies are resolved from pyproject.toml as before.
UV_VERSION ?= 0.13.9
# After installing, `albot1 warm-up` compiles Albot1's numba kernels for this machine and code version (~20 CPU-s,
# 20-30 s on 2 loaded cores), as pip compiles bytecode at install: the first run after an install then loads them
# from numba's cache instead of compiling them (docs/albot1-mapper.md, "Kernels"). WARM_UP=0 leaves that to the
# first run (make also reads WARM_UP from the environment; only 0 and 1 are accepted). A failed warm-up does not
# fail the install: it says so, and the tests then show which kernel fails and why.
WARM_UP ?= 1
$(STAMP): pyproject.toml
	@case "$(INSTALLER)" in uv|pip) ;; *) echo "make venv: INSTALLER=$(INSTALLER): expected uv or pip" >&2; exit 2;; esac
	@case "$(WARM_UP)" in 0|1) ;; *) echo "make venv: WARM_UP=$(WARM_UP): expected 1 (compile the kernels) or 0" >&2; exit 2;; esac
	@# A venv whose creation was interrupted (no pip in it) is made again, not reused half-built.
	if ! $(BIN)/python -m pip --version >/dev/null 2>&1; then \
	  if [ -e $(VENV) ]; then echo "make venv: $(VENV) has no working python with pip (an interrupted creation?); making it again" >&2; fi; \
	  rm -rf $(VENV) && $(PYTHON) -m venv $(VENV); \
	fi
	if [ "$(INSTALLER)" = uv ] && $(BIN)/python -m pip install --quiet 'uv==$(UV_VERSION)' \
	    && $(BIN)/uv pip install --quiet --compile-bytecode --python $(BIN)/python -e '.[dev]'; then :; else \
	  [ "$(INSTALLER)" = uv ] && echo "make venv: uv could not install the project; installing with pip" >&2; \
	  $(BIN)/python -m pip install --quiet --upgrade pip && $(BIN)/python -m pip install --quiet -e '.[dev]'; \
	fi
	rm -f $(VENV)/.installed-*
	touch $@
	@if [ "$(WARM_UP)" = 1 ]; then $(BIN)/albot1 warm-up \
	  || echo "make venv: NOTICE: albot1 warm-up failed (above); the first run will compile its kernels itself" >&2; fi

# Every test but three lanes (unit, property, integration on the public logs when ALBOT1_DATA_DIR has them, on
# slices), spread over TEST_JOBS worker processes (pytest-xdist; auto = one per core).
# `make test-whole-log` runs the tests marked `whole_log` (a whole public log or synthetic world run for quality,
# parity or scale, tens of seconds each: docs/benchmarking.md, "The whole-log lane"); `make test-end-to-end` the
# tests marked `end_to_end` (the `albot1 bench` command run end to end: grids in worker processes or a Dask cluster,
# faults injected, reports built; seconds to a minute each: "The end-to-end lane"); `make test-compile` the tests
# marked `compile` (the numba kernels compiled cold, cached, bundled into a wheel or switched off, in fresh processes;
# ten to thirty seconds each: "The compile lane"). CI runs all four (.ci/run), `make test-all` them all in one session.
# --dist loadscope: a worker that is nearly done is handed the next module (whole: its module fixtures are
# built once) in conftest.py's order, longest first by tests/durations.json, so the modules of the whole-log
# tests start at once and the short ones fill the gaps at the end; docs/benchmarking.md has the times.
# Bytecode is written (PYTHONDONTWRITEBYTECODE dropped) so that a second run reuses the assertion-rewritten
# test modules and the compiled package instead of compiling ~300 modules again in every worker.
XDIST := -n $(TEST_JOBS) --dist loadscope --no-loadscope-reorder
test: $(STAMP)
	env -u PYTHONDONTWRITEBYTECODE $(BIN)/python -m pytest -q $(XDIST) -m "not whole_log and not end_to_end and not compile"

test-whole-log: $(STAMP)
	env -u PYTHONDONTWRITEBYTECODE $(BIN)/python -m pytest -q $(XDIST) -m whole_log

test-end-to-end: $(STAMP)
	env -u PYTHONDONTWRITEBYTECODE $(BIN)/python -m pytest -q $(XDIST) -m "end_to_end and not whole_log"

test-compile: $(STAMP)
	env -u PYTHONDONTWRITEBYTECODE $(BIN)/python -m pytest -q $(XDIST) -m "compile and not whole_log and not end_to_end"

test-all: $(STAMP)
	env -u PYTHONDONTWRITEBYTECODE $(BIN)/python -m pytest -q $(XDIST)

# The edit-test loop (docs/benchmarking.md, "Session 23, test-fast"): unit and property tests without the slow ones
# and without the public logs (marked `integration`; conftest.py marks every test that takes `data_file`). Slow is
# measured: conftest.py marks `slow` every test tests/durations.json lists (1 s or more in the recorded run) besides
# the hand-set marks, so new tests start in the lane. The hypothesis profile `fast` (conftest.py) keeps every
# property test but runs each with at most 10 examples. `make test` and CI run every one of these tests with its
# own example count; `make test-all` runs them all.
test-fast: $(STAMP)
	env -u PYTHONDONTWRITEBYTECODE $(BIN)/python -m pytest -q $(XDIST) -m "not slow and not integration and not compile" --hypothesis-profile=fast tests/unit tests/property

# The suites' grids run one after the other; each suite's report starts as soon as its own grid has ended (it
# runs beside the next grid), the results page as soon as results/default and results/thesis are final
# (.ci/bench has the schedule and why), at niceness REPORT_NICE (10: they take the cores the grid's cells
# leave idle; 0 runs them at the grids' priority). Every report is built even when cells failed (the reports list them);
# each one's output is held in a temporary file and shown whole, in order, as it ends; then a non-zero status
# (the last one: the grids', then the reports', then the page's) is passed on. docs/results.md (+ docs/results/)
# and the README's results block are rewritten from results/default and results/thesis (no date in them: nothing
# new, no diff); commit them (docs/benchmarking.md). reports/thesis links the maps figures reports/default draws,
# but which ones those are is known from the default store, so it does not wait for that report.
REPORT_NICE ?= 10
bench: $(STAMP)
	BIN=$(BIN) JOBS=$(JOBS) REPORT_NICE=$(REPORT_NICE) .ci/bench $(SUITE)

# pytest-benchmark timing suite (short real sequences); JSON kept for CI.
bench-timing: $(STAMP)
	$(BIN)/python -m pytest benchmarks -q --benchmark-only --benchmark-json=reports/timing.json

# MRPT's SLAM applications for the mrpt-icp / mrpt-rbpf baselines (docs/baselines.md, MRPT):
# Debian's mrpt-apps (~215 packages, ~35 s to install here), installed only when icp-slam or
# rbpf-slam is missing and apt-get can be used (as root, or with password-less sudo). Otherwise
# one notice and no failure: the two methods are then listed as unavailable and skipped by suites.
MRPT_LOG := $${TMPDIR:-/tmp}/albot1-mrpt-install.log
mrpt:
	@if command -v icp-slam >/dev/null 2>&1 && command -v rbpf-slam >/dev/null 2>&1; then \
	  echo "mrpt: icp-slam and rbpf-slam found in $$(dirname $$(command -v icp-slam))"; \
	elif ! command -v apt-get >/dev/null 2>&1; then \
	  echo "mrpt: NOTICE: icp-slam/rbpf-slam are missing and apt-get is not available; mrpt-icp and mrpt-rbpf will be reported as unavailable"; \
	elif [ "$$(id -u)" != 0 ] && ! sudo -n true >/dev/null 2>&1; then \
	  echo "mrpt: NOTICE: icp-slam/rbpf-slam are missing and installing mrpt-apps needs root (sudo apt-get install mrpt-apps); mrpt-icp and mrpt-rbpf will be reported as unavailable"; \
	else \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo -n"; fi; \
	  start=$$(date +%s); \
	  install="$$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends mrpt-apps"; \
	  if $$install >$(MRPT_LOG) 2>&1 || { $$SUDO apt-get update -q >>$(MRPT_LOG) 2>&1 && $$install >>$(MRPT_LOG) 2>&1; }; then \
	    echo "mrpt: installed mrpt-apps in $$(( $$(date +%s) - start )) s"; \
	  else \
	    echo "mrpt: NOTICE: apt-get could not install mrpt-apps (log: $(MRPT_LOG)); mrpt-icp and mrpt-rbpf will be reported as unavailable"; \
	  fi; \
	fi

# Debian's chromium for the browser test of the HTML report (tests/unit/report/test_report_html.py),
# installed only when missing and apt-get can be used (as root, or with password-less sudo); otherwise
# one notice and no failure: that test is then skipped with its reason.
CHROMIUM_LOG := $${TMPDIR:-/tmp}/albot1-chromium-install.log
chromium:
	@if command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1; then \
	  echo "chromium: found"; \
	elif ! command -v apt-get >/dev/null 2>&1; then \
	  echo "chromium: NOTICE: chromium is missing and apt-get is not available; the HTML report's browser test will be skipped"; \
	elif [ "$$(id -u)" != 0 ] && ! sudo -n true >/dev/null 2>&1; then \
	  echo "chromium: NOTICE: installing chromium needs root (sudo apt-get install chromium); the browser test will be skipped"; \
	else \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo -n"; fi; \
	  install="$$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium"; \
	  if $$install >$(CHROMIUM_LOG) 2>&1 || { $$SUDO apt-get update -q >>$(CHROMIUM_LOG) 2>&1 && $$install >>$(CHROMIUM_LOG) 2>&1; }; then \
	    echo "chromium: installed"; \
	  else \
	    echo "chromium: NOTICE: apt-get could not install chromium (log: $(CHROMIUM_LOG)); the browser test will be skipped"; \
	  fi; \
	fi

# Static checks: style (ruff), types (mypy, config in pyproject.toml) and the
# import layers of docs/architecture.md (import-linter).
# All four run even when one fails, so one pass reports every problem.
lint: $(STAMP)
	@status=0; \
	$(BIN)/ruff check . || status=1; \
	$(BIN)/ruff format --check . || status=1; \
	$(BIN)/mypy || status=1; \
	$(BIN)/lint-imports || status=1; \
	exit $$status

# Build the wheel, install it with its dependencies into a fresh venv outside
# the clone and run the CLI from there (.ci/wheel-check).
wheel-check:
	PYTHON=$(PYTHON) .ci/wheel-check

clean:
	rm -rf $(VENV) .pytest_cache .benchmarks build dist
