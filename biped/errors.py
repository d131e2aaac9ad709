"""Exceptions of the biped package: each message names the bad value and what is allowed."""


class BipedError(Exception):
    """Base class of every error raised on purpose by this package."""


class ParameterError(BipedError, ValueError):
    """A robot parameter is outside its physical range."""

    def __init__(self, field: str, value, allowed: str):
        self.field, self.value, self.allowed = field, value, allowed
        super().__init__(f"robot parameter {field} = {value!r} is invalid: allowed {allowed}")


class UnreachableError(BipedError, ValueError):
    """The inverse geometric model has no solution (the hip is out of the leg's reach)."""
