# pdw: two commands on a fresh machine (Python 3.11 + gcc): `make run`, `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
OUT    ?= out/typical_gait
BUILT  := $(VENV)/.pdw-built
STAMP  := $(VENV)/.pdw-installed
BARE_CDM := build/bench/libbare_cdm.so
SOURCES := $(wildcard generated/*.c generated/*.h pdw/core/*.pyx pdw/core/*.pxi pdw/core/csrc/*.c pdw/core/csrc/*.h pdw/core/csrc/*.inc) setup.py pyproject.toml
# an extra's requirements, read from pyproject.toml (installed without rebuilding pdw)
EXTRA_REQS = $(PY) -c "import sys, tomllib; print('\n'.join(tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies'][sys.argv[1]]))"

.PHONY: docs all run test test-quick lint test-all derive check-generated bench study sanitize mutation clean \
        distclean instructions instructions-baseline

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

## test-quick: a fast subset (marker quick: parameters, simulate, gait steps, scenes, the ODE
## object, the command line, output files, the package's shape; tests/conftest.py QUICK_FILES),
## without the generated-code check and lint
test-quick: $(STAMP)
	$(PY) -m pytest -q -m "quick and not slow"

## lint: ruff (rules in pyproject.toml), the import contract (layers, no cycles: docs/architecture.md)
## and mypy on every module of pdw ([tool.mypy] in pyproject.toml)
lint: $(STAMP)
	$(VENV)/bin/ruff check pdw tests benchmarks derive
	$(VENV)/bin/lint-imports --no-cache
	$(VENV)/bin/mypy

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
bench: $(STAMP) $(BARE_CDM)
	$(PY) benchmarks/bench_model.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_cdm_step.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_simulate.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_integrators.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_scenes.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_batch.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_sweep_batch.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_step_maps.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_monodromy.py $(UPDATE_DOCS)
	$(PY) benchmarks/work_precision.py $(UPDATE_DOCS)
	$(PY) benchmarks/bench_terrain.py $(UPDATE_DOCS)
	$(PY) benchmarks/terrain_call_overhead.py
	$(PY) benchmarks/bench_mfpt.py $(UPDATE_DOCS)
	$(PY) benchmarks/continuation.py codim2 fold_kn $(UPDATE_DOCS)

## build/bench/libbare_cdm.so: the bare-C central-difference loop that bench_cdm_step.py measures
## pdw's cdm loop against (benchmarks/bare_cdm.c with the generated model, pdw's own flags)
$(BARE_CDM): benchmarks/bare_cdm.c generated/pdw_model.c generated/pdw_model.h
	@mkdir -p $(dir $@)
	$(CC) -O3 -std=c99 -fno-math-errno -fPIC -shared -Igenerated -Ipdw/core/csrc -o $@ benchmarks/bare_cdm.c \
	  generated/pdw_model.c -lm

## instructions: the instruction-count guard (valgrind's callgrind; benchmarks/instructions.py):
## the paper run with and without recording, a first call, 64-walker batches, find_gait,
## compared with benchmarks/results/instructions.json (fails on growth > 3 %; without valgrind,
## or with other compiler/libc/Python/NumPy versions than the baselines', one line and skip).
## About 30 s of CPU: run by .ci/run, not by `make test`.
instructions: $(STAMP)
	$(PY) benchmarks/instructions.py

## instructions-baseline: re-count and rewrite the baselines -- deliberately: commit the new
## benchmarks/results/instructions.json with a message that says why the counts changed
instructions-baseline: $(STAMP)
	$(PY) benchmarks/instructions.py --update

## study: slow studies (marked slow in tests/), written to out/ (UPDATE_DOCS as for bench)
study: $(STAMP)
	PDW_UPDATE_DOCS=$(if $(UPDATE_DOCS),1,0) $(PY) -m pytest -q -m slow
	$(PY) benchmarks/stability_maps.py $(UPDATE_DOCS)
	$(PY) benchmarks/step_edge_grid.py $(UPDATE_DOCS)
	$(PY) benchmarks/step_limits_laws.py $(UPDATE_DOCS)
	$(PY) benchmarks/basin_study.py 400 200 $(UPDATE_DOCS)
	$(PY) benchmarks/robustness_studies.py $(UPDATE_DOCS)
	$(PY) benchmarks/robustness_compliant.py $(UPDATE_DOCS)
	$(PY) benchmarks/robustness_compliant_khip.py $(UPDATE_DOCS)
	$(PY) benchmarks/robustness_compliant_mat.py $(UPDATE_DOCS)
	$(PY) benchmarks/robustness_tuning.py $(UPDATE_DOCS)
	$(PY) benchmarks/terrain_rigid_limit.py $(UPDATE_DOCS)
	$(PY) benchmarks/markov_vs_mc.py $(UPDATE_DOCS)
	$(PY) benchmarks/continuation.py region_kn region_hip_continuous $(UPDATE_DOCS)

## sanitize: the compiled core built with AddressSanitizer + UndefinedBehaviorSanitizer (in
## build/sanitize, the normal build untouched), and the tests of the compiled boundary, the loops
## and the hybrid map run on it (docs/stability.md); any ASan/UBSan report fails the run.
## allocator_may_return_null=1: an impossible allocation returns NULL (numpy's MemoryError), as
## glibc's malloc does, instead of aborting the whole run. The copy in build/sanitize is not a git
## checkout, so the test of pdw's own source revision is left out there
SAN_DIR   := build/sanitize
SAN_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined -g
SAN_TESTS ?= tests/core/test_core_sizes.py tests/sim/test_statuses.py \
             tests/core/test_model_inputs.py tests/sim/test_fuzz.py tests/sim/test_simulation.py \
             tests/analysis/rigid/test_hybrid.py tests/analysis/rigid/test_hybrid_options.py \
             tests/core/test_integrators.py tests/core/test_features.py \
             tests/sim/test_batch_inputs.py tests/sim/test_io.py tests/core/test_contact.py \
             tests/core/test_interrupt.py tests/sim/test_batch.py \
             tests/analysis/stepmap/test_step_maps.py \
             tests/core/test_contact_laws.py tests/core/test_ode_function.py tests/sim/test_export.py \
             tests/sim/test_dense_output.py
sanitize: $(STAMP)
	rm -rf $(SAN_DIR) && mkdir -p $(SAN_DIR)
	PDW_DEBUG=1 PDW_CFLAGS="$(SAN_FLAGS)" LDFLAGS="-fsanitize=address,undefined" \
	  $(PY) setup.py -q build_ext --build-lib $(SAN_DIR) --build-temp $(SAN_DIR)/tmp
	tar --exclude='*.so' --exclude='*.c' --exclude='__pycache__' -cf - pdw tests derive docs \
	  generated pyproject.toml | tar -xf - -C $(SAN_DIR)
	cd $(SAN_DIR) && ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:allocator_may_return_null=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  LD_PRELOAD="$$(gcc -print-file-name=libasan.so) $$(gcc -print-file-name=libubsan.so)" \
	  $(abspath $(PY)) -c "import pdw.core._core as c; assert '$(SAN_DIR)' in c.__file__, c.__file__" && \
	  ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:allocator_may_return_null=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  LD_PRELOAD="$$(gcc -print-file-name=libasan.so) $$(gcc -print-file-name=libubsan.so)" \
	  $(abspath $(PY)) -m pytest -q -p no:cacheprovider $(SAN_TESTS) \
	  --deselect tests/sim/test_export.py::test_source_revision_is_pdws_own_not_the_cwds

## mutation: the mutation campaign (docs/testing.md): each mutant of benchmarks/mutation.py
## applied, rebuilt (object cache in build/mutation-cc), its focused tests run, the source
## restored; results in benchmarks/results/mutation.json. It edits the working tree while it runs
mutation: $(STAMP)
	$(PY) benchmarks/mutation.py $(MUTATION_ARGS)

clean:
	rm -rf build out
	find pdw \( -name '*.so' -o -name '_core.c' -o -name '_hybrid.c' \) -delete

distclean: clean
	rm -rf $(VENV) *.egg-info

## docs: the documentation site (Sphinx: API reference, docs/*.md, the executed gallery) in
## out/docs/html; warnings are errors
docs: $(STAMP)
	$(EXTRA_REQS) docs > $(VENV)/requirements-docs.txt
	$(PIP) install --quiet --disable-pip-version-check -r $(VENV)/requirements-docs.txt
	$(PY) -m sphinx -W --keep-going -q -b html docs out/docs/html
