"""Exceptions raised by impstab.

Every input problem is a :class:`ModelError` whose message is one line naming the field,
the offending value and the rule it breaks. The command line prints that line and exits
with code 2; numerical trouble is a :class:`NumericalError` (exit code 1).
"""

from __future__ import annotations

__all__ = ["ModelError", "NumericalError"]


def _short(value: object, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


class ModelError(ValueError):
    """Bad input: a model, study or command-line value that breaks a rule.

    Parameters
    ----------
    field : str
        Dotted location of the value, e.g. ``"mounts[1].k_axial"``.
    value : object
        The offending value (shown with ``repr``, shortened).
    rule : str
        What the value must satisfy, in words.
    """

    def __init__(self, field: str, value: object, rule: str) -> None:
        self.field = field
        self.value = value
        self.rule = rule
        super().__init__(f"{field} = {_short(value)}: {rule}")


class NumericalError(RuntimeError):
    """A computation that could not be carried out reliably (reported, never hidden)."""
