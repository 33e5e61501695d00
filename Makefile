# pdw: two commands on a fresh machine (Python 3.11 + gcc): `make run`, `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
OUT    ?= out/typical_gait
BUILT  := $(VENV)/.pdw-built
STAMP  := $(VENV)/.pdw-installed
SOURCES := $(wildcard generated/*.c generated/*.h pdw/core/*.pyx pdw/core/csrc/*.c pdw/core/csrc/*.h) setup.py pyproject.toml
# an extra's requirements, read from pyproject.toml (installed without rebuilding pdw)
EXTRA_REQS = $(PY) -c "import sys, tomllib; print('\n'.join(tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies'][sys.argv[1]]))"

.PHONY: all run test lint test-all derive check-generated bench study clean distclean

all: $(STAMP)

$(VENV)/bin/python:
	$(PYTHON) -m venv $(VENV)

# What running needs: the build tools, then the package (editable, compiled in place) with the
# plot extra (the figures of `make run`).
$(BUILT): $(VENV)/bin/python $(SOURCES)
	$(PIP) install --quiet --disable-pip-version-check "setuptools>=77" wheel "Cython>=3.0"
	PYTHONWARNINGS=ignore $(PIP) install --quiet --disable-pip-version-check --no-build-isolation -e ".[plot]"
	@touch $(BUILT)

# What testing needs on top: the test extra.
$(STAMP): $(BUILT)
	$(EXTRA_REQS) test > $(VENV)/requirements-test.txt
	$(PIP) install --quiet --disable-pip-version-check -r $(VENV)/requirements-test.txt
	@touch $(STAMP)

## run: the main job -- the paper's typical gait, its step table and figures (in $(OUT))
run: $(BUILT)
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
	$(EXTRA_REQS) derive > $(VENV)/requirements-derive.txt
	$(PIP) install --quiet --disable-pip-version-check -r $(VENV)/requirements-derive.txt
	$(PY) -m derive

check-generated: $(STAMP)
	$(PY) -m derive --check

## bench: micro-benchmarks and the run-time benchmarks, written to out/benchmarks/;
## `make bench UPDATE_DOCS=--update-docs` writes the committed benchmarks/results/ and docs/figures/
UPDATE_DOCS ?=
bench: $(STAMP)
	$(PY) benchmarks/bench_model.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_simulate.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_integrators.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_scenes.py $(UPDATE_DOCS)
	$(PY) benchmarks/work_precision.py $(UPDATE_DOCS)

## study: slow studies (marked slow in tests/), written to out/ (UPDATE_DOCS as for bench)
study: $(STAMP)
	PDW_UPDATE_DOCS=$(if $(UPDATE_DOCS),1,0) $(PY) -m pytest -q -m slow
	$(PY) benchmarks/stability_maps.py $(UPDATE_DOCS)
	$(PY) benchmarks/step_edge_grid.py $(UPDATE_DOCS)

clean:
	rm -rf build out
	find pdw \( -name '*.so' -o -name '_core.c' -o -name '_hybrid.c' \) -delete

distclean: clean
	rm -rf $(VENV) *.egg-info
