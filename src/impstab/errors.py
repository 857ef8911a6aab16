"""Exceptions raised by impstab, and the plain one-line text they are shown with.

Every input problem is a :class:`ModelError` whose message is one line naming the field,
the offending value and the rule it breaks. The command line prints that line and exits
with code 2; numerical trouble is a :class:`NumericalError` (exit code 1).

Messages never carry a terminal control sequence or a line break: user strings (a model
``name``, an unknown key, a path) pass through :func:`printable`, which shows every control,
format and line-separator character as a Python escape (``\\x1b``, ``\\u202e``), and values are
written plainly by :func:`format_value` (``1e+200``, not ``np.float64(1e+200)``).
"""

from __future__ import annotations

import math

__all__ = ["ModelError", "NumericalError", "printable", "format_value"]

def _escape(ch: str) -> str:
    code = ord(ch)
    if code < 0x100:
        return f"\\x{code:02x}"
    if code < 0x10000:
        return f"\\u{code:04x}"
    return f"\\U{code:08x}"


def printable(text: object) -> str:
    """``text`` as one line that is safe to show on a terminal.

    Every character that Python does not count as printable (``str.isprintable``) is replaced
    by its Python escape: controls (``ESC``, ``BEL``, carriage return, line feed, tab, ``DEL``,
    the C1 range), format characters (bidirectional overrides, zero-width joiners), line and
    paragraph separators, spaces other than the plain space, surrogates, private-use and
    unassigned code points. Letters of every script and symbols are kept.
    """
    s = text if isinstance(text, str) else str(text)
    if s.isprintable():
        return s
    return "".join(ch if ch.isprintable() else _escape(ch) for ch in s)


def _plain_float(x: float) -> str:
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(float(x))


def _format(value: object, budget: int, depth: int) -> str:
    """Plain text of ``value``, giving up (``...``) past ``budget`` characters or depth 4."""
    try:
        import numpy as np
    except ImportError:  # pragma: no cover - numpy is a dependency
        np = None  # type: ignore[assignment]
    if np is not None:
        if isinstance(value, np.ndarray):
            if value.size > 64:
                return f"<array of shape {tuple(value.shape)}>"
            value = value.tolist()
        elif isinstance(value, np.generic):
            value = value.item()
    if value is None:
        return "None"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        text = str(value) if value.bit_length() < 128 else f"<integer of {len(str(abs(value)))} digits>"
        return text
    if isinstance(value, float):
        return _plain_float(value)
    if isinstance(value, complex):
        return f"({_plain_float(value.real)}{'+' if value.imag >= 0 else '-'}{_plain_float(abs(value.imag))}j)"
    if isinstance(value, str):
        return repr(value if len(value) <= budget else value[:budget] + "...")
    if isinstance(value, (list, tuple)):
        if depth >= 4:
            return "[...]"
        parts: list[str] = []
        used = 2
        for item in value:
            if used > budget:
                parts.append("...")
                break
            text = _format(item, budget - used, depth + 1)
            parts.append(text)
            used += len(text) + 2
        return "[" + ", ".join(parts) + "]"
    if isinstance(value, dict):
        if depth >= 4:
            return "{...}"
        parts = []
        used = 2
        for key, item in value.items():
            if used > budget:
                parts.append("...")
                break
            text = f"{printable(key)} = {_format(item, budget - used, depth + 1)}"
            parts.append(text)
            used += len(text) + 2
        return "{" + ", ".join(parts) + "}"
    return f"<{type(value).__name__}>"


def format_value(value: object, limit: int = 80) -> str:
    """A value as short plain text: numbers as Python writes them, strings quoted, at most
    ``limit`` characters (longer text ends in ``...``), always one printable line."""
    text = printable(_format(value, limit, 0))
    return text if len(text) <= limit else text[: limit - 3] + "..."


class ModelError(ValueError):
    """Bad input: a model, study or command-line value that breaks a rule.

    Parameters
    ----------
    field : str
        Dotted location of the value, e.g. ``"mounts[1].k_axial"``.
    value : object
        The offending value (shown plainly by :func:`format_value`, shortened).
    rule : str
        What the value must satisfy, in words.

    The message ``"{field} = {value}: {rule}"`` is always one printable line.
    """

    def __init__(self, field: str, value: object, rule: str) -> None:
        self.field = field
        self.value = value
        self.rule = rule
        super().__init__(printable(f"{field} = {format_value(value)}: {rule}"))


class NumericalError(RuntimeError):
    """A computation that could not be carried out reliably (reported, never hidden)."""
