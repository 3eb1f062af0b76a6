"""A config given as a path or as a dict with the YAML file's keys, turned into
the C++ library's resolved Settings (validated there, with the same one-line
messages as `fiberlab run`)."""
import json
import numbers
import os

from . import _fiberlab
from ._checks import path_argument


def _plain(value):
    """NumPy scalars and arrays as plain Python numbers and lists (for JSON)."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError("config value %r (%s) is not a number, string, list or dict"
                    % (value, type(value).__name__))


def _json_safe(value, where):
    """Refuses what JSON would write but YAML would not read as the number
    meant (NaN, infinities) or a key that is not text."""
    if isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, str):
                raise _fiberlab.Error("config: key %r under %s is not a string" % (key, where or "the top"))
            _json_safe(item, (where + "." if where else "") + key)
    elif isinstance(value, (list, tuple)):
        for item in value:
            _json_safe(item, where)
    elif isinstance(value, numbers.Real) and not isinstance(value, bool) and value != value:
        raise _fiberlab.Error("config: %s is NaN" % where)


def to_settings(config):
    """Settings from a YAML path (str or os.PathLike), a dict with the YAML's
    keys (degrees, as in the file), or a Result (its config)."""
    if hasattr(config, "_settings"):
        return config._settings()
    if isinstance(config, (str, bytes, os.PathLike)):
        return _fiberlab.load_settings(path_argument("config", config))
    if isinstance(config, dict):
        _json_safe(config, "")
        # JSON is YAML (a flow mapping), so the C++ parser reads it as a config file.
        try:
            text = json.dumps(config, default=_plain)
        except (TypeError, ValueError) as e:
            raise _fiberlab.Error("config dict: %s" % e) from None
        return _fiberlab.parse_settings(text, "config")
    raise _fiberlab.Error("config must be a path to a YAML file, a dict with its keys, or a Result; got %s"
                          % type(config).__name__)
