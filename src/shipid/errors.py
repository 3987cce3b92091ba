"""The one exception type of user errors: the CLI prints its message on one line and exits 1."""


class ShipidError(ValueError):
    """Bad input or an impossible request, with a message that names the file, column or option."""
