"""The one exception family of nambu_bch.

Every error raised on bad input derives from :class:`NambuBCHError` (itself a
``ValueError``), and its message names the offending input and what would be
accepted.  The CLI turns any of them into one line on stderr and exit code 2.
"""


class NambuBCHError(ValueError):
    """Base class of every error nambu_bch raises on bad input."""


class InvalidSystemError(NambuBCHError):
    """A system whose coordinates, Hamiltonians or parameters do not fit together."""


class NotSeparableError(InvalidSystemError):
    """A Hamiltonian that must be split per coordinate contains a coupling term."""


class UnknownModelError(NambuBCHError):
    """A built-in model name that does not exist."""


class InvalidCompositionError(NambuBCHError):
    """A composition (word or coefficient list) that is malformed."""


class UnknownPieceError(InvalidCompositionError):
    """A word names a piece that the splitting does not have."""


class InconsistentCoefficientsError(InvalidCompositionError):
    """The coefficients of some piece do not sum to one (the scheme is inconsistent)."""


class NoExactFlowError(NambuBCHError):
    """A piece of a splitting whose flow cannot be written in closed form."""


class InvalidOrderError(NambuBCHError):
    """A truncation order that is negative, not an integer, or too high to finish."""


class ExpressionParseError(NambuBCHError):
    """A user expression that is not accepted by the safe parser."""


class UnstableStepError(NambuBCHError):
    """A step size outside the stability interval of the integrator (e.g. ``|omega h| >= 2``)."""


class NumericalRangeError(NambuBCHError):
    """A numeric input or result that is not finite (overflow, NaN input)."""


class NoExactResultError(NambuBCHError):
    """An exact result (polynomial invariant, exact factor form F(omega h), closed-form solution) that this system and word do not have."""


class InvalidRunError(NambuBCHError):
    """An argument of a numeric run (step count, sampling, initial-state shape, backend, precision) that is not accepted."""


class OutputError(NambuBCHError):
    """An output path that cannot be written (a directory, a dangling link, no space left, no permission)."""


class ResourceLimitError(NambuBCHError):
    """A request whose size, estimated from the input before any work, exceeds what can finish (refused up front)."""


#: Longest error line printed (a huge input echoed back is shortened).
MAX_MESSAGE = 600


def shown(value, limit: int = 80) -> str:
    """A user string as echoed in a message: quoted, control characters, bidi marks and newlines escaped, shortened.

    The one way the command line echoes text it was given (paths, names, flag values) so that a
    message cannot carry terminal escapes, right-to-left overrides or line breaks.
    """
    text = str(value)
    if len(text) > limit:
        text = text[: limit - 3] + "..."
    return repr(text)


def one_line(message: str, limit: int = MAX_MESSAGE) -> str:
    """``message`` as one printable line: whitespace runs become one space, other unprintable characters are escaped.

    The last filter of every line the command line prints on stderr, and how the library's messages
    show a user value whose ``repr`` spans lines (a numpy array, a matrix).
    """
    text = " ".join(str(message).split())
    text = "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in text)
    if len(text) > limit:  # a huge input echoed back: keep the line readable
        text = text[: limit - 3] + "..."
    return text


def did_you_mean(word, candidates) -> str:
    """``" (did you mean 'x'?)"`` for the candidate closest to ``word``, or ``""`` when none is close.

    The one suggestion helper of the package (model names, integrator aliases, command-line
    flags and choices).  A candidate equal to ``word`` up to case and ``-``/``_`` wins, then
    the only candidate that ``word`` begins (``lotka`` for ``lotka-volterra``), else
    :func:`difflib.get_close_matches` picks at most one.

    >>> did_you_mean("rigidbody", ["ho3", "rigid-body"]), did_you_mean("zzz", ["ho3"])
    (" (did you mean 'rigid-body'?)", '')
    """
    import difflib

    if not isinstance(word, str) or not word:
        return ""
    names = [c for c in candidates if isinstance(c, str)]

    def key(text):
        return text.lower().replace("_", "-")

    same = [c for c in names if key(c) == key(word) and c != word]
    if not same and len(word) >= 3:
        same = [c for c in names if key(c).startswith(key(word))]
        same = same if len(same) == 1 else []
    close = same or difflib.get_close_matches(key(word), [key(c) for c in names], n=1, cutoff=0.6)
    if not close:
        return ""
    best = close[0] if same else next(c for c in names if key(c) == close[0])
    return f" (did you mean {best!r}?)"
