# holecell: the whole set-up is `make test` or `make demo` on a machine with python3 and make.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
# test processes (pytest-xdist): the suite waits on simulated real time, so two share 2 cores well
JOBS ?= 2

.PHONY: demo test lint format bench clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/holecell demo

test: $(STAMP)
	$(PY) -m pytest -q -n $(JOBS)

lint: $(STAMP)
	$(VENV)/bin/ruff check cell planner measure robots tests benchmarks examples
	$(VENV)/bin/ruff format --check cell planner measure robots tests benchmarks examples
	$(VENV)/bin/mypy

format: $(STAMP)
	$(VENV)/bin/ruff format cell planner measure robots tests benchmarks examples
	$(VENV)/bin/ruff check --fix cell planner measure robots tests benchmarks examples

bench: $(STAMP)
	for f in benchmarks/*.py; do $(PY) $$f || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info
