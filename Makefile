# The two commands a student or instructor needs are `make lab` and `make test`.
# Both create .venv on first use and re-install only when pyproject.toml or
# constraints.txt changed, so a second run starts at once. `make test-fast` is the
# authors' quick check (no notebook executed, no browser).

PYTHON ?= python3
# The pack's own virtualenv, always .venv here: never taken from the environment or the
# command line, so `make clean` cannot delete another environment.
override VENV := .venv
BIN := $(VENV)/bin
# Exact versions CI tested (Python 3.11; they need 3.11 or newer). Run `make CONSTRAINTS= test`
# to ignore them and install the newest versions pyproject.toml's ranges allow (e.g. on 3.10).
CONSTRAINTS ?= constraints.txt
CONSTRAINT_FLAG := $(if $(CONSTRAINTS),-c $(CONSTRAINTS),)
STAMP := $(VENV)/.installed
PYTEST_ARGS ?=
# A .venv whose Python no longer runs (its base Python removed or upgraded) stops make with
# one clear line instead of "No such file or directory" or "bad interpreter".
CHECK_VENV = if [ -e $(VENV) ] || [ -L $(VENV) ]; then reason=""; \
	if [ -L $(BIN)/python ] && [ ! -e $(BIN)/python ]; then \
	  reason="its Python, $$(readlink $(BIN)/python), no longer exists"; \
	elif [ ! -e $(BIN)/python ]; then reason="$(BIN)/python is missing"; \
	elif ! $(BIN)/python -c "" >/dev/null 2>&1; then reason="$(BIN)/python does not run"; fi; \
	if [ -n "$$reason" ]; then \
	  echo "error: .venv is broken ($$reason); run make clean, then make lab" >&2; exit 1; fi; fi

.PHONY: lab test test-fast lint notebooks handouts student student-pack nbgrader bench \
	bench-browser clean

$(BIN)/python:
	@$(CHECK_VENV)
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml $(CONSTRAINTS) | $(BIN)/python
	@$(CHECK_VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet $(CONSTRAINT_FLAG) -e '.[test]'
	touch $(STAMP)

# make test also runs the grading tests with real nbgrader: it adds the optional extra
# `grading` to the same .venv (make lab and the student pack install only '.[test]').
GRADING_STAMP := $(VENV)/.installed-grading
$(GRADING_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet $(CONSTRAINT_FLAG) -e '.[test,grading]'
	touch $(GRADING_STAMP)

# JupyterLab on notebooks/. As root (a container, a cloud workspace) it adds --allow-root;
# where no browser can open (Linux without $DISPLAY, $WAYLAND_DISPLAY or $BROWSER: ssh,
# headless) it adds --no-browser; it says so in one line each. JupyterLab prints the URL
# with its token. LAB_ARGS passes more options to JupyterLab (e.g. LAB_ARGS=--port=8890).
LAB_ARGS ?=
lab: $(STAMP)
	@$(CHECK_VENV)
	@set --; \
	if [ "$$(id -u)" = 0 ]; then set -- "$$@" --allow-root; \
	  echo "make lab: running as root, so JupyterLab is started with --allow-root"; fi; \
	if [ -z "$$DISPLAY$$WAYLAND_DISPLAY$$BROWSER" ] && [ "$$(uname -s)" != Darwin ]; then \
	  set -- "$$@" --no-browser; \
	  echo "make lab: no browser to open here (no DISPLAY or BROWSER): open the" \
	    "http://127.0.0.1:...?token=... URL that JupyterLab prints below in your browser"; fi; \
	exec $(BIN)/python -m jupyterlab notebooks "$$@" $(LAB_ARGS)

lint: $(STAMP)
	$(BIN)/ruff check lqe_helpers tests benchmarks notebooks

# Every test: ruff, the unit tests, nbval over every notebook and the browser tests
# (skipped with a reason where no Chromium is installed), on every core (pytest-xdist: the
# tests of one file, or of one group of files, run in one worker, in file order; see
# tests/conftest.py; the costly builds are shared, tests/artefacts.py), listing the 15
# slowest at the end. PYTEST_ARGS adds pytest options, and they win: PYTEST_ARGS="-n 0"
# runs in this process (--pdb does so by itself), PYTEST_ARGS=--durations=60 lists more.
PYTEST_PARALLEL := -n logical --dist loadfile --no-loadscope-reorder
test: $(GRADING_STAMP) lint
	$(BIN)/python -m pytest $(PYTEST_PARALLEL) --durations=15 tests --nbval notebooks \
	  --nbval-current-env $(PYTEST_ARGS)

# The authors' quick check, meant to take under a minute: ruff and every test that starts
# no Jupyter kernel and no browser and is not marked slow (no notebook is executed, no make
# lab, no pytest run inside the student pack; `make test` runs everything). Without nbval,
# which it does not use, pytest starts a second sooner.
test-fast: $(STAMP) lint
	$(BIN)/python -m pytest $(PYTEST_PARALLEL) -p no:nbval --durations=10 tests \
	  -m "not kernel and not browser and not slow" $(PYTEST_ARGS)

# Re-execute every notebook in a fresh kernel and save it with its outputs (for authors),
# after writing the given cells' keys and places from the notebooks' code (which execution
# does not change): a changed given cell with a stale key would count as a student's.
notebooks: $(STAMP)
	$(BIN)/python -m lqe_helpers.authoring.given_cells --source notebooks
	$(BIN)/python -m lqe_helpers.authoring.notebook_runner notebooks/*.ipynb

# HTML handouts in build/handouts/ (index.html; prose/ without code), executed afresh.
handouts: $(STAMP)
	$(BIN)/python -m lqe_helpers.authoring.handouts --source notebooks --out build/handouts

# Student edition in build/student/: solutions replaced by stubs, answers by prompts;
# beside it (never in the student pack) the instructor's build/marking-guide/marking-guide.md.
student: $(STAMP)
	$(BIN)/python -m lqe_helpers.authoring.student_edition --source notebooks --out build/student
	$(BIN)/python -m lqe_helpers.authoring.marking_guide --source notebooks --out build/marking-guide

# One zip for students, build/student-pack/lqe-student-pack.zip: unpack, then `make lab`.
student-pack: $(STAMP)
	$(BIN)/python -m lqe_helpers.authoring.student_pack --root . --out build/student-pack

# An nbgrader course folder in build/nbgrader/: source/lqe/ (questions (a)-(e), core path, with
# nbgrader cell metadata and points) and nbgrader_config.py. Run nbgrader there (pip install
# -e '.[grading]'); see docs/instructors.md, "Grading a class".
nbgrader: $(STAMP)
	$(BIN)/python -m lqe_helpers.grading.nbgrader_course --source notebooks --out build/nbgrader

# Speed against a peer in the same process (ratios, not pass/fail): filter and sliders.
bench: $(STAMP)
	$(BIN)/python benchmarks/bench_filter.py
	$(BIN)/python benchmarks/bench_widgets.py
	$(BIN)/python benchmarks/bench_notebooks.py
	$(BIN)/python benchmarks/bench_student_code.py

# Key press on a slider -> new picture shown, in a real JupyterLab (needs Debian's chromium).
bench-browser: $(STAMP)
	$(BIN)/python benchmarks/bench_browser.py

# Removes only what the Makefile made. In each tool's folder under build/, only the files
# listed in its .lqe-manifest.json and unchanged since (anything else there is kept and
# named); build/screenshots (the browser tests'); the pack's own .venv (a link named
# .venv loses only the link); the caches.
TOOL_OUTPUTS := build/handouts build/student build/marking-guide build/student-pack
clean:
	@if [ -n "$(wildcard $(TOOL_OUTPUTS))" ] && [ -f lqe_helpers/authoring/clean.py ]; then \
	  if $(BIN)/python -c "" >/dev/null 2>&1; then py=$(BIN)/python; else py=$(PYTHON); fi; \
	  $$py -m lqe_helpers.authoring.clean $(TOOL_OUTPUTS); fi
	rm -rf build/screenshots
	@rmdir build 2>/dev/null || true
	rm -rf $(VENV) .pytest_cache .ruff_cache .hypothesis lqe_course_pack.egg-info
	find . -name .git -prune -o -name __pycache__ -type d -prune -exec rm -rf {} +
