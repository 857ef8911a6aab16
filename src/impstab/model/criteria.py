"""The practical stability criterion's threshold: a damping ratio, or a logarithmic decrement.

For an eigenvalue ``lambda = sigma + i omega`` the damping ratio is ``zeta = -sigma / |lambda|``
and the logarithmic decrement ``delta = -2 pi sigma / omega`` (the log of the ratio of
successive peaks of a free decay); they are one measure, ``delta = 2 pi zeta / sqrt(1 - zeta^2)``.
Rotordynamic standards (API 617, API 684) state stability as ``delta >= 0.1``
(``zeta >= 0.0159``). The threshold is stored as a damping ratio; the search is
:mod:`impstab.linear.practical`.
"""

from __future__ import annotations

import math

from ..errors import ModelError
from ..limits import check_number

__all__ = ["damping_ratio_of_log_decrement", "log_decrement_of_damping_ratio", "damping_threshold"]


def damping_ratio_of_log_decrement(delta: float) -> float:
    """``zeta = delta / sqrt(4 pi^2 + delta^2)``, the damping ratio of a logarithmic decrement."""
    return float(delta / math.hypot(2 * math.pi, delta))


def log_decrement_of_damping_ratio(zeta: float) -> float:
    """``delta = 2 pi zeta / sqrt(1 - zeta^2)``, the logarithmic decrement of a damping ratio < 1."""
    return float(2 * math.pi * zeta / math.sqrt(1.0 - zeta * zeta))


def damping_threshold(min_damping_ratio: float | None = None, min_log_decrement: float | None = None,
                      *, names: tuple[str, str] = ("min_damping_ratio", "min_log_decrement")) -> float | None:
    """The damping-ratio threshold given as a damping ratio or a logarithmic decrement (not both).

    Returns None when neither is given. Raises :class:`~impstab.errors.ModelError` naming the
    argument (``names``) for a value outside its range (``damping_ratio`` / ``log_decrement`` in
    :data:`impstab.limits.RANGES`) or when both are given.
    """
    if min_damping_ratio is not None and min_log_decrement is not None:
        raise ModelError(names[1], min_log_decrement, f"give {names[0]} or {names[1]}, not both")
    if min_damping_ratio is not None:
        return check_number(names[0], min_damping_ratio, "damping_ratio")
    if min_log_decrement is not None:
        return damping_ratio_of_log_decrement(check_number(names[1], min_log_decrement, "log_decrement"))
    return None
