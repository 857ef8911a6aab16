# impstab: two commands for a new user.
#   make demo   create .venv if missing, install impstab, run the bundled example
#   make test   create/update the same .venv and run the whole test suite
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.impstab-installed
EXAMPLE := examples/imp_symmetric.toml

.PHONY: demo test bench clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test]"
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/impstab critical $(EXAMPLE)
	$(VENV)/bin/impstab locus $(EXAMPLE) -o demo-locus.nc
	@echo "locus written to demo-locus.nc and demo-locus.png"

test: $(STAMP)
	MPLBACKEND=Agg $(PY) -m pytest -q

bench: $(STAMP)
	$(PY) benchmarks/critical.py
	$(PY) benchmarks/fluid.py
	$(PY) benchmarks/simulate.py
	$(PY) benchmarks/sweep.py
	$(PY) benchmarks/response.py

clean:
	rm -rf $(VENV) demo-locus.nc demo-locus.png
