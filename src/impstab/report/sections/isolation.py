"""Vibration isolation at the operating thrust: transmissibility, excitation response, bands.

The transmissibility of a unit load (``excitation.input``, sway by default) is computed over a
band set by the model's own modes: from a quarter of the lowest damped natural frequency at the
operating thrust to ten times the highest (and past the highest excitation line, when the model
has an ``[excitation]``), :data:`POINTS` frequencies spaced evenly on a log scale. Isolation
starts near sqrt(2) times a mode's frequency, so the band shows the resonances and a decade of
isolation above them.
"""

from __future__ import annotations

import numpy as np

from ...display.format import number
from ..result import Figure, Note, Section
from ..svg import draw_svg
from ..tables import table
from .titles import TITLES
from .context import ModelContext

__all__ = ["isolation_section", "default_frequencies", "POINTS", "BAND_BELOW", "BAND_ABOVE"]

#: frequencies of the default band
POINTS = 800
#: the band starts at the lowest natural frequency divided by BAND_BELOW ...
BAND_BELOW = 4.0
#: ... and ends at the highest natural frequency times BAND_ABOVE (or past the excitation lines)
BAND_ABOVE = 10.0
#: margin beyond the highest excitation line
_LINE_MARGIN = 1.25


def default_frequencies(natural_hz: np.ndarray, lines_hz: np.ndarray | None = None) -> np.ndarray:
    """The default band (Hz) of the transmissibility for these natural frequencies and lines."""
    f = np.asarray(natural_hz, dtype=float)
    f = f[np.isfinite(f) & (f > 0)]
    if f.size == 0:
        lo, hi = 0.1, 100.0
    else:
        lo, hi = f.min() / BAND_BELOW, f.max() * BAND_ABOVE
    if lines_hz is not None and np.size(lines_hz):
        hi = max(hi, float(np.max(lines_hz)) * _LINE_MARGIN)
    return np.geomspace(lo, hi, POINTS)


def isolation_section(ctx: ModelContext) -> Section:
    from ...response import excitation_response, frequency_response

    m = ctx.model
    ex = excitation_response(m) if m.excitation.has_loads else None
    freqs = ctx.options.frequencies
    chosen = "given"
    if freqs is None:
        lines = None if ex is None else ex.frequency_hz[ex.frequency_hz > 0]
        freqs = default_frequencies(ctx.natural_frequencies_hz, lines)
        chosen = (f"default: {POINTS} log-spaced from a quarter of the lowest natural frequency to ten times the "
                  "highest" + (" and past the excitation lines" if ex is not None else ""))
    res = frequency_response(m, freqs)
    f, tr = res.frequency_hz, res.transmissibility
    force = res.input_unit == "N"
    unit = "N/N" if force else "N/(N m)"
    where = f"at T = {number(res.thrust)} N ({res.linearization})"
    blocks: list = [Figure(draw_svg(res.plot, "transmissibility"),
                           f"Force transmissibility |F_hull| / |F_in| of a unit {res.input} "
                           f"{'force' if force else 'moment'} at A {where}; {f.size} frequencies from "
                           f"{number(f[0], 4)} to {number(f[-1], 4)} Hz ({chosen}).")]
    j = int(np.nanargmax(tr))
    rows = [("frequencies", f"{f.size}, {number(f[0], 4)} to {number(f[-1], 4)} Hz ({chosen})"),
            ("peak transmissibility", f"{number(tr[j], 5)} {unit} ({20 * np.log10(tr[j]):.2f} dB) at {number(f[j], 5)} Hz")]
    if force:
        onset = res.isolation_frequency_hz()
        rows.append(("isolation (transmissibility < 1) from",
                     "not reached in the band" if onset is None else f"{number(onset, 5)} Hz"))
    rows.append((f"transmissibility at {number(f[-1], 4)} Hz", f"{number(tr[-1], 5)} {unit} ({20 * np.log10(tr[-1]):.2f} dB)"))
    rows.append(("modes at this thrust", ", ".join(f"{number(fm, 4)} Hz ({d})" for fm, d in
                                                   zip(res.mode_frequency_hz, res.mode_dominant))))
    rows.append(("foundation", str(res.settings.get("foundation", ""))))
    rows.append(("fluid", str(res.settings.get("fluid", ""))))
    blocks.append(table(f"force transmissibility to the hull {where}, unit {res.input} load", rows))
    blocks += [Note(w, "warning") for w in res.warnings]
    data = {"transmissibility": res}
    if ex is None:
        blocks.append(Note("The model has no [excitation] loads (unbalance, blade_rate or spectrum): no excitation "
                           "response and no band levels."))
    else:
        blocks += _excitation_blocks(ex)
        data["excitation"] = ex
    return Section("isolation", TITLES["isolation"], blocks=tuple(blocks), data=data)


def _excitation_blocks(ex) -> list:
    mag = ex.hull_force_magnitude
    rows = []
    for i, src in enumerate(ex.source):
        level = f"{20 * np.log10(mag[i] / np.sqrt(2)):.2f}" if mag[i] > 0 else "no force"
        rows.append([src, number(ex.frequency_hz[i], 5), number(mag[i], 5), level,
                     number(ex.power_transmitted[i].sum(), 4)])
    blocks: list = [Figure(draw_svg(ex.plot, "excitation"),
                           "Hull force of each excitation line and its one-third-octave band levels (rms, dB re 1 N)."),
                    table(f"excitation lines at T = {number(ex.thrust)} N (shaft rate {number(ex.shaft_rate, 5)} rad/s)",
                          rows, ["source", "f (Hz)", "|F_hull| (N)", "level (dB re 1 N rms)", "power into hull (W)"],
                          ["left", "right", "right", "right", "right"])]
    b = ex.bands()
    if b.index.size:
        band_rows = [[f"{b.nominal_hz[i]:g}", f"{b.lower_hz[i]:.4g} to {b.upper_hz[i]:.4g}", str(b.lines[i]),
                      f"{b.level_db[i]:.2f}" if np.isfinite(b.level_db[i]) else "no line in the band"]
                     for i in range(b.index.size)]
        blocks.append(table("hull force in one-third-octave bands (IEC 61260-1, base ten)", band_rows,
                            ["nominal (Hz)", "band (Hz)", "lines", "level (dB re 1 N)"], ["right"] * 4))
    blocks += [Note(w, "warning") for w in ex.warnings]
    return blocks
