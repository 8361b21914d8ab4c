"""Exceptions raised for bad input; each message says what was wrong and what is allowed."""


class InputError(ValueError):
    """A value given by the caller is out of range, of the wrong shape or not finite."""


class SingularSystemError(InputError):
    """The requested solve has no unique solution (usually: a boundary condition is missing)."""


class ScenarioError(InputError):
    """A scenario file is invalid; the message names the file, the key path and the line."""


class InputWarning(UserWarning):
    """Input that is used but deserves a look (a dropped trimming, an unjoined seam, …).

    The command line prints each as one line, ``warning: <message>``, on stderr.
    """
