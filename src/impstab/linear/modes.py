"""Natural frequencies, damping, growth rates and mode shapes at one thrust."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..model.model import DOF_NAMES, Model
from .critical import TOL_DUPLICATE
from .eigen import kinetic_shares
from .linearize import linearize
from .system import LinearSystem

__all__ = ["ModalResult", "modes", "modes_of_system"]


@dataclass(frozen=True, eq=False)
class ModalResult:
    """Modes of the linearized system at thrust ``thrust``, sorted by frequency.

    One entry per mode: a complex pair counts once (``omega >= 0``); a real eigenvalue (an
    overdamped or divergent motion) is its own entry with ``omega = 0``.

    Attributes
    ----------
    eigenvalues : (k,) complex
        ``lambda = sigma + i omega`` (1/s).
    shapes : (6, k) complex
        Displacement shapes, largest component 1.
    participation : (k, 6)
        Kinetic-energy share of each dof in each mode.
    """

    thrust: float
    linearization: str
    eigenvalues: NDArray[np.complex128]
    shapes: NDArray[np.complex128]
    participation: NDArray[np.float64]

    def __repr__(self) -> str:
        from ..display import modal_text

        return modal_text(self)

    def _repr_html_(self) -> str:
        from ..display import modal_html

        return modal_html(self)

    @property
    def omega(self) -> NDArray[np.float64]:
        """Damped angular frequency (rad/s)."""
        return np.abs(self.eigenvalues.imag)

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        return self.omega / (2 * np.pi)

    @property
    def growth_rate(self) -> NDArray[np.float64]:
        """``sigma = Re(lambda)`` (1/s); positive means growing."""
        return self.eigenvalues.real

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``zeta = -sigma / |lambda|`` (negative for a growing mode)."""
        mag = np.abs(self.eigenvalues)
        return np.where(mag > 0, -self.eigenvalues.real / np.where(mag > 0, mag, 1), 0.0)

    @property
    def stable(self) -> bool:
        scale = max(np.abs(self.eigenvalues).max(), 1e-300)
        return bool(np.all(self.growth_rate <= 1e-9 * scale))

    def dominant(self, threshold: float = 0.2) -> list[tuple[str, ...]]:
        """Dof names carrying at least ``threshold`` of each mode's kinetic energy."""
        return [tuple(n for n, s in zip(DOF_NAMES, row) if s >= threshold) for row in self.participation]

    def to_dict(self) -> dict:
        return {
            "thrust": self.thrust,
            "linearization": self.linearization,
            "modes": [
                {
                    "omega": float(self.omega[j]),
                    "frequency_hz": float(self.frequency_hz[j]),
                    "growth_rate": float(self.growth_rate[j]),
                    "damping_ratio": float(self.damping_ratio[j]),
                    "dominant": list(self.dominant()[j]),
                    "shape_real": self.shapes[:, j].real.tolist(),
                    "shape_imag": self.shapes[:, j].imag.tolist(),
                }
                for j in range(len(self.eigenvalues))
            ],
        }

    def to_xarray(self):
        import xarray as xr

        from .. import __version__

        return xr.Dataset(
            {
                "omega": ("mode", self.omega, {"units": "rad/s"}),
                "frequency_hz": ("mode", self.frequency_hz, {"units": "Hz"}),
                "growth_rate": ("mode", self.growth_rate, {"units": "1/s"}),
                "damping_ratio": ("mode", self.damping_ratio, {"units": "1"}),
                "shape_real": (("dof", "mode"), self.shapes.real),
                "shape_imag": (("dof", "mode"), self.shapes.imag),
                "participation": (("mode", "dof"), self.participation),
            },
            coords={"mode": np.arange(len(self.eigenvalues)), "dof": list(DOF_NAMES)},
            attrs={"thrust": self.thrust, "linearization": self.linearization, "impstab_version": __version__},
        )


def _undamped_eigenpairs(system: LinearSystem):
    """``lambda = i sqrt(s)`` from ``K x = s M x``: exact zero growth for real positive s.

    A complex pair ``s, conj(s)`` (flutter) gives one growing and one decaying root at the same
    frequency; a negative real s (divergence) gives ``lambda = +sqrt(-s)``.
    """
    s, x = np.linalg.eig(np.linalg.solve(system.M, system.K))
    scale = max(np.abs(s).max(), 1e-300)
    real = np.abs(s.imag) <= 1e-12 * scale
    root = np.where(real, np.sqrt(np.abs(s.real)) + 0j, np.sqrt(s.astype(complex)))
    lam = np.where(real & (s.real >= 0), 1j * root, np.where(real, root, 1j * root))
    lam = np.where(~real & (lam.imag < 0), -lam, lam)
    return lam, x


def _canonical_repeated(vals: NDArray, vecs: NDArray, m_diag: NDArray) -> NDArray:
    """A basis of each repeated eigenvalue's eigenspace that does not depend on the eigensolver.

    Any basis of the eigenspace of a repeated eigenvalue is as good as another, and LAPACK
    returns an arbitrary one: on a symmetric layout it mixes the sway-yaw and heave-pitch
    planes. Here ``g`` pivot dofs are chosen by QR with column pivoting of the mass-weighted
    vectors, and the basis is the one whose vectors are 1 at their own pivot and 0 at the
    others: on a symmetric layout exactly the two planes' modes. An exactly defective group
    (dependent vectors) is left as it is.
    """
    from scipy.linalg import qr

    scale = max(float(np.abs(vals).max(initial=0.0)), 1e-300)
    out = vecs.copy()
    start = 0
    while start < len(vals):
        stop = start + 1
        while stop < len(vals) and abs(vals[stop] - vals[start]) <= TOL_DUPLICATE * scale:
            stop += 1
        if stop - start > 1:
            v = vecs[:, start:stop]
            _, _, piv = qr((v * np.sqrt(m_diag)[:, None]).T, pivoting=True)
            piv = np.sort(piv[: stop - start])
            block = v[piv, :]
            if np.linalg.cond(block) < 1e8:
                basis = v @ np.linalg.inv(block)
                # listed by their first dof (sway before heave), for a stable order
                w = np.abs(basis) * np.sqrt(m_diag)[:, None]
                first = np.argmax(w > 1e-8 * w.max(axis=0, keepdims=True), axis=0)
                out[:, start:stop] = basis[:, np.argsort(first, kind="stable")]
        start = stop
    return out


def modes_of_system(system: LinearSystem) -> ModalResult:
    """Modes of a :class:`LinearSystem`."""
    if not (np.any(system.D) or np.any(system.G)):
        vals, vecs = _undamped_eigenpairs(system)
    else:
        vals, vecs = np.linalg.eig(system.state_matrix())
        scale = max(np.abs(vals).max(), 1e-300)
        keep = (vals.imag > 1e-12 * scale) | (np.abs(vals.imag) <= 1e-12 * scale)
        vals, vecs = vals[keep], vecs[:6, keep]
    vals, vecs = np.asarray(vals, dtype=complex), np.asarray(vecs, dtype=complex)
    order = np.lexsort((vals.real, np.abs(vals.imag)))
    vals, vecs = vals[order], vecs[:, order]
    vecs = _canonical_repeated(vals, vecs, np.diag(system.M))
    big = np.argmax(np.abs(vecs), axis=0)
    piv = vecs[big, np.arange(vecs.shape[1])]
    shapes = vecs / piv
    part = np.array([kinetic_shares(shapes[:, [j]], system.M) for j in range(shapes.shape[1])])
    return ModalResult(system.thrust, system.linearization, vals, shapes, part)


def modes(model: Model, thrust: float = 0.0, linearization: str | None = None) -> ModalResult:
    """Natural frequencies, damping ratios, growth rates and mode shapes at thrust ``thrust`` (N).

    With compressible fluid loading each mode is computed with the added mass and radiation
    damping at its own frequency, iterated to consistency (fixed point on the frequency).
    """
    base = modes_of_system(linearize(model, thrust, linearization))
    if not model.fluid.compressible:
        return base
    return _fluid_consistent(model, thrust, linearization, base)


def _fluid_consistent(model: Model, thrust: float, linearization: str | None, base: ModalResult) -> ModalResult:
    from .linearize import ModelFamily

    vals, shapes, part = base.eigenvalues.copy(), base.shapes.copy(), base.participation.copy()
    for j in range(len(vals)):
        f = abs(vals[j].imag) / (2 * np.pi)
        for _ in range(50):
            fam = ModelFamily(model, linearization, fluid_frequency=f)
            m, d, g, k, u0, r0 = fam.evaluate(np.array([thrust]))
            res = modes_of_system(LinearSystem(m[0], d[0], g[0], k[0], thrust, fam.linearization, u0[0], r0[0]))
            i = int(np.argmin(np.abs(res.eigenvalues - vals[j])))
            vals[j], shapes[:, j], part[j] = res.eigenvalues[i], res.shapes[:, i], res.participation[i]
            f_new = abs(vals[j].imag) / (2 * np.pi)
            if abs(f_new - f) <= 1e-12 * max(f_new, 1e-300):
                break
            f = f_new
    return ModalResult(base.thrust, base.linearization, vals, shapes, part)
