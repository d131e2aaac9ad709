"""Exceptions of the biped package: each message names the bad value and what is allowed;
and its one warning."""


class BipedError(Exception):
    """Base class of every error raised on purpose by this package."""


class ParameterError(BipedError, ValueError):
    """A robot parameter is outside its physical range."""

    def __init__(self, field: str, value, allowed: str):
        self.field, self.value, self.allowed = field, value, allowed
        super().__init__(f"robot parameter {field} = {value!r} is invalid: allowed {allowed}")


class UnreachableError(BipedError, ValueError):
    """The inverse geometric model has no solution (the hip is out of the leg's reach)."""


class BipedWarning(UserWarning):
    """Something the user should know that did not stop the work (the CLI says it as one
    line, ``biped_cli.guard.warnings_as_lines``)."""


class ViewerWarning(BipedWarning):
    """No rerun viewer took a recording streamed to it (--spawn, --connect); the recording's
    file is written all the same (``validate.outputs.record.record``)."""


class CompileWarning(BipedWarning):
    """The solver's derivatives run in CasADi's interpreter instead of compiled code (the
    same numbers, slower; ``biped.optimization.compiled``)."""
