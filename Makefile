# urdftool: `make check` runs the validator on robots/, `make test` runs the test suite.
# Both create the virtual environment and install what they need: `check` the package with its
# extras (`.[all]`), `test` the test bench on top (`.[test]`: pytest, the oracles, linters).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
# one stamp per install, so that `make check` then `make test` adds the test bench
MAIN_STAMP := $(VENV)/.installed-main
TEST_STAMP := $(VENV)/.installed
# `make test`: the suite that runs in minutes; `make test-slow`: the tests marked `slow` (scale,
# attack and oracle suites; CI runs both: .ci/run)
# Bytecode: the tests start urdftool in thousands of processes (the CLI, the sandboxed reader, the
# language server). Where PYTHONDONTWRITEBYTECODE is set (CI images often set it) each would compile
# urdftool's modules anew (about 0.2 s a process) and every pytest worker would rewrite the asserts
# of every test module: the suite compiles urdftool once and lets pytest keep its rewritten modules.
# --dist worksteal: a worker that runs out of tests takes some of the other's (long tests at the end).
# `make test` runs three workers on two cores: a good part of its tests wait (on a language server,
# a child process, a deadline), and a third worker fills that time (143-159 s against 152-169 s
# with two, idle machine); the slow suites' big inputs keep two.
PYTEST := env -u PYTHONDONTWRITEBYTECODE $(BIN)/python -m pytest -q --dist worksteal
TEST_WORKERS ?= 3
COMPILE := $(BIN)/python -m compileall -q urdftool

.PHONY: check test test-slow test-all fuzz bench lint clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip

$(MAIN_STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/pip install --quiet -e '.[all]'
	touch $@

$(TEST_STAMP): pyproject.toml $(MAIN_STAMP)
	$(BIN)/pip install --quiet -e '.[test]'
	touch $@

# The as-published seed robots must show their defects (exit 1); the corrected copies must pass
# with no errors and no warnings (--strict).
check: $(MAIN_STAMP)
	@echo "== as published (defects expected) =="
	@$(BIN)/urdftool check robots/*/published; rc=$$?; \
	  if [ $$rc -ne 1 ]; then echo "expected exit 1 from the published robots, got $$rc"; exit 1; fi
	@echo "== corrected (must be clean) =="
	@$(BIN)/urdftool check --strict robots/*/corrected

test: $(TEST_STAMP)
	$(COMPILE)
	$(PYTEST) -n $(TEST_WORKERS) -m "not slow"

# exit 5 (no test collected) fails: an empty slow set means the marker was lost
test-slow: $(TEST_STAMP)
	$(COMPILE)
	$(PYTEST) -n 2 -m slow

test-all: $(TEST_STAMP)
	$(COMPILE)
	$(PYTEST) -n 2

fuzz: $(TEST_STAMP)
	$(BIN)/python -m urdftool.fuzz --cases 10000
	URDFTOOL_FUZZ_EXAMPLES=3000 $(BIN)/python -m pytest -q tests/test_xacro_eval_fuzz.py

bench: $(TEST_STAMP)
	$(BIN)/python benchmarks/bench_check.py

lint: $(TEST_STAMP)
	$(BIN)/ruff check urdftool tests benchmarks

clean:
	rm -rf $(VENV) .pytest_cache
