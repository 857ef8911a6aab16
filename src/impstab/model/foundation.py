"""The hull at the mount attachments for the forced response (``[foundation]`` of the model file).

By default the hull is rigid: the mounts' hull ends do not move and the mount forces are the
answer. A compliant hull is described by an isotropic point impedance ``Z`` (N s/m) or mobility
``Y = 1/Z`` (m/(N s)) at each attachment, the same in every direction and uncoupled between
attachment points (transfer mobilities, rotational and cross-direction mobilities neglected).
Time factor ``e^{i omega t}``; the hull point's dynamic stiffness is ``S = i omega Z = i omega / Y``
(N/m): a hull force ``F`` moves the attachment by ``x = F / S``.

``model``:

* ``"rigid"``: ``S`` infinite;
* ``"lumped"``: a grounded mass-spring-damper, ``Z = damping + i (omega mass - stiffness / omega)``,
  ``S = stiffness + i omega damping - omega^2 mass``;
* ``"mobility-table"`` / ``"impedance-table"``: measured values at ``frequency_hz``, real and
  imaginary parts interpolated linearly in frequency; a frequency outside the table is an error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError

__all__ = ["Foundation", "FOUNDATION_MODELS"]

Array = NDArray[np.float64]

FOUNDATION_MODELS = ("rigid", "lumped", "mobility-table", "impedance-table")


@dataclass(frozen=True, eq=False)
class Foundation:
    """Point impedance of the hull at a mount attachment.

    Parameters
    ----------
    model : {"rigid", "lumped", "mobility-table", "impedance-table"}
    mass, stiffness, damping : float
        Lumped model: kg, N/m, N s/m.
    frequency_hz : (n,) array or None
        Table frequencies (Hz), strictly increasing.
    values : (n,) complex array or None
        Table values: mobility (m/(N s)) or impedance (N s/m).
    """

    model: str = "rigid"
    mass: float = 0.0
    stiffness: float = 0.0
    damping: float = 0.0
    frequency_hz: Array | None = None
    values: NDArray[np.complex128] | None = None

    def __post_init__(self) -> None:
        if self.model not in FOUNDATION_MODELS:
            raise ModelError("foundation.model", self.model, f"must be one of {list(FOUNDATION_MODELS)}")
        for name in ("frequency_hz", "values"):
            v = getattr(self, name)
            if v is not None:
                v = np.array(v, dtype=complex if name == "values" else float).reshape(-1)
                v.setflags(write=False)
                object.__setattr__(self, name, v)

    @property
    def rigid(self) -> bool:
        return self.model == "rigid"

    def dynamic_stiffness(self, frequency_hz: Array) -> NDArray[np.complex128]:
        """``S = i omega Z`` (N/m, complex) at each frequency (Hz); infinite for a rigid hull."""
        f = np.asarray(frequency_hz, dtype=float)
        w = 2.0 * np.pi * f
        if self.model == "rigid":
            return np.full(f.shape, np.inf + 0j)
        if self.model == "lumped":
            return self.stiffness - w**2 * self.mass + 1j * w * self.damping
        table_f, vals = self.frequency_hz, self.values
        assert table_f is not None and vals is not None
        if f.size and (f.min() < table_f[0] or f.max() > table_f[-1]):
            bad = float(f.min() if f.min() < table_f[0] else f.max())
            raise ModelError(
                "foundation.frequency_hz", bad,
                f"the table covers {table_f[0]:g} to {table_f[-1]:g} Hz: extend it to every frequency analysed",
            )
        value = np.interp(f, table_f, vals.real) + 1j * np.interp(f, table_f, vals.imag)
        if self.model == "impedance-table":
            return 1j * w * value
        return 1j * w / value
