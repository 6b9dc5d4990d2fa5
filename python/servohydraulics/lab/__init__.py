"""Deprecated alias of :mod:`servohydraulics.identification` (removed in 0.3.0).

``servohydraulics.lab`` and its modules (``lab.baselines``, ``lab.compare``, ``lab.figures``,
``lab.fitting``, ``lab.frf``, ``lab.generic``, ``lab.identification``, ``lab.keys``,
``lab.report``, ``lab.run``) are the modules of the identification package under their
old names."""

import importlib as _importlib
import sys as _sys
import warnings as _warnings

_warnings.warn("servohydraulics.lab is deprecated and will be removed in 0.3.0; use servohydraulics.identification",
               DeprecationWarning, stacklevel=2)

#: old module name -> its module in the identification package
_MOVED = {"baselines": "baselines", "compare": "compare", "figures": "figures", "fitting": "fit", "frf": "frf",
          "generic": "generic", "identification": "records", "keys": "coordinates", "report": "report",
          "run": "run"}

for _old, _new in _MOVED.items():
    _module = _importlib.import_module(f"servohydraulics.identification.{_new}")
    _sys.modules[f"{__name__}.{_old}"] = _module
    globals()[_old] = _module

from ..identification import *  # noqa: E402, F403 (every name of the package under its old one)
from ..identification import __all__  # noqa: E402, F401
