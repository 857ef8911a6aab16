"""Eigenvalue loci against thrust (the paper's Figure 4), computed in one batch and tracked."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError
from ..limits import check_number
from ..model.model import Model
from .eigen import state_matrices
from .linearize import ModelFamily
from .tracking import track_modes

__all__ = ["LocusResult", "locus"]


@dataclass(frozen=True, eq=False)
class LocusResult:
    """Eigenvalues of the state matrix along a thrust sweep, one column per tracked branch.

    Attributes
    ----------
    thrust : (N,) thrusts (N)
    eigenvalues : (N, 12) complex, ``lambda = sigma + i omega`` (1/s), tracked by MAC
    linearization : str
    model_name : str
    critical_thrust : float or None
        The critical thrust when it was computed alongside (drawn as a marker line).
    """

    thrust: NDArray[np.float64]
    eigenvalues: NDArray[np.complex128]
    linearization: str
    model_name: str = ""
    critical_thrust: float | None = None
    operating_thrust: float | None = None

    @property
    def growth_rate(self) -> NDArray[np.float64]:
        return self.eigenvalues.real

    @property
    def omega(self) -> NDArray[np.float64]:
        return self.eigenvalues.imag

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        return self.eigenvalues.imag / (2 * np.pi)

    def to_xarray(self):
        """Dataset with coordinates ``thrust`` and ``branch``; settings in ``attrs``."""
        import xarray as xr

        from .. import __version__

        attrs = {
            "title": f"eigenvalue loci of {self.model_name}",
            "linearization": self.linearization,
            "model": self.model_name,
            "impstab_version": __version__,
            "convention": "lambda = sigma + i omega, x(t) = Re(X exp(lambda t)); frequency_hz = omega / 2 pi",
        }
        if self.critical_thrust is not None:
            attrs["critical_thrust"] = self.critical_thrust
        if self.operating_thrust is not None:
            attrs["operating_thrust"] = self.operating_thrust
        return xr.Dataset(
            {
                "growth_rate": (("thrust", "branch"), self.growth_rate, {"units": "1/s", "long_name": "Re(lambda)"}),
                "omega": (("thrust", "branch"), self.omega, {"units": "rad/s", "long_name": "Im(lambda)"}),
                "frequency_hz": (("thrust", "branch"), self.frequency_hz, {"units": "Hz"}),
            },
            coords={
                "thrust": ("thrust", self.thrust, {"units": "N"}),
                "branch": np.arange(self.eigenvalues.shape[1]),
            },
            attrs=attrs,
        )

    @classmethod
    def from_xarray(cls, ds) -> "LocusResult":
        lam = ds["growth_rate"].values + 1j * ds["omega"].values
        return cls(
            ds["thrust"].values, lam, ds.attrs.get("linearization", ""), ds.attrs.get("model", ""),
            ds.attrs.get("critical_thrust"), ds.attrs.get("operating_thrust"),
        )

    def plot(self, ax=None):
        """Frequency (Hz) and growth rate (1/s) against thrust; returns the axes.

        ``ax`` may be None (a new figure with two stacked axes), one Axes (frequency only) or a
        pair of Axes.
        """
        from ..plot.locus import plot_locus

        return plot_locus(self, ax=ax)


def locus(
    model: Model,
    thrusts: NDArray[np.float64] | None = None,
    *,
    linearization: str | None = None,
    steps: int = 200,
    thrust_max: float | None = None,
) -> LocusResult:
    """Eigenvalue loci of ``model`` over ``thrusts`` (N), evaluated in one batch and tracked.

    Parameters
    ----------
    model : Model
    thrusts : array_like, optional
        Thrust values; default ``steps + 1`` values from 0 to ``thrust_max``.
    linearization : {"equilibrium", "classical"}, optional
    steps : int
        Number of intervals when ``thrusts`` is not given.
    thrust_max : float, optional
        Default ``model.analysis.thrust_max``.
    """
    if thrusts is None:
        if steps < 1:
            raise ModelError("steps", steps, "must be at least 1")
        t_max = check_number("thrust_max", thrust_max if thrust_max is not None else model.analysis.thrust_max, "thrust")
        thrusts = np.linspace(0.0, t_max, steps + 1)
    thrusts = np.asarray(thrusts, dtype=float)
    if thrusts.ndim != 1 or not np.all(np.isfinite(thrusts)):
        raise ModelError("thrusts", thrusts.tolist(), "must be a 1-D list of finite numbers")
    fam = ModelFamily(model, linearization)
    m, d, g, k = fam.matrices(thrusts)
    # the family has no matrices (NaN) where no static equilibrium exists: the locus ends there
    finite = np.isfinite(k).all(axis=(-2, -1)) & np.isfinite(m).all(axis=(-2, -1)) & np.isfinite(d + g).all(axis=(-2, -1))
    if not finite.all():
        end = int(np.argmin(finite))
        if end < 2:
            raise ModelError("thrust_max", float(thrusts[-1]), f"no static equilibrium is found from {thrusts[end]:g} N "
                             "on: the mounts do not carry the thrust (a locus needs two thrusts)")
        thrusts, m, d, g, k = thrusts[:end], m[:end], d[:end], g[:end], k[:end]
    vals, vecs = np.linalg.eig(state_matrices(m, d + g, k))
    vals, vecs = track_modes(vals, vecs)
    return LocusResult(thrusts, vals, fam.linearization, model.name, None, model.thrust.operating)  # type: ignore[arg-type]
