# Two commands on a fresh machine (Python 3.11 and pip): `make run` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: setup run test lint typecheck bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

setup: $(STAMP)

## The main job: the lab's four cases, run non-interactively.
run: $(STAMP)
	$(BIN)/collisionlab demo

lint: $(STAMP)
	$(BIN)/ruff check src tests bench
	$(BIN)/mypy

## Lint, type-check and the whole test suite (the browser test needs Debian's chromium: installed here).
test: lint
	bash tests/setup_browser.sh
	$(BIN)/python -m pytest

bench: $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[bench]'
	$(BIN)/python bench/bench_gas.py

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache .hypothesis
