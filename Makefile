# cerebx — `make run` and `make test` work on a fresh machine: they create .venv and install first.
SHELL := /bin/bash
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
DOCS_STAMP := $(VENV)/.docs-stamp
SLURM_STAMP := $(VENV)/.slurm-stamp
# kernels compiled for 256-bit vectors (CEREBX_VECTOR_BITS=256, docs/guide/speed.md#wide-vectors) are cached apart,
# as cerebx.jobenv does
export NUMBA_CACHE_DIR ?= $(CURDIR)/.cache/numba$(if $(filter 256,$(CEREBX_VECTOR_BITS)),-256,)
export CEREBX_CACHE ?= $(CURDIR)/.cache/cerebx

# The default experiment of `make run`; override e.g. `make run RUN_ARGS="+task=eight delay=gamma45"`.
RUN_ARGS ?= +experiment=default
BENCH_ARGS ?=
# `make report` runs the report's missing studies with this profile (quick: < 30 min on 2 cores;
# full: the thesis's trial counts, hours), then draws every figure. REPORT_ARGS e.g. "--figures fig3_4".
PROFILE ?= quick
REPORT_ARGS ?=
# `make test` spreads the tests over this many worker processes (pytest-xdist; 0: all in one process)
TEST_WORKERS ?= 2

.PHONY: help install run test test-unit test-slow test-full bench report lint docs format clean

help: ## list the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | awk -F':.*## ' '{printf "  %-10s %s\n", $$1, $$2}'

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e ".[test]"
	touch $(STAMP)

$(DOCS_STAMP): $(STAMP) pyproject.toml
	$(BIN)/pip install --quiet -e ".[test,docs]"
	touch $(DOCS_STAMP)

# the slow tests include a sweep through a local SLURM (scripts/slurm_local.sh brings one up as root with apt;
# without either, that test skips and says why)
$(SLURM_STAMP): $(STAMP) pyproject.toml
	$(BIN)/pip install --quiet -e ".[test,slurm]"
	touch $(SLURM_STAMP)

install: $(STAMP) ## create .venv and install cerebx with its test tools

run: $(STAMP) ## run the default experiment (RUN_ARGS=... to choose another)
	$(BIN)/cerebx run $(RUN_ARGS)

# tests/warm.py first compiles the kernels and solves the task paths the tests share, each once, on every core
# (on a fresh clone the workers would otherwise compile the same kernels side by side)
# (bytecode written even where the environment says not to: each process the tests start that imports cerebx would
# compile its modules again without it, and pytest would rewrite every test module's asserts again)
# (the 15 slowest tests listed at the end: where the five minutes go)
test: $(STAMP) ## unit and integration tests, not the slow ones (under 5 minutes on 2 cores)
	PYTHONDONTWRITEBYTECODE= $(BIN)/python tests/warm.py
	PYTHONDONTWRITEBYTECODE= $(BIN)/pytest -m "not slow" -n $(TEST_WORKERS) --durations=15

test-unit: $(STAMP) ## only the unit tests (seconds)
	$(BIN)/pytest -m unit

test-slow: $(SLURM_STAMP) ## only the slow tests (what test-full adds to test)
	$(BIN)/pytest -m slow

test-full: $(SLURM_STAMP) ## every test, including the slow ones
	$(BIN)/pytest

bench: $(STAMP) ## speed of plant, network and closed loop, as JSON
	$(BIN)/cerebx bench $(BENCH_ARGS)

report: $(STAMP) ## run missing studies (PROFILE=quick|full), then build reports/index.html
	$(BIN)/cerebx report --profile $(PROFILE) $(REPORT_ARGS)

lint: $(STAMP) ## ruff, and the import contracts of pyproject.toml (the layering: core, schema, papers)
	$(BIN)/ruff check src tests
	PYTHONPATH=examples/my_lab:examples/my_cerebellum $(BIN)/lint-imports --no-cache

docs: $(DOCS_STAMP) ## build the docs site into site/ (strict: a broken link or reference fails the build)
	DISABLE_MKDOCS_2_WARNING=true NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir site

format: $(STAMP) ## ruff format
	$(BIN)/ruff format src tests

clean: ## remove caches (keeps .venv and runs/)
	rm -rf .cache .pytest_cache .ruff_cache build dist site src/*.egg-info
	find . -name __pycache__ -type d -prune -not -path './.venv/*' -exec rm -rf {} +
