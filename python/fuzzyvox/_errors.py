"""The exceptions fuzzyvox raises; each carries the Rust library's message."""


class FuzzyvoxError(Exception):
    """Base class of every error fuzzyvox raises."""


class InvalidInputError(FuzzyvoxError, ValueError):
    """Bad input: a wrong shape, a value out of range, a non-finite number, an unknown name."""


class MapFileError(FuzzyvoxError, OSError):
    """A map file that cannot be read or written, or whose contents are damaged."""


class PlanError(FuzzyvoxError, RuntimeError):
    """The planner refused the start or goal, or found no path.

    ``failure`` names why: ``out_of_region``, ``start_unsafe``, ``goal_unsafe`` or
    ``disconnected``; the message says what blocks and which setting would change it.
    """

    failure: str = "unknown"


# Shown as `fuzzyvox.InvalidInputError` in tracebacks, where users import them from.
for _class in (FuzzyvoxError, InvalidInputError, MapFileError, PlanError):
    _class.__module__ = "fuzzyvox"
del _class
