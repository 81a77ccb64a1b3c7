"""The exceptions of the fbd package."""

from __future__ import annotations

from typing import Any, Optional


class ConfigError(ValueError):
    """A configuration is invalid: unreadable, bad TOML, an unknown key or a
    value out of its domain.

    Attributes:
        file: the file as given, ``"<string>"`` for TOML text, ``"<dict>"``
            for a dict.
        line, column: 1-based position of a syntax or type error in the text
            (None when unknown, and for dicts).
        key: the dotted ``table.key`` at fault, e.g. ``"time.dt"`` (None when
            the error concerns no single key).
    """

    def __init__(
        self,
        message: str,
        file: Optional[str] = None,
        line: Optional[int] = None,
        column: Optional[int] = None,
        key: Optional[str] = None,
    ) -> None:
        super().__init__(message)
        self.file = file
        self.line = line
        self.column = column
        self.key = key


class SimulationError(RuntimeError):
    """A simulation stopped: Newton's method failed, the contact-state
    search cycled, or the state became non-finite.

    Attributes:
        step: the step index ``k`` that failed (None when unknown).
        time: its time ``k·Δt`` (s).
        result: for :func:`fbd.run`, the partial :class:`fbd.Result` with
            every row solved before the failure; None for
            :class:`fbd.Simulator`, whose state stays at the last solved step.
    """

    def __init__(
        self,
        message: str,
        step: Optional[int] = None,
        time: Optional[float] = None,
        result: Any = None,
    ) -> None:
        super().__init__(message)
        self.step = step
        self.time = time
        self.result = result
