"""A config given as a path or as a dict with the YAML file's keys, turned into
the C++ library's resolved Settings (validated there, with the same one-line
messages as `fiberlab run`)."""
import json
import os

from . import _fiberlab


def _plain(value):
    """NumPy scalars and arrays as plain Python numbers and lists (for JSON)."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError("config value %r (%s) is not a number, string, list or dict"
                    % (value, type(value).__name__))


def to_settings(config):
    """Settings from a YAML path (str or os.PathLike), a dict with the YAML's
    keys (degrees, as in the file), or a Result (its config)."""
    if hasattr(config, "_settings"):
        return config._settings()
    if isinstance(config, (str, os.PathLike)):
        return _fiberlab.load_settings(os.fspath(config))
    if isinstance(config, dict):
        # JSON is YAML (a flow mapping), so the C++ parser reads it as a config file.
        try:
            text = json.dumps(config, default=_plain)
        except TypeError as e:
            raise _fiberlab.Error("config dict: %s" % e) from None
        return _fiberlab.parse_settings(text, "config")
    raise TypeError("config must be a path to a YAML file, a dict with its keys, or a Result; got %s"
                    % type(config).__name__)
