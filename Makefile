# holecell: the whole set-up is `make test` or `make demo` on a machine with python3 and make.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
# test processes (pytest-xdist): the suite waits on simulated real time, so two share 2 cores well
JOBS ?= 2
# system libraries of the GigE Vision head (Aravis) and of building PyGObject, which has no
# wheels: its build also needs pkg-config and Python's headers (Debian 12 names; other
# distributions: README.md)
DEB_PACKAGES := aravis-tools gir1.2-aravis-0.8 libaravis-0.8-0 libgirepository1.0-dev \
	libcairo2-dev pkg-config python3-dev
SYSDEPS := $(VENV)/.sysdeps

.PHONY: demo test lint format bench clean

# installs the missing Debian packages with apt when root; else prints the one line to run
$(SYSDEPS):
	@missing=$$(for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    echo "installing $$(echo $$missing)"; \
	    DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null || exit 1; \
	  else \
	    echo "holecell needs system packages; run:  sudo apt-get install -y $$(echo $$missing)"; \
	    echo "(not Debian or Ubuntu: README.md says what to install)"; exit 1; \
	  fi; \
	fi
	@mkdir -p $(VENV) && touch $@

$(STAMP): pyproject.toml $(SYSDEPS)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev,gige]'
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
