"""Result of a forced response: frequencies, body response, mount and hull forces, powers."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..model.model import DOF_NAMES
from .bands import BandLevels, band_levels

__all__ = ["ForcedResponse", "AXES"]

Array = NDArray[np.float64]
CArray = NDArray[np.complex128]

AXES = ("x", "y", "z")
_COMPLEX = {
    # name: (dims, units, long name)
    "load": (("frequency", "dof"), "N | N m", "generalized load at A, hull axes"),
    "response": (("frequency", "dof"), "m | rad", "response q of A (translation, small rotation), hull axes"),
    "mount_deflection": (("frequency", "mount", "dof"), "m | rad", "body-end motion B_i q of each mount"),
    "hull_displacement": (("frequency", "mount", "axis"), "m", "hull-end displacement of each mount (0 on a rigid hull)"),
    "mount_force": (("frequency", "mount", "axis"), "N", "force of each mount on the hull"),
    "hull_force": (("frequency", "axis"), "N", "total force of the mounts on the hull"),
}
_REAL = {
    "power_input": (("frequency",), "W", "time-averaged power of the load"),
    "power_thrust": (("frequency",), "W", "power of the thrust's load stiffness (circulatory work)"),
    "power_fluid": (("frequency",), "W", "power radiated into the fluid"),
    "power_damper": (("frequency", "mount"), "W", "power dissipated in each mount's dampers"),
    "power_transmitted": (("frequency", "mount"), "W", "power transmitted into the hull at each mount"),
    "pivot_ratio": (("frequency",), "1", "smallest over largest pivot of the solve (0: singular)"),
}


def _phase_deg(z: CArray) -> Array:
    """Phase in degrees in (-180, 180]."""
    ph = np.degrees(np.angle(z)) + 0.0
    return np.where(ph <= -180.0, ph + 360.0, ph)


@dataclass(frozen=True, eq=False)
class ForcedResponse:
    """Steady harmonic response of the linearized propulsor at one thrust.

    Harmonic quantities are complex amplitudes ``X`` with ``x(t) = Re(X e^{i omega t})``, in the
    linear coordinates of THEORY 1 (hull axes; at a rotating equilibrium the mounts' arms are
    the rotated ``R0 r_i``). Powers are time averages (W).

    Attributes
    ----------
    frequency_hz : (n,) Hz
    load, response : (n, 6) complex
        Load at A (N, N m) and response q (m, rad).
    mount_deflection : (n, nm, 6) complex
        Body-end motion of each mount, ``B_i q`` (m, rad).
    hull_displacement, mount_force : (n, nm, 3) complex
        Hull-end displacement (m) and force of each mount on the hull (N).
    hull_force : (n, 3) complex
        Total force of the mounts on the hull (N).
    power_input, power_thrust, power_fluid : (n,) W
    power_damper, power_transmitted : (n, nm) W
    pivot_ratio : (n,)
    thrust : float
        Thrust of the linearization (N).
    linearization : str
    input : str
        The dof of a unit load (a transfer function), or ``"excitation"`` (the model's loads).
    source : tuple of str
        For an excitation, the key each line comes from; empty otherwise.
    shaft_rate : float
        Propeller speed Omega at the thrust (rad/s).
    mode_frequency_hz, mode_growth_rate : (k,) arrays
        Damped natural frequencies (Hz) and growth rates (1/s) of the modes at the thrust.
    mode_dominant : tuple of str
        Dominant dof (largest kinetic-energy share) of each mode.
    settings : dict
        What produced the result: model, foundation, fluid treatment and its accuracy, version.
    warnings : tuple of str
    """

    frequency_hz: Array
    load: CArray
    response: CArray
    mount_deflection: CArray
    hull_displacement: CArray
    mount_force: CArray
    hull_force: CArray
    power_input: Array
    power_thrust: Array
    power_fluid: Array
    power_damper: Array
    power_transmitted: Array
    pivot_ratio: Array
    thrust: float
    linearization: str
    input: str
    shaft_rate: float = 0.0
    source: tuple[str, ...] = ()
    mode_frequency_hz: Array = field(default_factory=lambda: np.zeros(0))
    mode_growth_rate: Array = field(default_factory=lambda: np.zeros(0))
    mode_dominant: tuple[str, ...] = ()
    settings: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()

    # -- derived quantities -------------------------------------------------------------------
    @property
    def omega(self) -> Array:
        """Angular frequencies (rad/s)."""
        return 2.0 * np.pi * self.frequency_hz

    @property
    def is_transfer(self) -> bool:
        """True for the response to a unit load on one dof."""
        return self.input in DOF_NAMES

    @property
    def hull_force_magnitude(self) -> Array:
        """``|F_hull|``, the Euclidean norm of the complex hull force (N)."""
        return np.sqrt((np.abs(self.hull_force) ** 2).sum(axis=-1))

    @property
    def input_magnitude(self) -> Array:
        """``|F_in|`` of a unit load: 1 (N or N m); for an excitation, NaN (force and moment mix)."""
        if not self.is_transfer:
            return np.full(self.frequency_hz.shape, np.nan)
        return np.abs(self.load[:, DOF_NAMES.index(self.input)])

    @property
    def transmissibility(self) -> Array:
        """``|F_hull| / |F_in|`` (N/N, or N/(N m) for a moment input); NaN for an excitation."""
        return self.hull_force_magnitude / self.input_magnitude

    @property
    def transmissibility_db(self) -> Array:
        """``20 log10(transmissibility)`` (dB re 1 N/N or 1 N/(N m))."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(self.transmissibility)

    @property
    def input_unit(self) -> str:
        """``"N"`` for a force input, ``"N m"`` for a moment input."""
        return "N m" if self.input in DOF_NAMES[3:] else "N"

    @property
    def power_balance_error(self) -> Array:
        """``input + thrust - fluid - dampers - transmitted`` (W): zero to rounding."""
        return (self.power_input + self.power_thrust - self.power_fluid - self.power_damper.sum(axis=-1)
                - self.power_transmitted.sum(axis=-1))

    def bands(self) -> BandLevels:
        """One-third-octave band levels of the hull force (dB re 1 N) of an excitation's lines."""
        return band_levels(self.frequency_hz, self.hull_force)

    # -- output -------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-able dict: DESIGN's keys (``thrust``, ``input``, ``frequency_hz``,
        ``transmissibility``, ``response``) and extras (hull force, modes, powers, settings)."""
        out: dict = {
            "thrust": self.thrust,
            "input": self.input,
            "frequency_hz": self.frequency_hz.tolist(),
        }
        if self.is_transfer:
            out["transmissibility"] = self.transmissibility.tolist()
        out["response"] = {
            n: {"abs": np.abs(self.response[:, j]).tolist(), "phase_deg": _phase_deg(self.response[:, j]).tolist()}
            for j, n in enumerate(DOF_NAMES)
        }
        out["linearization"] = self.linearization
        out["hull_force"] = {
            a: {"abs": np.abs(self.hull_force[:, j]).tolist(), "phase_deg": _phase_deg(self.hull_force[:, j]).tolist()}
            for j, a in enumerate(AXES)
        }
        out["hull_force_abs"] = self.hull_force_magnitude.tolist()
        out["power_transmitted"] = self.power_transmitted.sum(axis=-1).tolist()
        out["shaft_rate"] = self.shaft_rate
        out["modes"] = {"frequency_hz": self.mode_frequency_hz.tolist(), "growth_rate": self.mode_growth_rate.tolist(),
                        "dominant": list(self.mode_dominant)}
        if self.source:
            out["source"] = list(self.source)
            out["bands"] = self.bands().to_dict()
        out["settings"] = dict(self.settings)
        out["warnings"] = list(self.warnings)
        return out

    def to_xarray(self):
        """Dataset on ``frequency`` (Hz), ``dof``, ``mount``, ``axis``; complex amplitudes as
        ``<name>_real`` / ``<name>_imag`` pairs; units on every variable, settings in ``attrs``."""
        import xarray as xr

        nm = self.mount_force.shape[1]
        data: dict = {}
        for name, (dims, units, long) in _COMPLEX.items():
            v = getattr(self, name)
            for part, arr in (("real", v.real), ("imag", v.imag)):
                data[f"{name}_{part}"] = (dims, np.ascontiguousarray(arr), {"units": units, "long_name": f"{long} ({part} part)"})
        for name, (dims, units, long) in _REAL.items():
            data[name] = (dims, np.asarray(getattr(self, name)), {"units": units, "long_name": long})
        data["hull_force_magnitude"] = (("frequency",), self.hull_force_magnitude, {"units": "N", "long_name": "|F_hull|"})
        if self.is_transfer:
            unit = "N/(N m)" if self.input_unit == "N m" else "N/N"
            data["transmissibility"] = (("frequency",), self.transmissibility, {"units": unit, "long_name": "|F_hull| / |F_in|"})
        data["mode_frequency_hz"] = (("mode",), self.mode_frequency_hz, {"units": "Hz", "long_name": "damped natural frequency"})
        data["mode_growth_rate"] = (("mode",), self.mode_growth_rate, {"units": "1/s", "long_name": "Re(lambda)"})
        data["mode_dominant"] = (("mode",), np.array(self.mode_dominant, dtype=object) if self.mode_dominant else np.zeros(0, dtype=object), {"units": "1"})
        if self.source:
            data["source"] = (("frequency",), np.array(self.source, dtype=object), {"units": "1", "long_name": "excitation key of each line"})
        attrs = {
            "title": f"forced response at thrust {self.thrust:g} N",
            "thrust": self.thrust, "thrust_units": "N", "linearization": self.linearization, "input": self.input,
            "shaft_rate": self.shaft_rate, "shaft_rate_units": "rad/s",
            "convention": "x(t) = Re(X exp(i omega t)); omega = 2 pi frequency_hz; hull axes; dof order surge..yaw",
            "warnings": "; ".join(self.warnings),
        }
        attrs.update({f"setting_{k}": (v if isinstance(v, (int, float, str)) else str(v)) for k, v in self.settings.items()})
        return xr.Dataset(
            data,
            coords={
                "frequency": ("frequency", self.frequency_hz, {"units": "Hz"}),
                "dof": list(DOF_NAMES), "mount": np.arange(nm), "axis": list(AXES),
                "mode": np.arange(self.mode_frequency_hz.size),
            },
            attrs=attrs,
        )

    @classmethod
    def from_xarray(cls, ds) -> "ForcedResponse":
        """Rebuild from :meth:`to_xarray` (e.g. after a netCDF round trip)."""
        c = {n: ds[f"{n}_real"].values + 1j * ds[f"{n}_imag"].values for n in _COMPLEX}
        r = {n: ds[n].values for n in _REAL}
        a = ds.attrs
        settings = {k[len("setting_"):]: v for k, v in a.items() if k.startswith("setting_")}
        warnings = tuple(w for w in str(a.get("warnings", "")).split("; ") if w)
        return cls(
            frequency_hz=ds["frequency"].values, **c, **r, thrust=float(a["thrust"]),
            linearization=str(a["linearization"]), input=str(a["input"]), shaft_rate=float(a.get("shaft_rate", 0.0)),
            source=tuple(str(s) for s in ds["source"].values) if "source" in ds else (),
            mode_frequency_hz=ds["mode_frequency_hz"].values, mode_growth_rate=ds["mode_growth_rate"].values,
            mode_dominant=tuple(str(s) for s in ds["mode_dominant"].values), settings=settings, warnings=warnings,
        )

    def plot(self, ax=None):
        """Draw the result; returns the matplotlib Axes.

        A transfer function: transmissibility in dB against log frequency with the modes marked
        and labelled. An excitation: the hull force of each line and the one-third-octave band
        levels, in dB re 1 N.
        """
        from ..plot.response import plot_excitation, plot_transmissibility

        return plot_transmissibility(self, ax=ax) if self.is_transfer else plot_excitation(self, ax=ax)
