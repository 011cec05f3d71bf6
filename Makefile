# The two commands a student or instructor needs are `make lab` and `make test`.
# Both create .venv on first use and re-install only when pyproject.toml or
# constraints.txt changed, so a second run starts at once.

PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
# Exact versions CI tested (Python 3.11; they need 3.11 or newer). Run `make CONSTRAINTS= test`
# to ignore them and install the newest versions pyproject.toml's ranges allow (e.g. on 3.10).
CONSTRAINTS ?= constraints.txt
CONSTRAINT_FLAG := $(if $(CONSTRAINTS),-c $(CONSTRAINTS),)
STAMP := $(VENV)/.installed
PYTEST_ARGS ?=

.PHONY: lab test lint notebooks handouts student bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml $(CONSTRAINTS) | $(BIN)/python
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet $(CONSTRAINT_FLAG) -e '.[test]'
	touch $(STAMP)

lab: $(STAMP)
	$(BIN)/jupyter lab notebooks/

lint: $(STAMP)
	$(BIN)/ruff check lqe_helpers tests benchmarks notebooks

# Every test: ruff, the unit tests, nbval over every notebook and the browser tests
# (skipped with a reason where no Chromium is installed).
test: $(STAMP) lint
	$(BIN)/python -m pytest tests --nbval notebooks --nbval-current-env $(PYTEST_ARGS)

# Re-execute every notebook in a fresh kernel and save it with its outputs (for authors).
notebooks: $(STAMP)
	$(BIN)/python -m lqe_helpers.authoring.notebook_runner notebooks/*.ipynb

# HTML handouts in build/handouts/ (index.html; prose/ without code), executed afresh.
handouts: $(STAMP)
	$(BIN)/python -m lqe_helpers.authoring.handouts --source notebooks --out build/handouts

# Student edition in build/student/: solutions replaced by stubs, answers by prompts.
student: $(STAMP)
	$(BIN)/python -m lqe_helpers.authoring.student_edition --source notebooks --out build/student

# Speed against a peer in the same process (ratios, not pass/fail): filter and sliders.
bench: $(STAMP)
	$(BIN)/python benchmarks/bench_filter.py
	$(BIN)/python benchmarks/bench_widgets.py
	$(BIN)/python benchmarks/bench_notebooks.py

clean:
	rm -rf $(VENV) build .pytest_cache .ruff_cache .hypothesis lqe_course_pack.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
