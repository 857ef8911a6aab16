"""Numbers as people read them: no ``-0``, a word instead of a bare dash, units attached."""

from __future__ import annotations

import math
import re

__all__ = ["number", "signed_zero_free", "growth"]

_ZERO = re.compile(r"^-(0(\.0*)?(e[+-]?\d+)?)$")


def signed_zero_free(text: str) -> str:
    """``"-0"``, ``"-0.00"``, ``"-0e+00"`` -> without the sign (a value that rounds to zero)."""
    m = _ZERO.match(text)
    return m.group(1) if m else text


def number(value, digits: int = 6, unit: str = "", *, missing: str = "n/a", fmt: str = "g") -> str:
    """``value`` with ``digits`` significant digits (``fmt="g"``) or decimals (``"f"``), and its unit.

    None and NaN print as ``missing`` (say why where it is used: ``"none up to thrust_max"``);
    a value that rounds to zero prints without a minus sign.
    """
    if value is None:
        return missing
    try:
        v = float(value)
    except (TypeError, ValueError):
        return str(value)
    if math.isnan(v):
        return missing
    if math.isinf(v):
        text = "inf" if v > 0 else "-inf"
    else:
        text = signed_zero_free(f"{v + 0.0:.{digits}{fmt}}")
    return f"{text} {unit}" if unit else text


def growth(rate, scale: float | None = None, digits: int = 4) -> str:
    """A growth rate (1/s); below ``1e-10 x scale`` (the rounding of eigenvalues of size
    ``scale``) it is zero and printed as ``"0"``."""
    if rate is None or (isinstance(rate, float) and math.isnan(rate)):
        return "n/a"
    limit = 1e-10 * (scale if scale else 1.0)
    if abs(rate) < limit:
        return "0"
    return number(rate, digits)
