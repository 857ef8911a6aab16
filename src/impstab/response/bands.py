"""One-third-octave bands (IEC 61260-1, base ten) and band levels of harmonic lines.

Band ``n`` has the exact midband frequency ``f_m = 1000 * 10^(n/10)`` Hz and the edges
``f_m * 10^(-1/20)`` and ``f_m * 10^(+1/20)``; its nominal label is the preferred number of the R10
series (..., 25, 31.5, 40, 50, 63, 80, 100, 125, ...). A line at ``f > 0`` belongs to band
``n = floor(10 log10(f / 1000) + 1/2)`` (lower edge inclusive).

Band level of a complex vector amplitude ``F`` (``F(t) = Re(F e^{i omega t})``), in dB re 1 N:

    L = 10 log10( sum over the band's frequencies of |F|^2 / 2  /  (1 N)^2 ),

the mean-square (rms) value of the force vector in the band; lines at the same frequency add
coherently (their complex amplitudes are summed first), lines at different frequencies in power.
Lines at 0 Hz belong to no band.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["BandLevels", "band_levels", "band_index", "nominal_frequency", "band_edges", "REFERENCE_FORCE"]

Array = NDArray[np.float64]

#: reference of the band levels (N)
REFERENCE_FORCE = 1.0
_R10 = (1.0, 1.25, 1.6, 2.0, 2.5, 3.15, 4.0, 5.0, 6.3, 8.0)


def band_index(frequency_hz: Array) -> NDArray[np.int64]:
    """Index ``n`` of the one-third-octave band of each frequency (> 0 Hz)."""
    f = np.asarray(frequency_hz, dtype=float)
    return np.floor(10.0 * np.log10(f / 1000.0) + 0.5).astype(np.int64)


def band_edges(index: NDArray) -> tuple[Array, Array, Array]:
    """``(lower, midband, upper)`` exact frequencies (Hz) of bands ``index``."""
    n = np.asarray(index, dtype=float)
    mid = 1000.0 * 10.0 ** (n / 10.0)
    return mid * 10.0 ** (-0.05), mid, mid * 10.0 ** 0.05


def nominal_frequency(index: NDArray) -> Array:
    """Nominal midband frequency (Hz) of bands ``index``: the R10 preferred number."""
    n = np.asarray(index, dtype=np.int64)
    return np.array([_R10[int(k) % 10] * 10.0 ** (3 + int(k) // 10) for k in n.reshape(-1)]).reshape(n.shape)


@dataclass(frozen=True, eq=False)
class BandLevels:
    """One-third-octave band levels of a force, every band from the lowest to the highest line.

    Attributes
    ----------
    index : (nb,) band numbers n (0 is the 1 kHz band)
    nominal_hz, lower_hz, midband_hz, upper_hz : (nb,) Hz
    mean_square : (nb,) N^2, ``sum |F|^2 / 2`` of the band's lines (0 for an empty band)
    lines : (nb,) number of lines in each band
    """

    index: NDArray[np.int64]
    nominal_hz: Array
    lower_hz: Array
    midband_hz: Array
    upper_hz: Array
    mean_square: Array
    lines: NDArray[np.int64]

    @property
    def level_db(self) -> Array:
        """Band level (dB re 1 N); ``-inf`` for an empty band."""
        with np.errstate(divide="ignore"):
            return 10.0 * np.log10(self.mean_square / REFERENCE_FORCE**2)

    def to_dict(self) -> dict:
        """Lists per band; empty bands have ``level_db`` None (JSON null)."""
        level = [float(v) if np.isfinite(v) else None for v in self.level_db]
        return {
            "nominal_hz": self.nominal_hz.tolist(), "lower_hz": self.lower_hz.tolist(),
            "upper_hz": self.upper_hz.tolist(), "level_db": level, "lines": self.lines.tolist(),
            "reference": "dB re 1 N (rms of the force vector in the band)",
        }


def band_levels(frequency_hz: Array, amplitude: NDArray) -> BandLevels:
    """Band levels of lines at ``frequency_hz`` (Hz) with complex vector amplitudes ``(n, k)`` (N)."""
    f = np.asarray(frequency_hz, dtype=float).reshape(-1)
    amp = np.asarray(amplitude, dtype=complex).reshape(f.size, -1)
    keep = f > 0
    f, amp = f[keep], amp[keep]
    empty = np.zeros(0)
    if f.size == 0:
        ints = np.zeros(0, dtype=np.int64)
        return BandLevels(ints, empty, empty, empty, empty, empty, ints)
    uniq, inverse = np.unique(f, return_inverse=True)
    summed = np.zeros((uniq.size, amp.shape[1]), dtype=complex)
    np.add.at(summed, inverse, amp)                       # coherent at equal frequencies
    power = 0.5 * (np.abs(summed) ** 2).sum(axis=1)
    idx = band_index(uniq)
    bands = np.arange(idx.min(), idx.max() + 1)
    mean_square = np.zeros(bands.size)
    np.add.at(mean_square, idx - bands[0], power)
    counts = np.zeros(bands.size, dtype=np.int64)
    np.add.at(counts, band_index(f) - bands[0], 1)
    lower, mid, upper = band_edges(bands)
    return BandLevels(bands, nominal_frequency(bands), lower, mid, upper, mean_square, counts)
