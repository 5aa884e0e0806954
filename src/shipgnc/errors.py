"""Exceptions that carry a message meant for people.

Every error raised at a public boundary names what was wrong (field, value, what is allowed);
the CLI prints ``str(error)`` on one line and exits non-zero.
"""

from __future__ import annotations


class ShipGNCError(Exception):
    """Base class of every error shipgnc raises on purpose."""

    exit_code = 2


class ConfigError(ShipGNCError, ValueError):
    """Invalid configuration or argument: the message names the field, the value and the rule."""


class DivergenceError(ShipGNCError, FloatingPointError):
    """The simulation left the physically meaningful region (NaN, inf or a runaway state).

    Attributes name the time, the state, its value and the ship (batch index).
    """

    exit_code = 3

    def __init__(self, message: str, *, time: float, state: str, value: float, index: tuple):
        super().__init__(message)
        self.time = time
        self.state = state
        self.value = value
        self.index = index


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a run: ``time`` [s] is the last sample computed and ``partial`` the result up
    to it (an ``xarray.Dataset`` with ``attrs["interrupted"] = 1``, or None). A KeyboardInterrupt,
    so code that does not know it stops as before; the command line prints one line and exits 130
    (``--keep-partial`` writes the partial result first)."""

    exit_code = 130

    def __init__(self, time: float | None = None, partial=None, message: str | None = None):
        text = message or ("interrupted" if time is None else f"interrupted at t = {time:.6g} s")
        super().__init__(text)
        self.time = time
        self._partial = partial

    @property
    def partial(self):
        """The partial result; given as a callable it is built on first use (building it can
        import xarray, a second or more: a command that exits does not wait for it)."""
        if callable(self._partial):
            self._partial = self._partial()
        return self._partial

    @partial.setter
    def partial(self, value) -> None:
        self._partial = value


class ShipGNCWarning(UserWarning):
    """A result that is sound but weaker than asked (e.g. a study whose chunks ran on different
    loops agrees to round-off, not to the bit); the command line prints it as a one-line warning."""


def require(condition: bool, field: str, value: object, rule: str) -> None:
    """Raise :class:`ConfigError` ``"<field> = <value>: <rule>"`` unless ``condition`` holds."""
    if not condition:
        raise ConfigError(f"{field} = {value!r}: {rule}")
