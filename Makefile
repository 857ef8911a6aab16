# impstab: two commands for a new user.
#   make demo         create .venv if missing, install impstab, compile its kernels, run the bundled example
#   make test         create/update the same .venv, compile the kernels, run the whole test suite (in parallel)
#   make compile      compile the kernels the commands use (once; kept until their sources change)
#   make clean-cache  remove the compiled kernels, shared by the clones on this machine (make compile, or the first
#                     command, compiles them again)
# The environment is installed by uv (itself installed by pip first; its resolver and parallel
# downloads and unpacking take 5 s where pip takes 35 s), or by pip where uv cannot be installed.
# pip installs without compiling to bytecode (on one core, half its time); then the environment's
# modules are compiled to bytecode on every core at once. Python would write the bytecode of what
# it imports itself, but not where PYTHONDONTWRITEBYTECODE is set (as in many containers and CI
# images): every process would then compile numpy, scipy, xarray, numba ... from source again,
# 1 to 5 s of each start-up (measured: a study process 6.3 s -> 2.1 s, `impstab critical` ~0.6 s).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.impstab-installed
EXAMPLE := examples/imp_symmetric.toml
# test processes: pytest-xdist's "auto" (one per core); a module stays on one process, so that its
# module-scoped fixtures are computed once
JOBS   ?= auto

# the bytecode of every module installed in the environment, but for the packages' own test suites
# and pip, which no command imports (a third of the files: 24 s -> 14 s on two cores). Files that do
# not compile, such as another Python version's, are skipped without a word: Python reads the
# source of whatever has no bytecode if it is ever imported
define BYTECODE
import compileall, re, sysconfig
skip = re.compile(r"/tests?/|/site-packages/pip/")
for folder in sorted({sysconfig.get_paths()[k] for k in ("purelib", "platlib")}):
    compileall.compile_dir(folder, quiet=2, workers=0, rx=skip)
endef
export BYTECODE

.PHONY: demo test compile bench clean clean-cache

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	($(PY) -m pip install --quiet --no-compile uv && $(PY) -m uv pip install --quiet --python $(PY) -e ".[test]") \
	    || $(PY) -m pip install --quiet --no-compile -e ".[test]"
	$(PY) -c "$$BYTECODE"
	touch $(STAMP)

compile: $(STAMP)
	MPLBACKEND=Agg $(PY) -m impstab.precompile

demo: compile
	$(VENV)/bin/impstab critical $(EXAMPLE)
	$(VENV)/bin/impstab locus $(EXAMPLE) -o demo-locus.nc
	@echo "locus written to demo-locus.nc and demo-locus.png"

# pytest keeps the test modules it rewrites (for its assertion messages) as bytecode beside them:
# each test process collects in 7 s instead of 13 s from the second run on, where
# PYTHONDONTWRITEBYTECODE (set in many containers) would make every run rewrite them again;
# --no-loadscope-reorder keeps tests/conftest.py's longest-first order of the modules (pytest-xdist
# would order them by their number of tests, and a long module handed out last idles the other worker)
test: compile
	MPLBACKEND=Agg PYTHONDONTWRITEBYTECODE= $(PY) -m pytest -q -n $(JOBS) --dist loadscope --no-loadscope-reorder

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
