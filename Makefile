# urdftool: `make check` runs the validator on robots/, `make test` runs the test suite.
# Both create the virtual environment and install everything they need.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: check test fuzz bench lint clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[test]'
	touch $(STAMP)

# The as-published seed robots must show their defects (exit 1); the corrected copies must pass
# with no errors and no warnings (--strict).
check: $(STAMP)
	@echo "== as published (defects expected) =="
	@$(BIN)/urdftool check robots/*/published; rc=$$?; \
	  if [ $$rc -ne 1 ]; then echo "expected exit 1 from the published robots, got $$rc"; exit 1; fi
	@echo "== corrected (must be clean) =="
	@$(BIN)/urdftool check --strict robots/*/corrected

test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2

fuzz: $(STAMP)
	$(BIN)/python -m urdftool.cli.fuzz --cases 10000
	URDFTOOL_FUZZ_EXAMPLES=3000 $(BIN)/python -m pytest -q tests/test_xacro_eval_fuzz.py

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_check.py

lint: $(STAMP)
	$(BIN)/ruff check urdftool tests benchmarks

clean:
	rm -rf $(VENV) .pytest_cache
