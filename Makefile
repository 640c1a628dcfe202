# roastlab: `make reproduce` runs the main job, `make test` the test suite.
# Both create .venv on a fresh machine (Python >= 3.11 and the package registries only).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: test reproduce bench lint clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

test: $(STAMP)
	$(PY) -m pytest

reproduce: $(STAMP)
	$(VENV)/bin/roastlab reproduce --out out/reproduce

bench: $(STAMP)
	$(VENV)/bin/roastlab bench

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests
	$(VENV)/bin/ruff format --check src tests

clean:
	rm -rf $(VENV) out .pytest_cache
	find src tests -name __pycache__ -type d -exec rm -rf {} +
