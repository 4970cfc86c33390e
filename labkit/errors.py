"""The one exception family for input a person can fix.

:class:`InputError` is a :class:`ValueError` (so ``except ValueError`` still catches it) whose message says
what is wrong and how to fix it. ``labkit``'s command line prints it as it is; any other exception is a bug
in labkit, and the command line says so and how to see its traceback.
"""


class InputError(ValueError):
    """Bad input: a path, option, file, notebook or argument a person can fix as the message says."""
