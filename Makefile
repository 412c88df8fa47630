# geobrep — two commands on a fresh machine:
#   make demo   set up .venv and run the demo job on the built-in sample model
#   make test   set up .venv and run ruff, mypy and the whole test suite
# Both are quick on a second run (installs are skipped until pyproject.toml changes).

PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMPS := $(VENV)/.geobrep-stamps
EXAMPLE_PLUGIN := docs/examples/geobrep-example-plugin
PIP_QUIET := --quiet --disable-pip-version-check

.PHONY: demo test test-newest test-min lint typecheck pytest bench fuzz fuzz-properties schemas docs-tables sysdeps clean help geoh5-check

help:
	@echo "make demo   - run the demo on the built-in sample model (writes demo-output/)"
	@echo "make test   - ruff + mypy + the whole test suite (newest allowed dependencies)"
	@echo "make test-min - the suite on the lowest versions pyproject.toml allows (.venv-min)"
	@echo "make bench  - benchmarks (not part of make test)"
	@echo "make fuzz   - 25,000 mutated files through every reader (not part of make test)"
	@echo "make fuzz-properties - the property tests with fresh random examples (not part of make test)"
	@echo "make geoh5-check - cross-check the geoh5 adapter with geoh5py in a venv of its own"

$(PY):
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "geobrep needs Python 3.11 or newer: set PYTHON=python3.11 (or newer)")'
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install $(PIP_QUIET) --upgrade "pip>=23.1" "setuptools>=77.0.1" wheel

$(STAMPS)/base: pyproject.toml | $(PY)
	$(PY) -m pip install $(PIP_QUIET) -e .
	@mkdir -p $(STAMPS) && touch $@

$(STAMPS)/test: pyproject.toml $(STAMPS)/base
	$(PY) -m pip install $(PIP_QUIET) -e ".[test,dev,open3d,gis]"
	@mkdir -p $(STAMPS) && touch $@

# open3d (the `open3d` extra) needs system libraries that a bare machine may lack.
sysdeps:
	@if ! ldconfig -p 2>/dev/null | grep -q 'libusb-1.0.so.0'; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "installing libusb-1.0-0 (needed by open3d)"; \
	    apt-get install -y -qq libusb-1.0-0 >/dev/null 2>&1 || \
	      { apt-get update -qq >/dev/null && apt-get install -y -qq libusb-1.0-0 >/dev/null; } || \
	      echo "could not install libusb-1.0-0: open3d features will be unavailable"; \
	  else \
	    echo "open3d needs libusb-1.0, which is missing. Install it with:"; \
	    echo "    sudo apt-get install libusb-1.0-0    # Debian/Ubuntu"; \
	    echo "    sudo dnf install libusb1             # Fedora/RHEL"; \
	    echo "(everything else works without it)"; \
	  fi; \
	fi
	@if ! command -v chromium >/dev/null 2>&1 && ! command -v chromium-browser >/dev/null 2>&1; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "installing chromium (the browser test of geobrep view)"; \
	    apt-get install -y -qq chromium >/dev/null 2>&1 || \
	      { apt-get update -qq >/dev/null && apt-get install -y -qq chromium >/dev/null; } || \
	      echo "could not install chromium: the browser test will be skipped"; \
	  else \
	    echo "the browser test of geobrep view needs Chromium. Install it with:"; \
	    echo "    sudo apt-get install chromium    # Debian/Ubuntu"; \
	  fi; \
	fi

$(STAMPS)/demo: pyproject.toml $(STAMPS)/base
	$(PY) -m pip install $(PIP_QUIET) -e ".[viz,gis]"
	@mkdir -p $(STAMPS) && touch $@

demo: $(STAMPS)/demo
	$(VENV)/bin/geobrep demo --output demo-output

lint: $(STAMPS)/test
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

# mypy cannot follow setuptools' editable finder for the core/ -> geobrep mapping, so it checks a
# tree of symbolic links laid out as the installed package.
TYPECHECK_DIR ?= build/typecheck
typecheck: $(STAMPS)/test
	@rm -rf $(TYPECHECK_DIR) && mkdir -p $(TYPECHECK_DIR)/geobrep
	@for entry in core/*; do ln -s "$(CURDIR)/$$entry" $(TYPECHECK_DIR)/geobrep/; done
	@ln -s "$(CURDIR)/plugins" $(TYPECHECK_DIR)/geobrep/plugins
	@ln -s "$(CURDIR)/adapters" $(TYPECHECK_DIR)/geobrep/adapters
	@ln -s "$(CURDIR)/schemas" $(TYPECHECK_DIR)/geobrep/schemas
	cd $(TYPECHECK_DIR) && MYPYPATH=. $(CURDIR)/$(VENV)/bin/mypy --config-file $(CURDIR)/pyproject.toml -p geobrep

pytest: $(STAMPS)/test sysdeps
	$(PY) -m pytest

test: lint typecheck pytest

# `make test` installs the newest versions pyproject.toml allows; test-newest names that.
test-newest: test

# The suite on the floors: Python 3.11 and every core, build-system and extra requirement pinned
# to its declared lower bound (tools/floors.py), in a venv of its own. geobrep itself is built
# with the floor setuptools (no build isolation), so the build-system floor is tested too.
MIN_PYTHON ?= python3.11
MIN_VENV   ?= .venv-min
MIN_PY     := $(MIN_VENV)/bin/python
MIN_EXTRAS := test open3d gis viz dask
MIN_STAMP  := $(MIN_VENV)/.geobrep-floors

$(MIN_STAMP): pyproject.toml tools/floors.py
	@$(MIN_PYTHON) -c 'import sys; sys.exit(0 if sys.version_info[:2] == (3, 11) else "make test-min runs on the floor Python, 3.11: set MIN_PYTHON=python3.11")'
	rm -rf $(MIN_VENV)
	$(MIN_PYTHON) -m venv $(MIN_VENV)
	$(MIN_PY) -m pip install $(PIP_QUIET) --upgrade "pip>=23.1"
	$(MIN_PY) tools/floors.py --build > $(MIN_VENV)/build-floors.txt
	$(MIN_PY) tools/floors.py $(MIN_EXTRAS) > $(MIN_VENV)/floors.txt
	$(MIN_PY) tools/floors.py --requirements $(MIN_EXTRAS) > $(MIN_VENV)/requirements.txt
	$(MIN_PY) -m pip install $(PIP_QUIET) -r $(MIN_VENV)/build-floors.txt
	$(MIN_PY) -m pip install $(PIP_QUIET) -c $(MIN_VENV)/floors.txt -c $(MIN_VENV)/build-floors.txt \
	  -r $(MIN_VENV)/requirements.txt
	$(MIN_PY) -m pip install $(PIP_QUIET) --no-deps --no-build-isolation -e .
	$(MIN_PY) -m pip check
	$(MIN_PY) -m pip freeze --exclude-editable > $(MIN_VENV)/installed.txt
	@touch $@

test-min: $(MIN_STAMP) sysdeps
	@$(MIN_PY) -c 'import numpy, rtree, scipy; print(f"floors: numpy {numpy.__version__}, rtree {rtree.__version__}, scipy {scipy.__version__} (all pins: $(MIN_VENV)/installed.txt)")'
	$(MIN_PY) -m pytest -p no:cacheprovider

# geoh5py pins numpy<1.27 and cannot share .venv: it gets a venv of its own, and the check runs
# in three steps (geobrep writes, geoh5py reads it and writes, geobrep reads that): tools/geoh5_check.py.
GEOH5_VENV ?= .venv-geoh5
GEOH5_DIR  ?= build/geoh5-check
$(GEOH5_VENV)/.geoh5py: Makefile
	rm -rf $(GEOH5_VENV)
	$(PYTHON) -m venv $(GEOH5_VENV)
	$(GEOH5_VENV)/bin/python -m pip install $(PIP_QUIET) "geoh5py>=0.12,<0.14" "numpy>=1.26,<1.27"
	@touch $@

geoh5-check: $(STAMPS)/test $(GEOH5_VENV)/.geoh5py
	$(PY) tools/geoh5_check.py write $(GEOH5_DIR)
	$(GEOH5_VENV)/bin/python tools/geoh5_check.py geoh5py $(GEOH5_DIR)
	$(PY) tools/geoh5_check.py read $(GEOH5_DIR)

schemas: $(STAMPS)/base
	$(PY) -m geobrep.schemas

docs-tables: $(STAMPS)/base
	$(PY) -m geobrep.batch.operations docs/pipelines.md

bench: $(STAMPS)/test
	$(PY) -m pip install $(PIP_QUIET) -e ".[bench]"
	$(PY) benchmarks/run_all.py

# The readers' large fuzz run (not part of make test): 25,000 mutated files, each read in a worker
# process within 10 s and max(256 MB, 20 x its size) of memory; prints the figures per format.
FUZZ_CASES ?= 25000
fuzz: $(STAMPS)/test
	$(PY) benchmarks/fuzz.py --cases $(FUZZ_CASES) --timeout 10

# The property tests with fresh random examples (make test draws the same ones every run):
# GEOBREP_EXAMPLES per test, default 2000; a failure prints the @reproduce_failure to keep.
fuzz-properties: $(STAMPS)/test
	$(PY) -m pytest tests -q -p no:cacheprovider -m hypothesis --hypothesis-profile geobrep-explore

clean:
	rm -rf build dist *.egg-info .mypy_cache .ruff_cache .pytest_cache demo-output
