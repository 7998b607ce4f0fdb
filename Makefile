# voiga: set-up, build, run and test in two commands (`make run`, `make test`).
# Every target first installs what is missing (Debian packages through apt-get,
# Python packages through pip), so a fresh Debian 12 machine needs nothing else.

CASE    ?= cases/hertz/m3-NN2.2.nml
PYTHON  ?= python3
PREFIX  := build/install
VOIGA   := $(PREFIX)/bin/voiga
APT_PKGS := gfortran pkg-config libhdf5-dev zlib1g-dev libsuitesparse-dev liblapack-dev libblas-dev libopenblas-dev
SUDO    := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
# One BLAS thread per run unless the caller sets it: on this 2-core machine the sweep
# runs one case per core, and OpenBLAS threads that wait by spinning made hertz m3
# 3x slower while anything else ran (docs/performance.md).
export OPENBLAS_NUM_THREADS ?= 1
# The same for CHOLMOD's OpenMP loops (the Cholesky factor of linear bodies' stiffness).
export OMP_NUM_THREADS ?= 1

# The Python modules voiga's tools need; deps finds them without importing them (an
# import of all of them took 2.7 s, paid by every target: make paper included).
PY_MODULES := numpy h5py matplotlib splipy f90nml tqdm scipy vtk pytest wheel dask distributed pyarrow \
              fortitude ruff
export PY_MISSING := import importlib.util as u, sys; sys.exit(any(u.find_spec(m) is None for m in sys.argv[1:]))
# The packages requirements.txt pins (name==version: the linters, whose findings change
# from one version to the next); deps installs them when another version is there.
PY_PINNED := $(shell sed -n 's/^\([A-Za-z0-9_.-]*==[^ #]*\).*/\1/p' requirements.txt)
export PY_OTHER_VERSION := import importlib.metadata as m, sys; sys.exit(any(m.version(n) != v for n, v in (a.split('==') for a in sys.argv[1:])))

.PHONY: all deps build run test lint test-fortran test-python clean bench paper paper3d stress regress attack

all: build

## deps: install missing system and Python packages
deps:
	@missing=""; \
	command -v gfortran >/dev/null 2>&1 || missing="yes"; \
	command -v pkg-config >/dev/null 2>&1 || missing="yes"; \
	pkg-config --exists hdf5 2>/dev/null || missing="yes"; \
	pkg-config --exists lapack 2>/dev/null || missing="yes"; \
	pkg-config --exists openblas 2>/dev/null || missing="yes"; \
	[ -f /usr/include/suitesparse/umfpack.h ] || missing="yes"; \
	pkg-config --exists zlib 2>/dev/null || missing="yes"; \
	if [ -n "$$missing" ]; then \
	  echo "deps: installing Debian packages: $(APT_PKGS)"; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $(APT_PKGS) >/dev/null; \
	fi
	@if ! $(PYTHON) -c "$$PY_MISSING" $(PY_MODULES) 2>/dev/null \
	   || ! $(PYTHON) -c "$$PY_OTHER_VERSION" $(PY_PINNED) 2>/dev/null \
	   || ! command -v fpm >/dev/null 2>&1; then \
	  echo "deps: installing Python packages from requirements.txt"; \
	  $(PYTHON) -m pip install -q -r requirements.txt; \
	fi
	@if ! $(PYTHON) -c "import importlib.metadata as m; m.version('voiga')" >/dev/null 2>&1; then \
	  echo "deps: installing the pre and post packages (pip install -e .: voiga-pre, voiga-post)"; \
	  $(PYTHON) -m pip install -q --no-deps --no-build-isolation -e .; \
	fi

# Compiler flags of the release build, added to fpm's: the host's instruction set
# (wider vector loops in the element kernel, the contact projection and the
# factorization's own loops: ironing m3 NN2.2 about 6 % faster, docs/performance.md),
# and no contraction of a*b + c into one fused multiply-add, so that a result is
# bit-identical to that of a build without ARCH_FLAGS (or on a CPU without FMA).
# ARCH_FLAGS= builds a binary that runs on any x86-64 (a cluster whose nodes have
# another CPU than the machine that builds).
ARCH_FLAGS ?= -march=native
RELEASE_FLAGS := $(ARCH_FLAGS) -ffp-contract=off

## build: release build, installed to build/install/bin/voiga (ARCH_FLAGS: see above)
build: deps
	fpm install --profile release --flag "$(RELEASE_FLAGS)" --prefix $(PREFIX)

## run: build, solve CASE (default: hertz m3 NN2.2, checked against analytic Hertz), print
## what it found and write its figures and ParaView files into RUN_OUT (the case is
## copied there; nothing is written next to it)
RUN_OUT ?= build/run/$(notdir $(patsubst %/,%,$(dir $(abspath $(CASE)))))-$(basename $(notdir $(CASE)))
run: build
	VOIGA_BIN=$(CURDIR)/$(VOIGA) $(PYTHON) -m post run $(CASE) --out $(RUN_OUT)

## test: lint, then Fortran unit tests (fpm test) and Python tests (pytest)
test: lint build test-fortran test-python

## lint: fortitude on the Fortran (settings: fpm.toml [extra.fortitude]), ruff on the
## Python (pyproject.toml [tool.ruff]) and the docs check (test/python/check_docs.py:
## paths, files and code names that README.md and docs/ mention but the tree no longer
## has); the versions are pinned in requirements.txt
lint: deps
	$(PYTHON) -m fortitude check --output-format concise src app test
	$(PYTHON) -m ruff check pre post bench test/python
	$(PYTHON) test/python/check_docs.py

test-fortran: deps
	fpm test

test-python: build
	VOIGA_BIN=$(CURDIR)/$(VOIGA) $(PYTHON) -m pytest -q

clean:
	rm -rf build

## stress: the full hard-case suite of issue 6 (docs/hard-cases.md), one case at a time;
## prints the table (case, outcome, steps, cuts, Newton iterations, wall s) and writes it
## to build/stress/table.md; fails if a case does not end as expected.
## STRESS_ARGS e.g. --only 'deep-m1-*' 'penalty-*', or --list
stress: build
	VOIGA_BIN=$(CURDIR)/$(VOIGA) $(PYTHON) test/python/hard_cases.py --out build/stress \
	  --markdown build/stress/table.md $(STRESS_ARGS)

## attack: the attack suite of issues 19 and 36 (docs/attack.md): every namelist,
## geometry, output-path and result-file input of test/python/attack_inputs.py and every
## link, special-file, swap and huge-size attack of attack_files.py (about 1450) judged
## by its oracles; prints the counts per family and writes them to build/attack/table.md;
## fails on any crash, hang, silent wrong result, traceback or changed input.
## make test runs the reduced set (test/python/test_attack.py). ATTACK_ARGS e.g.
## --family output post swap, --list
attack: build
	VOIGA_BIN=$(CURDIR)/$(VOIGA) $(PYTHON) test/python/attack.py --out build/attack \
	  --markdown build/attack/table.md $(ATTACK_ARGS)

## bench: performance figures of one run (stages, NNp vs Np, accuracy, scaling, CalculiX,
## Kratos, CalculiX on the thick sphere of issue 41)
bench: build
	VOIGA_BIN=$(CURDIR)/$(VOIGA) $(PYTHON) -m bench $(BENCH_ARGS)

## paper: run the paper's studies (the study cases/studies/paper.toml: every committed case;
## PAPER_ARGS, e.g. --scenes hertz --meshes m1 m2) into PAPER_OUT and regenerate the
## figures and tables in docs/validation; fails if a case fails
PAPER_OUT ?= results
paper: build
	@status=0; \
	VOIGA_BIN=$(CURDIR)/$(VOIGA) $(PYTHON) -m post study cases/studies/paper.toml --out $(PAPER_OUT) $(PAPER_ARGS) || status=$$?; \
	$(PYTHON) -m post figures --results $(PAPER_OUT) --out docs/validation || status=$$?; \
	exit $$status

## paper3d: what VO buys in 3D (docs/validation-3d.md): the study cases/studies/paper3d.toml
## (the committed hertz3d and ironing3d cases; about 20 CPU minutes) into PAPER3D_OUT, then
## its figures and accuracy/cost tables in docs/validation/3d; fails if a case fails.
## PAPER3D_ARGS e.g. --scenes hertz3d --meshes m1 m2
PAPER3D_OUT ?= results3d
paper3d: build
	@status=0; \
	VOIGA_BIN=$(CURDIR)/$(VOIGA) $(PYTHON) -m post study cases/studies/paper3d.toml --out $(PAPER3D_OUT) $(PAPER3D_ARGS) || status=$$?; \
	$(PYTHON) -m post figures --results $(PAPER3D_OUT) --out docs/validation/3d || status=$$?; \
	exit $$status

## regress: every committed case and every converging hard case, compared per step with
## the baseline made by the binary before the solver redesign (test/regress/); REGRESS_ARGS
## e.g. --only 'hertz/*', --jobs 1, --write (remake the baseline with this binary)
regress: build
	VOIGA_BIN=$(CURDIR)/$(VOIGA) $(PYTHON) test/python/regress.py $(REGRESS_ARGS)
