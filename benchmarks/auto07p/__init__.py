"""The propulsor model in AUTO-07p: its equations of motion transcribed to Fortran, and the runs.

AUTO-07p (Doedel et al.; Debian package ``auto-07p``) continues equilibria and periodic orbits
of ``u' = f(u, par)`` written as a Fortran subroutine ``FUNC``. :func:`transcribe` writes that
file for an impstab model with the model's numbers baked in: the same 12 states as
:class:`impstab.dynamics.system.NonlinearSystem` (position of A, z-y-x Euler angles, body-frame
velocities), the same equations as :func:`impstab.dynamics.rhs.model_rhs` line by line (mounts
with 3 x 3 translational stiffness and damping, their cubic axial and shear laws and snubbers
with the smoothed ramp, follower and fixed thrust, propeller gyroscopic moment, Newton-Euler
Coriolis terms, fluid radiation damping, ``nu' = M^-1 tau``), and the thrust in kN as
``PAR(1)`` (so that the parameter and the states weigh alike in AUTO's unscaled arclength).
Mounts with rotational stiffness (6 x 6 mounts, beam mounts) are not transcribed (refused with
a ValueError).

:func:`run_branch` compiles it (gfortran, linked against AUTO's library objects as AUTO's own
``@r`` makefile does) and runs AUTO's executable directly, without its Python front end:

1. equilibria from ``T = 0`` (the unloaded state ``u = 0``) up in thrust, ``IPS = 1``: AUTO
   detects the Hopf point (HB) from the eigenvalues of its Jacobian;
2. periodic orbits from the HB point, ``IPS = 2``, ``ICP = [1, 11]`` (thrust and period):
   AUTO's orthogonal collocation (``NTST`` intervals, ``NCOL`` Gauss points, adaptive mesh
   ``IAD = 3``), pseudo-arclength steps, Floquet multipliers of every orbit (``ISP = 2``), each
   requested thrust located exactly as a user point (``UZR``), the last one ending the run
   (``UZSTOP``).

The amplitude of an AUTO orbit is measured on AUTO's own piecewise polynomial: its stored
solution holds the values at ``NCOL + 1`` equally spaced nodes per mesh interval, exactly the
representation of :class:`impstab.postcritical.collocation.Profile`, whose polished extrema
then give the half peak-to-peak of each coordinate.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["AUTO_DIR", "available", "transcribe", "compile_model", "hopf_point", "run_branch", "AutoBranch",
           "read_solutions", "amplitude", "KN"]

#: AUTO-07p's installation (Debian: /usr/lib/auto-07p)
AUTO_DIR = Path(os.environ.get("AUTO_DIR", "/usr/lib/auto-07p"))
#: thrust unit of PAR(1) (N)
KN = 1000.0
#: OpenMP threads of AUTO's runs: one (on a loaded two-core machine two threads ran 2.5 times
#: slower in wall-clock time, measured)
THREADS = 1


def available() -> str | None:
    """None when AUTO-07p and gfortran can be used, else the reason they cannot."""
    if not (AUTO_DIR / "lib" / "main.o").exists():
        return f"AUTO-07p not found (no {AUTO_DIR / 'lib' / 'main.o'}; Debian package auto-07p)"
    if shutil.which("gfortran") is None:
        return "gfortran not found (AUTO-07p's equations files are compiled with it)"
    return None


def _f(x: float) -> str:
    """A Fortran double-precision literal, exact (17 significant digits)."""
    s = f"{float(x):.17e}"
    mant, exp = s.split("e")
    return f"{mant}d{int(exp)}"


def _array(name: str, values: np.ndarray, shape: tuple[int, ...]) -> str:
    """``DOUBLE PRECISION, PARAMETER :: name(shape) = RESHAPE([...], [shape])`` (Fortran order)."""
    flat = [_f(v) for v in np.asarray(values, dtype=float).ravel(order="F")]
    lines = [", ".join(flat[k:k + 3]) for k in range(0, len(flat), 3)]
    body = ", &\n      ".join(lines)
    dims = ",".join(str(d) for d in shape)
    return f"  DOUBLE PRECISION, PARAMETER :: {name}({dims}) = RESHAPE([ &\n      {body}], [{dims}])\n"


def transcribe(model) -> str:
    """The AUTO-07p equations file (Fortran 90) of ``model``'s nonlinear equations of motion.

    ``PAR(1)`` is the thrust in kN; the state is ``NonlinearSystem``'s (absolute, not the
    deviation from the equilibrium); ``STPNT`` is the unloaded equilibrium ``u = 0`` at ``T = 0``.
    """
    from impstab.dynamics.rhs import (FLAG_ROTATION, P_CG, P_E, P_IA, P_JP, P_MASS, P_RADIATION, P_RT, P_TANG)
    from impstab.dynamics.system import NonlinearSystem
    from impstab.model.mount_law import (LAW_AXIS, LAW_CLEARANCE, LAW_K3_AXIAL, LAW_K3_SHEAR, LAW_SNUBBER,
                                         SNUBBER_SMOOTHING)

    ns = NonlinearSystem(model)
    pos, kmat, cmat, flags, laws, par, minv, damp6 = ns.system.arrays[:8]
    if np.any(flags & FLAG_ROTATION):
        raise ValueError("mounts with rotational stiffness or damping are not transcribed to AUTO-07p")
    nm = pos.shape[0]
    if laws.size == 0:
        laws = np.zeros((nm, 7))
    prop = model.propeller
    if prop.speed_law == "sqrt-thrust":
        spin = (f"{_f(prop.speed)} * SQRT(MAX(T, 0.0d0) / {_f(model.thrust.operating)})")
    else:
        spin = _f(prop.speed)
    src = ["! impstab model transcribed for AUTO-07p: " + model.name.replace("\n", " "),
           "! PAR(1): thrust (kN); U: X_A, Y_A, Z_A (m), phi, theta, psi (rad), u, v, w (m/s), p, q, r (rad/s)",
           "MODULE PROPMODEL", "  IMPLICIT NONE", f"  INTEGER, PARAMETER :: NM = {nm}"]
    src.append(_array("POS", pos.T, (3, nm)))
    src.append(_array("KM", kmat[:, :3, :3].transpose(1, 2, 0), (3, 3, nm)))
    src.append(_array("CM", cmat[:, :3, :3].transpose(1, 2, 0), (3, 3, nm)))
    src.append(_array("AX", laws[:, LAW_AXIS:LAW_AXIS + 3].T, (3, nm)))
    src.append(_array("K3A", laws[:, LAW_K3_AXIAL], (nm,)))
    src.append(_array("K3S", laws[:, LAW_K3_SHEAR], (nm,)))
    src.append(_array("CLR", laws[:, LAW_CLEARANCE], (nm,)))
    src.append(_array("KSN", laws[:, LAW_SNUBBER], (nm,)))
    src.append(f"  DOUBLE PRECISION, PARAMETER :: SMOOTH = {_f(SNUBBER_SMOOTHING)}\n")
    src.append(_array("MINV", minv, (6, 6)))
    src.append(_array("D6", damp6, (6, 6)))
    src.append(_array("IA", par[P_IA:P_IA + 9].reshape(3, 3), (3, 3)))
    src.append(_array("CG", par[P_CG:P_CG + 3], (3,)))
    src.append(_array("ED", par[P_E:P_E + 3], (3,)))
    src.append(_array("RT", par[P_RT:P_RT + 3], (3,)))
    src.append(f"  DOUBLE PRECISION, PARAMETER :: MASS = {_f(par[P_MASS])}, TANG = {_f(par[P_TANG])}, "
               f"&\n      JP = {_f(par[P_JP])}\n")
    src.append(f"  LOGICAL, PARAMETER :: RADIATION = {'.TRUE.' if par[P_RADIATION] != 0.0 else '.FALSE.'}")
    src.append("END MODULE PROPMODEL")
    src.append(_FUNC.replace("@SPIN@", spin))
    return "\n".join(src) + "\n"


_FUNC = r"""
SUBROUTINE CROSS(A, B, C)
  IMPLICIT NONE
  DOUBLE PRECISION, INTENT(IN) :: A(3), B(3)
  DOUBLE PRECISION, INTENT(OUT) :: C(3)
  C(1) = A(2) * B(3) - A(3) * B(2)
  C(2) = A(3) * B(1) - A(1) * B(3)
  C(3) = A(1) * B(2) - A(2) * B(1)
END SUBROUTINE CROSS

SUBROUTINE FUNC(NDIM, U, ICP, PAR, IJAC, F, DFDU, DFDP)
  USE PROPMODEL
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM, ICP(*), IJAC
  DOUBLE PRECISION, INTENT(IN) :: U(NDIM), PAR(*)
  DOUBLE PRECISION, INTENT(OUT) :: F(NDIM)
  DOUBLE PRECISION, INTENT(INOUT) :: DFDU(NDIM, NDIM), DFDP(NDIM, *)
  DOUBLE PRECISION :: T, R(3, 3), CF, SF, CT, ST, CP, SP, TT, X(3), VB(3), WB(3), VH(3), WH(3)
  DOUBLE PRECISION :: FH(3), MH(3), RHO(3), D(3), DD(3), G(3), C(3), DA, S(3), CA, CS, L(3)
  DOUBLE PRECISION :: RE(3), TH(3), RTH(3), TAU(6), H(3), WV(3), WG(3), WWG(3), IW(3), NU(6)
  DOUBLE PRECISION :: R2, RR, WW, TS, RAMP
  INTEGER :: I
  T = PAR(1) * 1000.0d0
  X = U(1:3)
  VB = U(7:9)
  WB = U(10:12)
  CF = COS(U(4)); SF = SIN(U(4))
  CT = COS(U(5)); ST = SIN(U(5))
  CP = COS(U(6)); SP = SIN(U(6))
  ! rotation body -> hull, z-y-x Euler angles
  R(1, 1) = CP * CT
  R(1, 2) = -SP * CF + CP * ST * SF
  R(1, 3) = SP * SF + CP * CF * ST
  R(2, 1) = SP * CT
  R(2, 2) = CP * CF + SP * ST * SF
  R(2, 3) = -CP * SF + SP * ST * CF
  R(3, 1) = -ST
  R(3, 2) = CT * SF
  R(3, 3) = CT * CF
  VH = MATMUL(R, VB)
  WH = MATMUL(R, WB)
  ! kinematics
  F(1:3) = VH
  TT = ST / CT
  F(4) = WB(1) + SF * TT * WB(2) + CF * TT * WB(3)
  F(5) = CF * WB(2) - SF * WB(3)
  F(6) = (SF * WB(2) + CF * WB(3)) / CT
  ! mounts: force on the body (hull frame), moment about A
  FH = 0.0d0
  MH = 0.0d0
  DO I = 1, NM
    RHO = MATMUL(R, POS(:, I))
    D = X + RHO - POS(:, I)
    CALL CROSS(WH, RHO, C)
    DD = VH + C
    G = MATMUL(KM(:, :, I), D) + MATMUL(CM(:, :, I), DD)
    DA = DOT_PRODUCT(AX(:, I), D)
    S = D - DA * AX(:, I)
    CA = K3A(I) * DA**3
    CS = K3S(I) * DOT_PRODUCT(S, S)
    G = G + CA * AX(:, I) + CS * S
    IF (CLR(I) > 0.0d0) THEN
      ! snubber: k_snub ramp(|d| - c) d / |d|, the ramp C2-smoothed over SMOOTH c
      R2 = DOT_PRODUCT(D, D)
      IF (R2 > CLR(I)**2) THEN
        RR = SQRT(R2)
        WW = SMOOTH * CLR(I)
        TS = (RR - CLR(I)) / WW
        IF (TS < 1.0d0) THEN
          RAMP = WW * TS**3 * (1.0d0 - 0.5d0 * TS)
        ELSE
          RAMP = RR - CLR(I) - 0.5d0 * WW
        END IF
        G = G + KSN(I) * RAMP / RR * D
      END IF
    END IF
    L = -G
    CALL CROSS(RHO, L, C)
    FH = FH + L
    MH = MH + C
  END DO
  ! thrust: follower part along R e, fixed part along e, at R r_T
  RE = MATMUL(R, ED)
  TH = T * (TANG * RE + (1.0d0 - TANG) * ED)
  RTH = MATMUL(R, RT)
  CALL CROSS(RTH, TH, C)
  FH = FH + TH
  MH = MH + C
  TAU(1:3) = MATMUL(TRANSPOSE(R), FH)
  TAU(4:6) = MATMUL(TRANSPOSE(R), MH)
  ! propeller gyroscopic moment -w x h, h = J_p Omega e
  H = JP * (@SPIN@) * ED
  CALL CROSS(WB, H, C)
  TAU(4:6) = TAU(4:6) - C
  ! Coriolis-centripetal terms (Newton-Euler form)
  CALL CROSS(WB, VB, WV)
  CALL CROSS(WB, CG, WG)
  CALL CROSS(WB, WG, WWG)
  TAU(1:3) = TAU(1:3) - MASS * (WV + WWG)
  IW = MATMUL(IA, WB)
  CALL CROSS(WB, IW, C)
  TAU(4:6) = TAU(4:6) - C
  CALL CROSS(CG, WV, C)
  TAU(4:6) = TAU(4:6) - MASS * C
  IF (RADIATION) THEN
    NU(1:3) = VB
    NU(4:6) = WB
    TAU = TAU - MATMUL(D6, NU)
  END IF
  F(7:12) = MATMUL(MINV, TAU)
END SUBROUTINE FUNC

SUBROUTINE STPNT(NDIM, U, PAR, T)
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM
  DOUBLE PRECISION, INTENT(INOUT) :: U(NDIM), PAR(*)
  DOUBLE PRECISION, INTENT(IN) :: T
  PAR(1) = 0.0d0
  U = 0.0d0
END SUBROUTINE STPNT

SUBROUTINE BCND
END SUBROUTINE BCND

SUBROUTINE ICND
END SUBROUTINE ICND

SUBROUTINE FOPT
END SUBROUTINE FOPT

SUBROUTINE PVLS
END SUBROUTINE PVLS
"""


@dataclass(frozen=True)
class Solution:
    """One labelled solution of an AUTO solution file (fort.8)."""

    label: int
    kind: int                     # AUTO's ITP: 3 HB, -4 / 4 user point, 9 / -9 end point, ...
    ntst: int
    ncol: int
    times: np.ndarray             # (NTST NCOL + 1,) scaled time of the stored rows
    states: np.ndarray            # (NTST NCOL + 1, NDIM)
    par: np.ndarray               # PAR(1..NPAR)


def read_solutions(path: Path) -> list[Solution]:
    """Every solution of an AUTO-07p solution file (``fort.8`` / ``s.*``)."""
    lines = Path(path).read_text().splitlines()
    out = []
    k = 0
    while k < len(lines):
        head = lines[k].split()
        if not head:
            k += 1
            continue
        itp, lab, ntpl, nar, nrowpr, ntst, ncol, npar = (int(head[2]), int(head[3]), int(head[6]), int(head[7]),
                                                        int(head[8]), int(head[9]), int(head[10]), int(head[11]))
        block = lines[k + 1:k + 1 + nrowpr]
        k += 1 + nrowpr
        tokens = [float(v) for ln in block for v in ln.replace("D", "E").split()]
        rows = np.array(tokens[:ntpl * nar]).reshape(ntpl, nar)
        par = np.array(tokens[-npar:])
        out.append(Solution(lab, itp, ntst, ncol, rows[:, 0], rows[:, 1:], par))
    return out


def amplitude(sol: Solution) -> np.ndarray:
    """Half peak-to-peak of each state over AUTO's orbit, on its piecewise polynomial."""
    from impstab.postcritical.collocation import Profile

    m = sol.ncol
    mesh = sol.times[::m]
    return Profile(mesh, sol.states[:-1], m).amplitude()


@dataclass(frozen=True)
class AutoBranch:
    """AUTO-07p's branch at the requested thrusts and its timings."""

    thrust: np.ndarray            # (k,) N, the requested thrusts AUTO located
    period: np.ndarray            # (k,) s
    amplitude: np.ndarray         # (k, 12) half peak-to-peak of every state
    hopf_thrust: float            # N, AUTO's HB point
    hopf_omega: float             # rad/s, 2 pi / period stored at the HB point
    ntst: int
    ncol: int
    compile_seconds: float
    run_seconds: float            # both AUTO runs (equilibria, periodic orbits), compilation excluded
    points: int                   # continuation points of the periodic run
    log: str = field(repr=False, default="")

    @property
    def seconds(self) -> float:
        return self.compile_seconds + self.run_seconds


def _constants(**kw) -> str:
    out = []
    for key, value in kw.items():
        if isinstance(value, float):
            value = repr(value)
        out.append(f"{key}={value}")
    return "\n".join(out) + "\n"


def _run(exe: Path, work: Path, constants: str) -> tuple[str, float]:
    (work / "fort.2").write_text(constants)
    t0 = time.perf_counter()
    env = dict(os.environ, OMP_NUM_THREADS=str(THREADS))
    proc = subprocess.run([str(exe)], cwd=work, capture_output=True, text=True, timeout=600, env=env)
    dt = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"AUTO-07p run failed ({proc.returncode}): {proc.stdout[-2000:]} {proc.stderr[-2000:]}")
    return proc.stdout, dt


def compile_model(model, work: Path) -> tuple[Path, float]:
    """Write ``model``'s equations file into ``work`` and build AUTO's executable from it, as
    AUTO's ``@r`` makefile does; returns the executable and the seconds it took."""
    why = available()
    if why:
        raise RuntimeError(why)
    work = Path(work)
    (work / "prop.f90").write_text(transcribe(model))
    libs = sorted(str(p) for p in (AUTO_DIR / "lib").glob("*.o"))
    t0 = time.perf_counter()
    for cmd in (["gfortran", "-O2", "-fopenmp", "-c", "prop.f90", "-o", "prop.o"],
                ["gfortran", "-O2", "-fopenmp", "prop.o", "-o", "prop.exe", *libs]):
        proc = subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=300)
        if proc.returncode != 0:
            raise RuntimeError(f"compiling the AUTO-07p equations failed: {proc.stderr[-2000:]}")
    return work / "prop.exe", time.perf_counter() - t0


def _common(tolerance: float, location_tolerance: float) -> dict:
    return dict(NDIM=12, ILP=1, NBC=0, NINT=0, ISW=1, IPLT=0, MXBF=10, IID=2, ITMX=20, ITNW=7, NWTN=3,
                JAC=0, EPSL=float(tolerance), EPSU=float(tolerance), EPSS=float(location_tolerance))


def hopf_point(exe: Path, work: Path, thrust_max: float, *, tolerance: float = 1e-10,
               location_tolerance: float = 1e-9) -> tuple[Solution, float, str]:
    """AUTO's equilibria from the unloaded state ``u = 0`` at ``T = 0`` up in thrust (``IPS = 1``)
    to the first Hopf point it detects (``STOP = ['HB1']``); returns that solution (``PAR(1)``
    in kN, ``PAR(11)`` the period at the onset), the seconds and AUTO's log. Its solution file
    stays in ``work/fort.8``."""
    log, seconds = _run(exe, work, _constants(
        IPS=1, IRS=0, ICP="[1]", NTST=10, NCOL=4, IAD=3, ISP=1, NMX=500, NPR=1000, DS=0.2,
        DSMIN=1e-6, DSMAX=0.5, IADS=1, RL0=-0.1, RL1=float(thrust_max) / KN, A0=0.0, A1=1e3, STOP="['HB1']",
        **_common(tolerance, location_tolerance)))
    hb = [s for s in read_solutions(Path(work) / "fort.8") if s.kind == 3]
    if not hb:
        raise RuntimeError("AUTO-07p found no Hopf point on the equilibrium branch:\n" + log[-2000:])
    return hb[0], seconds, log


def run_branch(model, thrusts, thrust_max: float, *, ntst: int = 40, ncol: int = 4, ds: float = 0.01,
               ds_max: float = 0.05, tolerance: float = 1e-10, location_tolerance: float = 1e-9,
               max_points: int = 2000, workdir: Path | None = None) -> AutoBranch:
    """AUTO-07p's equilibria to the Hopf point and its periodic orbits through ``thrusts`` (N).

    ``ds``, ``ds_max`` are AUTO's arclength steps (in its unscaled norm, thrust in kN);
    ``tolerance`` is its Newton tolerance on the states and the parameter (EPSU, EPSL);
    ``location_tolerance`` (EPSS) that of its special and user points (with AUTO's default 1e-6 a
    requested thrust is located to some 1e-5 N, an amplitude error of 5e-8 near the onset). The
    last thrust ends the run. JAC = 0: AUTO differentiates ``FUNC`` by finite differences.
    """
    thrusts = np.sort(np.asarray(thrusts, dtype=float))
    own = workdir is None
    work = Path(tempfile.mkdtemp(prefix="impstab-auto07p-")) if own else Path(workdir)
    try:
        exe, t_compile = compile_model(model, work)
        hb, t1, log1 = hopf_point(exe, work, thrust_max, tolerance=tolerance, location_tolerance=location_tolerance)
        shutil.copy(work / "fort.8", work / "fort.3")
        # periodic orbits from the Hopf point through the requested thrusts
        uzr = ", ".join(repr(float(t) / KN) for t in thrusts[:-1])
        log2, t2 = _run(exe, work, _constants(
            IPS=2, IRS=hb.label, ICP="[1, 11]", NTST=ntst, NCOL=ncol, IAD=3, ISP=2, NMX=int(max_points),
            NPR=100000, DS=float(ds), DSMIN=1e-8, DSMAX=float(ds_max), IADS=1, RL0=0.0,
            RL1=float(thrust_max) / KN * 1.01, A0=0.0, A1=1e3, UZR="{1: [" + uzr + "]}",
            UZSTOP="{1: " + repr(float(thrusts[-1]) / KN) + "}", **_common(tolerance, location_tolerance)))
        orbits = [s for s in read_solutions(work / "fort.8") if s.kind in (4, -4, 9, -9)]
        found = []
        for t in thrusts:
            best = min(orbits, key=lambda s: abs(s.par[0] * KN - t), default=None)
            if best is None or abs(best.par[0] * KN - t) > 1e-6 * t:
                raise RuntimeError(f"AUTO-07p's periodic branch has no orbit at {t:.3f} N:\n" + log2[-3000:])
            found.append(best)
        b = [ln for ln in (work / "fort.7").read_text().splitlines() if ln.strip() and not ln.lstrip().startswith("0")]
        return AutoBranch(thrust=thrusts, period=np.array([s.par[10] for s in found]),
                          amplitude=np.array([amplitude(s) for s in found]), hopf_thrust=float(hb.par[0] * KN),
                          hopf_omega=float(2 * math.pi / hb.par[10]), ntst=ntst, ncol=ncol,
                          compile_seconds=t_compile, run_seconds=t1 + t2, points=len(b), log=log1 + log2)
    finally:
        if own:
            shutil.rmtree(work, ignore_errors=True)
