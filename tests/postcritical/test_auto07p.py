"""The AUTO-07p transcription of the propulsor model used by benchmarks/postcritical.py.

Optional: skipped without gfortran (the transcription) or AUTO-07p (the Hopf point).
Independent answers: impstab's compiled right-hand side at random states (the Fortran file is a
second, hand-written implementation of the same equations), and impstab's critical thrust and
onset frequency from its linear stability engine (AUTO finds the Hopf point from the
eigenvalues of its own finite-difference Jacobian of the Fortran equations).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impstab
from impstab.dynamics.system import NonlinearSystem

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))
import auto07p  # noqa: E402

DRIVER = """
PROGRAM DRIVER
  IMPLICIT NONE
  DOUBLE PRECISION :: U(12), PAR(36), F(12), DFDU(12, 12), DFDP(12, 36)
  INTEGER :: ICP(1), K, N
  ICP(1) = 1
  PAR = 0.0d0
  READ (*, *) N
  DO K = 1, N
    READ (*, *) PAR(1), U
    CALL FUNC(12, U, ICP, PAR, 0, F, DFDU, DFDP)
    WRITE (*, '(12ES26.17)') F
  END DO
END PROGRAM DRIVER
"""


def _tilted_model():
    """Hardening and softening cubic laws on tilted axes, a snubber, a thrust point off A, partial
    follower thrust and a spinning propeller (gyroscopic moment, speed law in the thrust)."""
    from impstab.model import model_from_dict
    from impstab.model.assemble import read_toml

    d = read_toml(ROOT / "examples" / "imp_hardening.toml")
    d["mounts"][0]["axis"] = [0.9, 0.3, 0.1]
    d["mounts"][0]["k3_axial"] = -2.0e8
    d["mounts"][2]["k3_axial"] = 5.0e8
    d["mounts"][1]["snubber_clearance"] = 0.004
    d["mounts"][1]["snubber_stiffness"] = 4.0e5
    d["thrust"]["point"] = [-0.4, 0.02, -0.01]
    d["thrust"]["tangency"] = 0.7
    d["propeller"] = {"polar_inertia": 0.8, "speed": 120.0, "speed_law": "sqrt-thrust"}
    return model_from_dict(d, name="tilted")


@pytest.mark.skipif(shutil.which("gfortran") is None, reason="gfortran not installed")
@pytest.mark.parametrize("which", ["imp_hardening", "imp_softening", "tilted"])
def test_fortran_equations_equal_impstab_rhs(tmp_path, which):
    model = _tilted_model() if which == "tilted" else impstab.load_model(ROOT / "examples" / f"{which}.toml")
    (tmp_path / "prop.f90").write_text(auto07p.transcribe(model))
    (tmp_path / "driver.f90").write_text(DRIVER)
    subprocess.run(["gfortran", "-O0", "prop.f90", "driver.f90", "-o", "drv"], cwd=tmp_path, check=True,
                   capture_output=True)
    ns = NonlinearSystem(model)
    rng = np.random.default_rng(7)
    scale = np.array([1e-2] * 3 + [0.1] * 3 + [0.5] * 3 + [2.0] * 3)
    states = rng.standard_normal((20, 12)) * scale
    thrusts = rng.uniform(0.0, 20000.0, 20)
    lines = ["20"] + [" ".join(repr(float(v)) for v in [t / auto07p.KN, *y]) for t, y in zip(thrusts, states)]
    out = subprocess.run(["./drv"], cwd=tmp_path, input="\n".join(lines) + "\n", capture_output=True, text=True,
                         check=True).stdout
    fortran = np.array([[float(v) for v in ln.split()] for ln in out.strip().splitlines()])
    expected = np.array([ns.rhs(y, t) for t, y in zip(thrusts, states)])
    scale_f = np.max(np.abs(expected), axis=0)
    np.testing.assert_allclose(fortran, expected, rtol=0, atol=1e-12 * scale_f.max())
    assert np.max(np.abs(fortran - expected) / np.maximum(np.abs(expected), 1e-300 + 1e-9 * scale_f)) < 1e-9


@pytest.mark.skipif(auto07p.available() is not None, reason=str(auto07p.available()))
@pytest.mark.parametrize("which", ["imp_hardening", "imp_softening"])
def test_auto_hopf_point_equals_critical_thrust(tmp_path, which):
    model = impstab.load_model(ROOT / "examples" / f"{which}.toml")
    crit = impstab.critical_thrust(model)
    exe, _ = auto07p.compile_model(model, tmp_path)
    hb, _, _ = auto07p.hopf_point(exe, tmp_path, model.analysis.thrust_max)
    assert hb.par[0] * auto07p.KN == pytest.approx(crit.thrust, rel=1e-6)
    assert 2 * np.pi / hb.par[10] == pytest.approx(crit.omega, rel=1e-6)
