# Shortcuts for tasks.py, which needs only Python 3.11 and pip: `make run` = `python3 tasks.py run`.
PYTHON ?= python3

.PHONY: run test bench clean

## The main job: the lab's four cases, run non-interactively.
run:
	$(PYTHON) tasks.py run

## Lint, type-check and the whole test suite (installs Debian's chromium for the browser test).
test:
	$(PYTHON) tasks.py test

bench:
	$(PYTHON) tasks.py bench

clean:
	rm -rf .venv .pytest_cache .mypy_cache .ruff_cache .hypothesis
