# impstab: two commands for a new user.
#   make demo         create .venv if missing, install impstab, compile its kernels, run the bundled example
#   make test         create/update the same .venv, compile the kernels, run the whole test suite (in parallel)
#   make compile      compile the kernels the commands use (once; kept until their sources change)
#   make clean-cache  remove the compiled kernels (make compile, or the first command, compiles them again)
# pip installs without compiling every module to bytecode (half its time): Python compiles what
# is imported, once.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.impstab-installed
EXAMPLE := examples/imp_symmetric.toml
# test processes: pytest-xdist's "auto" (one per core); a module stays on one process, so that its
# module-scoped fixtures are computed once
JOBS   ?= auto

.PHONY: demo test compile bench clean clean-cache

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --no-compile -e ".[test]"
	touch $(STAMP)

compile: $(STAMP)
	MPLBACKEND=Agg $(PY) -m impstab.precompile

demo: compile
	$(VENV)/bin/impstab critical $(EXAMPLE)
	$(VENV)/bin/impstab locus $(EXAMPLE) -o demo-locus.nc
	@echo "locus written to demo-locus.nc and demo-locus.png"

test: compile
	MPLBACKEND=Agg $(PY) -m pytest -q -n $(JOBS) --dist loadscope

bench: compile
	$(PY) benchmarks/startup.py
	$(PY) benchmarks/critical.py
	$(PY) benchmarks/fluid.py
	$(PY) benchmarks/simulate.py
	$(PY) benchmarks/sweep.py
	$(PY) benchmarks/response.py

clean-cache:
	test ! -x $(PY) || $(PY) -m impstab.precompile --clean
	find src -name __pycache__ -type d -prune -exec rm -rf {} +

clean:
	rm -rf $(VENV) demo-locus.nc demo-locus.png
