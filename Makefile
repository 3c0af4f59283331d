# contact_ufl: from nothing to a running demo (`make demo`) and a passing test run (`make test`).
VENV    := .venv
PY      := $(VENV)/bin/python
MPIRUN  := $(VENV)/bin/mpirun
# A working Python 3.12: `python3.12` on PATH, else a pyenv-installed one.
PYTHON  ?= $(shell for p in python3.12 $$HOME/.pyenv/versions/3.12*/bin/python3.12; do \
             $$p -c 'import sys; assert sys.version_info[:2] == (3, 12)' 2>/dev/null && { echo $$p; break; }; done)
PYTEST_TIMEOUT ?= 1500
PYTEST_TIMEOUT_ALL ?= 7200

.PHONY: install test test-serial test-mpi test-all demo notebook docs docs-clean lint benchmarks clean

install: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	@test -n "$(PYTHON)" || { echo "error: no Python 3.12 found (set PYTHON=/path/to/python3.12)"; exit 1; }
	@bash .ci/system-deps
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[wheel,test]'
	@touch $@

# The default suite: serially on both cores (pytest-xdist, a file's tests on one worker so
# that its fixtures are made once), then on 2 MPI ranks (every test not marked `serial`).
# `make test-all` adds the slow tier (refinement studies, long scenes).
XDIST   ?= -n 2 --dist loadfile
PYTEST  := $(PY) -m pytest -q -p no:cacheprovider

test: install
	$(MAKE) test-serial
	$(MAKE) test-mpi

test-serial: install
	timeout $(PYTEST_TIMEOUT) $(PYTEST) $(XDIST) tests

test-mpi: install
	timeout $(PYTEST_TIMEOUT) $(MPIRUN) -n 2 $(PYTEST) -m "not slow and not serial" tests

test-all: install
	timeout $(PYTEST_TIMEOUT_ALL) $(PYTEST) $(XDIST) -m "" tests
	timeout $(PYTEST_TIMEOUT_ALL) $(MPIRUN) -n 2 $(PYTEST) -m "not serial" tests

demo: install
	cd demos && ../$(PY) hertz.py && ../$(PY) plastic_indentation.py && ../$(MPIRUN) -n 2 ../$(PY) beams.py && ../$(PY) membrane.py \
	  && ../$(PY) adaptive_hertz.py

# demos/hertz.ipynb: the Hertz demo as a notebook, executed (pictures inline, files in demos/output)
notebook: install
	$(VENV)/bin/jupytext --to notebook demos/hertz.py
	$(VENV)/bin/jupyter execute --inplace demos/hertz.ipynb

# docs/_build/html: the documentation (Sphinx, MyST), the demos run as notebooks (their
# outputs cached in docs/_build/.jupyter_cache until a demo changes); warnings are errors.
# DOCS_EXECUTE=off builds it without running the demos, DOCS_EXECUTE=force runs them again.
DOCS_EXECUTE ?= cache
docs: $(VENV)/.docs-installed
	CONTACT_UFL_DOCS_EXECUTE=$(DOCS_EXECUTE) $(PY) -m sphinx -W --keep-going -b html docs docs/_build/html
	@echo "docs: open docs/_build/html/index.html"

# the `docs` extra (sphinx, myst-nb, furo, jupytext, ipykernel), unless already there
$(VENV)/.docs-installed: $(VENV)/.installed pyproject.toml
	@$(PY) -c 'import importlib, sphinx, myst_nb, furo, jupytext, ipykernel; importlib.import_module("sphinx-mathjax-offline")' 2>/dev/null \
	  || $(PY) -m pip install -q -e '.[docs]' \
	  || { echo "error: the documentation tools are missing and could not be installed:"; \
	       echo "       run \`$(PY) -m pip install -e '.[docs]'\` where PyPI can be reached"; exit 1; }
	@touch $@

docs-clean:
	rm -rf docs/_build docs/tutorial

lint: install
	$(VENV)/bin/ruff check contact_ufl demos tests benchmarks
	$(VENV)/bin/ruff format --check contact_ufl demos tests benchmarks

benchmarks: install
	$(PY) benchmarks/hertz.py --json benchmarks/results/hertz.json
	$(PY) benchmarks/taylor.py --json benchmarks/results/taylor.json

# docs/benchmarks.md and its figures (docs/benchmarks/), generated from benchmarks/results/*.json
.PHONY: benchmark-report
benchmark-report: install
	$(PY) benchmarks/report.py

# docs/verification.md and docs/verification.json, generated from the records of the tests
# (the `verification` fixture, in the JUnit XML of a run of the serial suite); the page is
# written also when a test fails (it says which), and the target then fails too
.PHONY: verification-report
verification-report: install
	@mkdir -p build
	timeout $(PYTEST_TIMEOUT) $(PYTEST) $(XDIST) --junitxml=build/verification.xml tests; \
	  status=$$?; $(PY) tests/verification_report.py --from-junit build/verification.xml \
	  && exit $$status

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache docs/_build docs/tutorial
