"""Frequency-dependent (viscoelastic) mount laws and their causal Prony realisation.

A viscoelastic mount scales its static 3 x 3 translation stiffness ``k`` (from ``k_axial`` and
``k_shear``) by a complex ratio ``r(omega) = k*(omega) / k0``:

* standard linear solid: ``r = (1 + i w s tau) / (1 + i w tau)``, a one-term Prony series with
  ``g = s - 1``; relaxation ``k(t) / k0 = s - (s - 1) (1 - exp(-t / tau))`` = ``1 + g exp(-t / tau)``;
* Prony series: ``r = 1 + sum_j g_j i w tau_j / (1 + i w tau_j)``;
* fractional Zener: ``r = (1 + s (i w tau)^alpha) / (1 + (i w tau)^alpha)``;
* table (a measured ISO 10846 data sheet): ``r(f) = s(f) (1 + i eta(f))``, interpolated by
  monotone cubics (PCHIP) in log frequency, held constant outside the table.

In the time domain a Prony term j is an internal 3-vector ``z_j`` (hull frame): the mount force
is ``f = k d + sum_j g_j k (d - z_j)`` with ``tau_j z_j' = d - z_j``; at rest ``z_j = d`` and the
force is the static ``k d``. The fractional law and the table have no finite realisation: they
are fitted by a Prony series (:func:`fit_prony`: relaxation times log-spaced over the fit band,
weights >= 0 by non-negative least squares on the relative complex error, ``scipy.optimize.nnls``)
whose largest relative error ``|r_fit - r| / |r|`` over the band is stored with the law.

A table whose loss factor does not vanish at its lowest frequency (a constant loss factor,
hysteretic damping) is non-causal: no Prony series reaches it at low frequency. The forced
response uses the table itself; the stability analysis uses the causal Prony fit over the
table's band (its error stated) and checks each onset on the exact table at the onset frequency
(:mod:`impstab.linear.viscoelastic`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["ViscoelasticLaw", "LAWS", "fit_prony", "prony_ratio", "FIT_POINTS_PER_DECADE", "FIT_DECADES_FRACTIONAL"]

Array = NDArray[np.float64]

LAWS = ("standard-linear-solid", "prony", "fractional-zener", "table")
#: frequencies per decade at which a fit is made and its error measured
FIT_POINTS_PER_DECADE = 40
#: default fit band of the fractional Zener law: this many decades either side of 1 / (2 pi tau)
FIT_DECADES_FRACTIONAL = 2.0


def prony_ratio(lam: complex | Array, g: Array, tau: Array) -> Array:
    """``1 + sum_j g_j lam tau_j / (1 + lam tau_j)`` at Laplace variables ``lam`` (``i omega`` on the axis)."""
    lam = np.asarray(lam, dtype=complex)[..., None]
    x = lam * np.asarray(tau, dtype=float)
    return 1.0 + (np.asarray(g, dtype=float) * x / (1.0 + x)).sum(axis=-1)


def _prony_dratio(lam, g, tau):
    lam = np.asarray(lam, dtype=complex)[..., None]
    tau = np.asarray(tau, dtype=float)
    return (np.asarray(g, dtype=float) * tau / (1.0 + lam * tau) ** 2).sum(axis=-1)


def fit_prony(omega: Array, target: Array, tau: Array) -> tuple[Array, float]:
    """Non-negative Prony weights ``g_j`` for the given relaxation times that fit ``target``.

    Minimises ``sum_w |(r_fit(i w) - target(w)) / target(w)|^2`` over ``g >= 0``
    (``scipy.optimize.nnls`` on the stacked real and imaginary parts). Returns ``g`` and the
    largest relative error ``max_w |r_fit - target| / |target|``.
    """
    from scipy.optimize import nnls

    omega = np.asarray(omega, dtype=float)
    target = np.asarray(target, dtype=complex)
    x = 1j * omega[:, None] * tau[None, :]
    basis = x / (1.0 + x)
    scale = 1.0 / np.abs(target)
    a = np.concatenate([basis.real * scale[:, None], basis.imag * scale[:, None]])
    b = np.concatenate([(target.real - 1.0) * scale, target.imag * scale])
    g, _ = nnls(a, b)
    err = float(np.max(np.abs(prony_ratio(1j * omega, g, tau) - target) * scale))
    return g, err


@dataclass(frozen=True, eq=False)
class ViscoelasticLaw:
    """A frequency-dependent mount law and the Prony series that realises it in the time domain.

    Build it with :meth:`standard_linear_solid`, :meth:`prony`, :meth:`fractional_zener` or
    :meth:`table`.

    Attributes
    ----------
    law : {"standard-linear-solid", "prony", "fractional-zener", "table"}
    weights, relaxation_times : (n,) arrays
        The Prony series ``g_j`` (dimensionless, >= 0) and ``tau_j`` (s) of the time-domain
        realisation: exact for the first two laws, fitted for the others.
    fit_error : float
        Largest relative error ``|r_fit - r| / |r|`` of the series against the law over
        ``fit_band_hz`` (0 for an exact series).
    fit_band_hz : (2,) array or None
        Band of the fit (Hz); None for an exact series.
    stiffening, relaxation_time, alpha : float or None
        Parameters of the standard linear solid and the fractional Zener law.
    frequency_hz, storage_ratio, loss_factor : arrays or None
        The table.
    """

    law: str
    weights: Array
    relaxation_times: Array
    fit_error: float = 0.0
    fit_band_hz: Array | None = None
    stiffening: float | None = None
    relaxation_time: float | None = None
    alpha: float | None = None
    frequency_hz: Array | None = None
    storage_ratio: Array | None = None
    loss_factor: Array | None = None

    def __post_init__(self) -> None:
        for name in ("weights", "relaxation_times", "fit_band_hz", "frequency_hz", "storage_ratio", "loss_factor"):
            value = getattr(self, name)
            if value is not None:
                arr = np.array(value, dtype=float).reshape(-1)
                arr.setflags(write=False)
                object.__setattr__(self, name, arr)
        if self.law not in LAWS:
            raise ValueError(f"ViscoelasticLaw.law = {self.law!r}: must be one of {list(LAWS)}")
        if self.weights.shape != self.relaxation_times.shape:
            raise ValueError("ViscoelasticLaw: weights and relaxation_times must have the same length")
        if np.any(self.weights < 0) or np.any(self.relaxation_times <= 0):
            raise ValueError("ViscoelasticLaw: Prony weights must be >= 0 and relaxation times > 0")

    # -- constructors ---------------------------------------------------------------------------
    @classmethod
    def standard_linear_solid(cls, stiffening: float, relaxation_time: float) -> "ViscoelasticLaw":
        """``r = (1 + i w s tau) / (1 + i w tau)``: the one-term series ``g = s - 1``."""
        if not stiffening > 1.0:
            raise ValueError(f"stiffening = {stiffening!r}: must be > 1")
        return cls("standard-linear-solid", [stiffening - 1.0], [relaxation_time], stiffening=float(stiffening),
                   relaxation_time=float(relaxation_time))

    @classmethod
    def prony(cls, weights, relaxation_times) -> "ViscoelasticLaw":
        """``r = 1 + sum_j g_j i w tau_j / (1 + i w tau_j)``."""
        return cls("prony", weights, relaxation_times)

    @classmethod
    def fractional_zener(cls, stiffening: float, relaxation_time: float, alpha: float, band_hz=None,
                         terms: int | None = None) -> "ViscoelasticLaw":
        """``r = (1 + s (i w tau)^alpha) / (1 + (i w tau)^alpha)``, fitted over ``band_hz``
        (default: :data:`FIT_DECADES_FRACTIONAL` decades either side of ``1 / (2 pi tau)``)."""
        if not stiffening > 1.0:
            raise ValueError(f"stiffening = {stiffening!r}: must be > 1")
        if not 0.0 < alpha < 1.0:
            raise ValueError(f"alpha = {alpha!r}: must be strictly between 0 and 1")
        if band_hz is None:
            f0 = 1.0 / (2.0 * np.pi * relaxation_time)
            band_hz = (f0 * 10.0 ** -FIT_DECADES_FRACTIONAL, f0 * 10.0 ** FIT_DECADES_FRACTIONAL)
        shell = cls("fractional-zener", [], [], stiffening=float(stiffening), relaxation_time=float(relaxation_time),
                    alpha=float(alpha))
        return shell._fitted(band_hz, terms)

    @classmethod
    def table(cls, frequency_hz, storage_ratio, loss_factor, band_hz=None, terms: int | None = None) -> "ViscoelasticLaw":
        """``r(f) = s(f) (1 + i eta(f))`` from a measured table, fitted over its band (or ``band_hz``)."""
        f = np.asarray(frequency_hz, dtype=float)
        if f.ndim != 1 or f.size < 2 or np.any(f <= 0) or np.any(np.diff(f) <= 0):
            raise ValueError("frequency_hz must hold at least two frequencies > 0, strictly increasing")
        s, eta = np.asarray(storage_ratio, dtype=float), np.asarray(loss_factor, dtype=float)
        if s.shape != f.shape or eta.shape != f.shape:
            raise ValueError("storage_ratio and loss_factor must have one value per frequency")
        shell = cls("table", [], [], frequency_hz=f, storage_ratio=s, loss_factor=eta)
        return shell._fitted((f[0], f[-1]) if band_hz is None else band_hz, terms)

    def _fitted(self, band_hz, terms: int | None) -> "ViscoelasticLaw":
        lo, hi = float(band_hz[0]), float(band_hz[1])
        if not 0.0 < lo < hi:
            raise ValueError(f"fit band {[lo, hi]} Hz: must be two frequencies 0 < low < high")
        decades = np.log10(hi / lo)
        if terms is None:
            terms = int(min(12, max(2, np.ceil(1.5 * decades) + 1)))
        omega = 2.0 * np.pi * np.logspace(np.log10(lo), np.log10(hi), max(int(FIT_POINTS_PER_DECADE * decades), 20) + 1)
        # relaxation times over the band, half a decade beyond each end
        tau = np.logspace(np.log10(1.0 / (2 * np.pi * hi)) - 0.5, np.log10(1.0 / (2 * np.pi * lo)) + 0.5, int(terms))
        g, err = fit_prony(omega, self.ratio(omega), tau)
        keep = g > 0.0
        if not keep.any():  # a table no positive series approaches: keep the best single term
            keep[np.argmin(np.abs(tau - 1.0 / np.sqrt(omega[0] * omega[-1])))] = True
        return ViscoelasticLaw(self.law, g[keep], tau[keep], err, np.array([lo, hi]), self.stiffening,
                               self.relaxation_time, self.alpha, self.frequency_hz, self.storage_ratio, self.loss_factor)

    # -- the law ---------------------------------------------------------------------------------
    @property
    def n_terms(self) -> int:
        """Number of Prony terms (internal 3-vectors per mount)."""
        return int(self.weights.size)

    @property
    def exact_series(self) -> bool:
        """True when the Prony series is the law itself (standard linear solid, Prony)."""
        return self.law in ("standard-linear-solid", "prony")

    @property
    def high_frequency_ratio(self) -> float:
        """``k(inf) / k0`` of the Prony series, ``1 + sum g_j``."""
        return float(1.0 + self.weights.sum())

    def ratio(self, omega: float | Array) -> Array:
        """Exact complex stiffness ratio ``k*(omega) / k0`` of the law at angular frequencies ``omega`` (rad/s)."""
        omega = np.asarray(omega, dtype=float)
        if self.law == "table":
            from scipy.interpolate import PchipInterpolator

            logf = np.log(self.frequency_hz)
            x = np.clip(np.log(np.maximum(np.abs(omega), 1e-300) / (2 * np.pi)), logf[0], logf[-1])
            s = PchipInterpolator(logf, self.storage_ratio)(x)
            eta = PchipInterpolator(logf, self.loss_factor)(x)
            return s * (1.0 + 1j * np.sign(omega) * eta)
        return self.ratio_at(1j * omega)

    def ratio_at(self, lam: complex | Array) -> Array:
        """The law's ratio at Laplace variables ``lam`` (its analytic continuation off the axis).

        A table is known on the imaginary axis only: ``lam`` must be ``i omega`` there.
        """
        lam = np.asarray(lam, dtype=complex)
        if self.law == "fractional-zener":
            x = (lam * self.relaxation_time) ** self.alpha
            return (1.0 + self.stiffening * x) / (1.0 + x)
        if self.law == "table":
            if np.any(np.abs(lam.real) > 1e-9 * np.abs(lam)):
                raise ValueError("a tabulated law is known on the imaginary axis only (lambda = i omega)")
            return self.ratio(lam.imag)
        return prony_ratio(lam, self.weights, self.relaxation_times)

    def dratio_at(self, lam: complex) -> complex:
        """``d r / d lam`` of the law (a table: by central differences in frequency)."""
        if self.law == "fractional-zener":
            tau, a, s = self.relaxation_time, self.alpha, self.stiffening
            x = (lam * tau) ** a
            return complex((s - 1.0) * a * x / lam / (1.0 + x) ** 2)
        if self.law == "table":
            w = float(np.imag(lam))
            h = 1e-6 * max(abs(w), 1e-3)
            return complex((self.ratio(w + h) - self.ratio(w - h)) / (2 * h) / 1j)
        return complex(_prony_dratio(lam, self.weights, self.relaxation_times))

    def fit_ratio(self, omega: float | Array) -> Array:
        """Ratio of the Prony series (the time-domain realisation) at ``omega`` (rad/s)."""
        return prony_ratio(1j * np.asarray(omega, dtype=float), self.weights, self.relaxation_times)

    def relaxation(self, t: float | Array) -> Array:
        """Relaxation stiffness ratio ``k(t) / k0 = 1 + sum_j g_j exp(-t / tau_j)`` of the Prony series
        (the force per unit step deflection, over the static stiffness)."""
        t = np.asarray(t, dtype=float)[..., None]
        return 1.0 + (self.weights * np.exp(-t / self.relaxation_times)).sum(axis=-1)

    @property
    def hysteretic(self) -> bool:
        """True for a table whose loss factor does not vanish at its lowest frequency (non-causal)."""
        return self.law == "table" and bool(self.loss_factor[0] > 0.0)

    def describe(self) -> str:
        """One line: the law, its Prony series and the fit error."""
        fit = (f", fitted over {self.fit_band_hz[0]:.4g}-{self.fit_band_hz[1]:.4g} Hz, max relative error "
               f"{self.fit_error:.2e}") if self.fit_band_hz is not None else ""
        return f"{self.law}: {self.n_terms} Prony term(s){fit}"
