# contact_ufl: from nothing to a running demo (`make demo`) and a passing test run (`make test`).
VENV    := .venv
PY      := $(VENV)/bin/python
MPIRUN  := $(VENV)/bin/mpirun
# A working Python 3.12: `python3.12` on PATH, else a pyenv-installed one.
PYTHON  ?= $(shell for p in python3.12 $$HOME/.pyenv/versions/3.12*/bin/python3.12; do \
             $$p -c 'import sys; assert sys.version_info[:2] == (3, 12)' 2>/dev/null && { echo $$p; break; }; done)
PYTEST_TIMEOUT ?= 1500

.PHONY: install test test-serial test-mpi demo notebook lint benchmarks clean

install: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	@test -n "$(PYTHON)" || { echo "error: no Python 3.12 found (set PYTHON=/path/to/python3.12)"; exit 1; }
	@bash .ci/system-deps
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[wheel,test]'
	@touch $@

test: install
	$(MAKE) test-serial
	$(MAKE) test-mpi

test-serial: install
	timeout $(PYTEST_TIMEOUT) $(PY) -m pytest -q -p no:cacheprovider tests

test-mpi: install
	timeout $(PYTEST_TIMEOUT) $(MPIRUN) -n 2 $(PY) -m pytest -q -p no:cacheprovider -m "not slow and not serial" tests

demo: install
	cd demos && ../$(PY) hertz.py && ../$(PY) plastic_indentation.py && ../$(MPIRUN) -n 2 ../$(PY) beams.py && ../$(PY) membrane.py

# demos/hertz.ipynb: the Hertz demo as a notebook, executed (pictures inline, files in demos/output)
notebook: install
	$(VENV)/bin/jupytext --to notebook demos/hertz.py
	$(VENV)/bin/jupyter execute --inplace demos/hertz.ipynb

lint: install
	$(VENV)/bin/ruff check contact_ufl demos tests benchmarks
	$(VENV)/bin/ruff format --check contact_ufl demos tests benchmarks

benchmarks: install
	$(PY) benchmarks/hertz.py --json benchmarks/results/hertz.json
	$(PY) benchmarks/taylor.py --json benchmarks/results/taylor.json

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
