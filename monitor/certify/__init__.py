"""Certification: the engine (:func:`certify`) and the two certified checkers.

``monitor.certify`` is both this subpackage and the public function
``monitor.certify(scene, plan, ...)``: the module object is made callable and
forwards to :func:`monitor.certify.engine.certify`, so that importing any
``monitor.certify.*`` submodule (which rebinds the attribute ``monitor.certify``
to this package) never shadows the function.
"""

from __future__ import annotations

import sys
import types
from typing import Any


class _CallableModule(types.ModuleType):
    """Module type whose instances forward calls to ``engine.certify``."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        from monitor.certify.engine import certify

        return certify(*args, **kwargs)


def __getattr__(name: str) -> Any:
    if name == "certify":
        from monitor.certify.engine import certify

        return certify
    raise AttributeError(f"module 'monitor.certify' has no attribute {name!r}")


sys.modules[__name__].__class__ = _CallableModule
