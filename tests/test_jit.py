"""Kernels run interpreted until compiling pays (impstab._jit), with the same answers either way.

Every check runs in a fresh interpreter: which way a kernel runs is a property of the process.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from impstab.linear.critical_thrust import FLUID_TOLERANCE

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: THEORY's closed form for the symmetric example (the pitch/yaw coalescence), as benchmarks/critical.py
CLOSED_FORM = 18012.0999227555


def _python(code: str, **env: str) -> str:
    environment = dict(os.environ, **{"IMPSTAB_JIT": "auto", **env})  # the default policy unless given
    environment["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + environment.get("PYTHONPATH", "")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=environment,
                          timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip().splitlines()[-1]


_THRUSTS = """
import json, sys, impstab
from impstab.model import load_model
names = {names!r}
out = {{n: impstab.critical_thrust(load_model('examples/' + n)).thrust for n in names}}
print(json.dumps({{"thrusts": out, "numba": "numba" in sys.modules, "compiled": impstab._jit.compiled()}}))
"""

MODELS = ["imp_symmetric.toml", "imp_asymmetric.toml", "imp_damped.toml", "imp_fluid.toml",
          "imp_viscoelastic.toml", "imp_beam_mounts.toml", "imp_hardening.toml"]


def test_a_single_model_analysis_never_imports_numba():
    got = json.loads(_python(_THRUSTS.format(names=["imp_symmetric.toml"])))
    assert got["numba"] is False and got["compiled"] is False
    assert abs(got["thrusts"]["imp_symmetric.toml"] - CLOSED_FORM) <= 1e-12 * CLOSED_FORM


def test_interpreted_and_compiled_kernels_give_the_same_critical_thrusts():
    interpreted = json.loads(_python(_THRUSTS.format(names=MODELS), IMPSTAB_JIT="interpreted"))
    compiled = json.loads(_python(_THRUSTS.format(names=MODELS), IMPSTAB_JIT="compiled"))
    assert interpreted["numba"] is False and interpreted["compiled"] is False
    assert compiled["compiled"] is True
    for name in MODELS:
        a, b = interpreted["thrusts"][name], compiled["thrusts"][name]
        # LAPACK's QR against the compiled one: rounding of the eigenvalues, then the same exact
        # refinement. The compressible fluid's frequency iteration stops when the thrust changes by
        # less than FLUID_TOLERANCE (relative), so rounding may end it one iteration sooner or later.
        tol = 10 * FLUID_TOLERANCE if name == "imp_fluid.toml" else 1e-11
        assert abs(a - b) <= tol * abs(b), (name, a, b)


def test_past_the_budget_the_process_compiles_and_stays_compiled():
    code = """
import json, sys, impstab, impstab._jit as jit
from impstab.model import load_model
jit.BUDGET_S = 0.0
model = load_model('examples/imp_symmetric.toml')
first = impstab.critical_thrust(model).thrust
after_first = jit.compiled()
second = impstab.critical_thrust(model).thrust
from impstab.linear import small_eig
from numba.core.registry import CPUDispatcher
print(json.dumps([first, second, after_first, isinstance(small_eig._solve_one, CPUDispatcher)]))
"""
    first, second, compiled, rebound = json.loads(_python(code))
    assert compiled and rebound
    assert abs(first - CLOSED_FORM) <= 1e-12 * CLOSED_FORM and abs(second - CLOSED_FORM) <= 1e-12 * CLOSED_FORM


def test_a_long_kernel_compiles_before_its_first_call():
    code = """
import json, impstab, impstab._jit as jit
from impstab.model import load_model
r = impstab.simulate(load_model('examples/imp_symmetric.toml'), 17000.0, 0.05, critical_thrust=False)
print(json.dumps(jit.compiled()))
"""
    assert json.loads(_python(code)) is True


def test_python_arithmetic_errors_are_answered_by_the_compiled_kernel():
    # plain Python raises on 1.0 / 0.0; the compiled kernel (error_model="numpy") gives inf
    code = """
import json, math, impstab._jit as jit
@jit.njit(error_model="numpy")
def ratio(a, b):
    return a / b
before = jit.compiled()
value = ratio(1.0, 0.0)
print(json.dumps([before, jit.compiled(), math.isinf(value) and value > 0]))
"""
    assert json.loads(_python(code)) == [False, True, True]


def test_the_interpreted_policy_never_compiles():
    code = """
import json, impstab._jit as jit
@jit.njit(compile_first=True)
def twice(a):
    return 2.0 * a
print(json.dumps([twice(2.0), jit.compiled()]))
"""
    assert json.loads(_python(code, IMPSTAB_JIT="interpreted")) == [4.0, False]


def test_a_bad_policy_is_one_line_and_exit_2():
    environment = dict(os.environ, IMPSTAB_JIT="sometimes")
    environment["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + environment.get("PYTHONPATH", "")
    done = subprocess.run([sys.executable, "-m", "impstab", "critical", str(EXAMPLES / "imp_symmetric.toml")],
                          capture_output=True, text=True, env=environment, timeout=300)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert lines == ["impstab: error: environment variable IMPSTAB_JIT = 'sometimes': must be one of auto, "
                     "compiled, interpreted"]


@pytest.mark.parametrize("policy", ["auto", "compiled"])
def test_objmode_blocks_work_both_ways(policy):
    # a provider family (a callable K(T)) is evaluated from the engine's loop through objmode
    code = """
import json, numpy as np, impstab
m = np.eye(2); k0 = np.diag([1.0, 4.0]); k1 = np.array([[0.0, 1.0], [-1.0, 0.0]])
r = impstab.critical_load(lambda p: (m, None, None, k0 + p * k1), p_max=5.0)
print(json.dumps([r.load, impstab._jit.compiled()]))
"""
    load, compiled = json.loads(_python(code, IMPSTAB_JIT=policy))
    # K = diag(1, 4) + p [[0, 1], [-1, 0]]: s^2 - 5 s + 4 + p^2 = 0 has a double root at p = 3/2
    assert abs(load - 1.5) <= 1e-9
    assert compiled is (policy == "compiled")


def test_modules_imported_after_the_process_compiled_get_compiled_kernels():
    # compile first, then import the engine (its object-mode blocks must see numba's objmode)
    code = """
import json, impstab._jit as jit
jit.require_compiled()
import numpy as np, impstab
from impstab.model import load_model
r = impstab.critical_thrust(load_model('examples/imp_viscoelastic.toml'))
m = np.eye(2); k0 = np.diag([1.0, 4.0]); k1 = np.array([[0.0, 1.0], [-1.0, 0.0]])
p = impstab.critical_load(lambda p: (m, None, None, k0 + p * k1), p_max=5.0)
print(json.dumps([r.thrust, p.load]))
"""
    thrust, load = json.loads(_python(code))
    reference = json.loads(_python(_THRUSTS.format(names=["imp_viscoelastic.toml"]), IMPSTAB_JIT="interpreted"))
    assert abs(thrust - reference["thrusts"]["imp_viscoelastic.toml"]) <= 1e-11 * thrust
    assert abs(load - 1.5) <= 1e-9


_ANNOUNCED = """
import json, numpy as np, impstab._jit as jit
lines = []
jit.announce_compiling(lines.append)
jit.require_compiled()
from impstab.kinematics.so3 import _cross, _skew
_skew(np.ones(3))  # the first compile: one line
_cross(np.ones(3), np.ones(3))  # a second compile: no more
print(json.dumps(lines))
"""


def test_the_first_compile_is_announced_once_and_a_cache_load_is_not(tmp_path):
    from impstab import _jit

    cache = str(tmp_path / "kernels")
    assert json.loads(_python(_ANNOUNCED, NUMBA_CACHE_DIR=cache)) == [_jit.COMPILING]
    assert json.loads(_python(_ANNOUNCED, NUMBA_CACHE_DIR=cache)) == []  # both loaded from the cache


_OBJMODE_KERNEL = """
import numpy as np
from impstab._jit import njit, objmode


def host(x):
    return float(np.sum(x))


@njit(cache=True)
def kernel(x):
    with objmode(total="float64"):
        total = host(x)
    return 2.0 * total
"""

_ANNOUNCED_OBJMODE = """
import json, sys, numpy as np, impstab._jit as jit
lines = []
jit.announce_compiling(lines.append)
jit.require_compiled()
sys.path.insert(0, {folder!r})
from objmode_kernel import kernel
assert kernel(np.ones(3)) == 6.0
print(json.dumps(lines))
"""


def test_an_object_mode_block_is_not_announced_as_compiling(tmp_path):
    """numba makes the object-mode blocks of a kernel loaded from the cache again in every process
    (Python calls, not machine code; milliseconds): no line, or every run of the command would
    claim a first compile."""
    from impstab import _jit

    (tmp_path / "objmode_kernel.py").write_text(_OBJMODE_KERNEL, encoding="utf-8")
    code, cache = _ANNOUNCED_OBJMODE.format(folder=str(tmp_path)), str(tmp_path / "kernels")
    assert json.loads(_python(code, NUMBA_CACHE_DIR=cache)) == [_jit.COMPILING]
    assert json.loads(_python(code, NUMBA_CACHE_DIR=cache)) == []  # loaded from the cache, its block made again


def test_the_command_line_announces_compiling_on_standard_error(monkeypatch, capsys):
    from impstab import _jit
    from impstab.cli import main

    writers = []
    monkeypatch.setattr(_jit, "announce_compiling", writers.append)
    assert main(["--version"]) == 0
    assert len(writers) == 1
    writers[0]("a line")
    assert capsys.readouterr().err == "a line\n"
