"""The checks the command line makes on its flags, for Python's arguments:
a wrong value or type raises fiberlab.Error naming the argument and what is
allowed (never a TypeError from deep inside, never a silent prefix)."""
import math
import numbers
import os

from . import _fiberlab


def path_argument(name, path):
    """A file path (str or os.PathLike) as str; refuses other types and NUL bytes
    (the C library would read the path only up to the NUL)."""
    try:
        text = os.fspath(path)
    except TypeError:
        raise _fiberlab.Error("%s must be a path (str or os.PathLike), not %s"
                              % (name, type(path).__name__)) from None
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    if "\0" in text:
        raise _fiberlab.Error("%s %r contains a NUL byte" % (name, text))
    if not text:
        raise _fiberlab.Error("%s is empty" % name)
    return text


def count_argument(name, value, minimum, maximum=2 ** 64 - 1):
    """An integer in [minimum, maximum]; a float is accepted when it is integral
    (1e6, as configs and --photons accept it). None stays None."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise _fiberlab.Error("%s = %r is not a number (an integer from %d to %d)"
                              % (name, value, minimum, maximum))
    if not isinstance(value, numbers.Integral):
        x = float(value)
        if not math.isfinite(x) or x != math.floor(x):
            raise _fiberlab.Error("%s = %r is not an integer (from %d to %d)" % (name, value, minimum, maximum))
        if not minimum <= x <= maximum:  # before int(): 1e300 is integral too
            raise _fiberlab.Error("%s = %r is out of range (an integer from %d to %d)"
                                  % (name, value, minimum, maximum))
        value = int(x)
    value = int(value)
    if not minimum <= value <= maximum:
        raise _fiberlab.Error("%s = %d is out of range (an integer from %d to %d)" % (name, value, minimum, maximum))
    return value


def real_argument(name, value, allowed):
    """A real number (not a bool); the range is checked by the C++ library."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise _fiberlab.Error("%s = %r is not a number (%s)" % (name, value, allowed))
    return float(value)


def instance_argument(name, value, cls, what):
    if not isinstance(value, cls):
        raise _fiberlab.Error("%s must be %s, not %s" % (name, what, type(value).__name__))
    return value
