"""Sub-commands of ``servohydraulics`` that live in their own module.

Each module here defines ``register(sub)``, which adds its parser to the
``argparse`` sub-parsers and sets ``func`` (a function ``args -> int``).  The
CLI imports every module of this package in name order, so adding a command is
adding a file.  Keep the module's top-level imports light (import the heavy
work inside ``func``): every CLI start imports them all.
"""

from __future__ import annotations

import importlib
import pkgutil


def register_all(sub) -> None:
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        importlib.import_module(f"{__name__}.{info.name}").register(sub)
