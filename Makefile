# pdw: two commands on a fresh machine (Python 3.11 + gcc): `make run`, `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
OUT    ?= out/typical_gait
STAMP  := $(VENV)/.pdw-installed
SOURCES := $(wildcard generated/*.c generated/*.h pdw/core/*.pyx pdw/core/csrc/*.c pdw/core/csrc/*.h) setup.py pyproject.toml

.PHONY: all run test lint test-all derive check-generated bench study clean distclean

all: $(STAMP)

$(VENV)/bin/python:
	$(PYTHON) -m venv $(VENV)
	$(PIP) install --quiet --upgrade pip

# Build dependencies first, then the package (editable, compiled in place), with test extras.
$(STAMP): $(VENV)/bin/python $(SOURCES)
	$(PIP) install --quiet "setuptools>=68" wheel "Cython>=3.0" "numpy>=1.23"
	$(PIP) install --quiet --no-build-isolation -e ".[test]"
	@touch $(STAMP)

## run: the main job -- the paper's typical gait, its step table and figures (in $(OUT))
run: $(STAMP)
	$(PY) -m pdw walk --out $(OUT)

## test: build everything, check generated/ against derive/, lint, the layer contract, the tests
test: $(STAMP)
	$(PY) -m derive --check
	$(MAKE) --no-print-directory lint
	$(PY) -m pytest -q

## lint: ruff (rules in pyproject.toml) and the import contract (layers, no cycles: docs/architecture.md)
lint: $(STAMP)
	$(VENV)/bin/ruff check pdw tests benchmarks derive
	$(VENV)/bin/lint-imports --no-cache

## test-all: also the slow studies
test-all: $(STAMP)
	$(PY) -m pytest -q -m ""

## derive: regenerate generated/ and pdw/core/_layout.py from the symbolic derivation
derive: $(VENV)/bin/python
	$(PIP) install --quiet "sympy>=1.12"
	$(PY) -m derive

check-generated: $(STAMP)
	$(PY) -m derive --check

## bench: micro-benchmarks and the run-time benchmarks (writes docs/benchmarks.md data)
bench: $(STAMP)
	$(PY) benchmarks/bench_model.py
	$(PY) benchmarks/bench_simulate.py
	$(PY) benchmarks/bench_integrators.py
	$(PY) benchmarks/bench_scenes.py
	$(PY) benchmarks/work_precision.py

## study: slow studies (marked slow in tests/)
study: $(STAMP)
	$(PY) -m pytest -q -m slow
	$(PY) benchmarks/stability_maps.py

clean:
	rm -rf build pdw/core/_core.c pdw/core/_hybrid.c pdw/core/*.so out

distclean: clean
	rm -rf $(VENV) *.egg-info
