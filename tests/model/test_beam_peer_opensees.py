"""Beam mounts against an independent beam code, OpenSees (openseespy, optional: skipped when it
is not installed or does not load): the clamped-free Timoshenko tip compliance and the first
natural frequencies.

OpenSees' ``ElasticTimoshenkoBeam`` (3-D, shear areas ``kappa A``, consistent mass without rotary
inertia) on 64 elements, clamped at one end. The beam is slender (``L / d = 50``) but soft in shear
(``E / G = 1000``), so that shear deformation moves its first bending frequency by about 1 % while
the rotary inertia that OpenSees leaves out moves it by ``(r / L)^2 ~ 1e-5``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from impstab.model.beam import BeamMount, tip_stiffness
from impstab.model.beam_dynamic import dynamic_stiffness_local

L, D, E, G, RHO, N = 1.0, 0.02, 2.0e9, 2.0e6, 1500.0, 64
BEAM = BeamMount(L, D, 0.0, E, G, density=RHO)


_PEER = r"""
import ctypes, importlib.util, json, os, sys
spec = importlib.util.find_spec("openseespylinux")
if spec is None or not spec.submodule_search_locations:
    print(json.dumps({"skip": "openseespy is not installed (optional: pip install 'impstab[peers]')"})); sys.exit()
lib = os.path.join(list(spec.submodule_search_locations)[0], "lib")
for name in ("libquadmath.so.0", "libgfortran.so.4", "libgomp.so.1", "libblas.so.3", "liblapack.so.3"):
    if os.path.exists(os.path.join(lib, name)):  # the BLAS/LAPACK it bundles, where the system has none
        ctypes.CDLL(os.path.join(lib, name), mode=ctypes.RTLD_GLOBAL)
try:
    import openseespylinux.opensees as ops
except Exception as exc:
    print(json.dumps({"skip": f"openseespy does not load here: {exc}"})); sys.exit()
L, E, G, rho, n, A, I, kap = (float(v) for v in sys.argv[1:])
n = int(n)

def cantilever():
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i in range(n + 1):
        ops.node(i, i * L / n, 0.0, 0.0)
    ops.fix(0, 1, 1, 1, 1, 1, 1)
    ops.geomTransf("Linear", 1, 0.0, 0.0, 1.0)
    for e in range(n):
        ops.element("ElasticTimoshenkoBeam", e + 1, e, e + 1, E, G, A, 2 * I, I, I, kap * A, kap * A, 1,
                    "-mass", rho * A, "-cMass")

columns = []
for dof in range(6):
    cantilever()
    ops.timeSeries("Constant", 1)
    ops.pattern("Plain", 1, 1)
    load = [0.0] * 6
    load[dof] = 1.0
    ops.load(n, *load)
    ops.system("FullGeneral"); ops.numberer("Plain"); ops.constraints("Plain"); ops.algorithm("Linear")
    ops.integrator("LoadControl", 1.0); ops.analysis("Static")
    assert ops.analyze(1) == 0
    columns.append(list(ops.nodeDisp(n)))
cantilever()
eig = ops.eigen("-fullGenLapack", 6)
ops.wipe()
print(json.dumps({"flexibility": columns, "omega2": list(eig)}))
"""


def _opensees_run():
    """Tip flexibility columns and the six lowest ``omega^2`` from OpenSees, in a process of its own
    (its bundled BLAS stays out of this one)."""
    import json
    import subprocess
    import sys

    args = [str(v) for v in (L, E, G, RHO, N, BEAM.area, BEAM.second_moment, BEAM.shear_coefficient)]
    out = subprocess.run([sys.executable, "-c", _PEER, *args], capture_output=True, text=True, timeout=300)
    lines = [ln for ln in out.stdout.splitlines() if ln.startswith("{")]
    if not lines:
        pytest.fail(f"the OpenSees run gave no result: {out.stderr[-2000:]}")
    data = json.loads(lines[-1])
    if "skip" in data:
        pytest.skip(data["skip"])
    return np.array(data["flexibility"]).T, np.array(data["omega2"])


def test_tip_compliance_and_frequencies_against_opensees():
    flex_ops, omega2 = _opensees_run()
    flexibility = np.linalg.inv(tip_stiffness(BEAM, [1.0, 0.0, 0.0]))
    for dof in range(6):
        assert np.abs(flex_ops[:, dof] - flexibility[:, dof]).max() <= 1e-9 * np.abs(flexibility[:, dof]).max(), dof
    f_ops = np.sqrt(omega2) / (2 * np.pi)

    # impstab's exact clamped-free frequencies: the zeros of the exact body-end dynamic stiffness
    # (bending plane e1-e2: dofs u2, theta3 of the body end; torsion: theta1)
    def det_bending(f):
        k = dynamic_stiffness_local(BEAM, [2 * np.pi * f])[0][0]
        return np.linalg.det(k[np.ix_([7, 11], [7, 11])]) / (E * BEAM.second_moment) ** 2

    def torsion(f):
        return dynamic_stiffness_local(BEAM, [2 * np.pi * f])[0][0][9, 9]

    exact = []
    for f, fun in ((f_ops[0], det_bending), (f_ops[2], torsion), (f_ops[3], det_bending)):
        exact.append(brentq(fun, 0.99 * f, 1.01 * f, xtol=1e-13))
    exact = np.array(exact)
    assert f_ops[0] == pytest.approx(f_ops[1], rel=1e-10)  # the two bending planes
    assert np.allclose(f_ops[[0, 2, 3]], exact, rtol=2e-4, atol=0), (f_ops, exact)
    # shear deformation matters here: the Euler-Bernoulli value lies 1 % above
    f_eb = 1.875104068711961**2 / (2 * np.pi * L**2) * np.sqrt(E * BEAM.second_moment / (RHO * BEAM.area))
    assert f_eb / exact[0] - 1 > 5e-3
