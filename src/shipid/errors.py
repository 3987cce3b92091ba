"""The exception and warning types of user-facing problems.

``ShipidError``: bad input or an impossible request; the CLI prints its message on one line and
exits 1. ``ShipidWarning``: a result that stands but deserves a look (an implausible index, a
manoeuvre outside the training envelope, a trim that kept little); the CLI prints each as one
``warning:`` line and records them in its JSON outputs.
"""


class ShipidError(ValueError):
    """Bad input or an impossible request, with a message that names the file, column or option."""


class InfeasibleConstraintsError(ShipidError):
    """Constraints of a fit that no coefficients meet together (a structure that cannot be
    straight-line stable, say); ``select`` drops such a candidate instead of stopping."""


def require_function(value, where: str, example: str) -> None:
    """One line where a function is asked for and something else given (a structure or a model
    in ``fit``'s place failed with "'X' object is not callable" from inside)."""
    if not callable(value):
        raise ShipidError(f"{where}: fit must be a function, e.g. {example}; got "
                          f"{type(value).__name__}")


class ShipidWarning(UserWarning):
    """A result that stands but should be looked at; the message names what and why."""
