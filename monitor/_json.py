"""One converter from numpy-bearing objects to strict JSON values.

Used by certificates (``to_dict``), MCAP logs and benchmark reports, which
differ only in what a non-finite float becomes.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np

NonFinite = Literal["null", "clamp"]


def finite_or(x: float, nonfinite: NonFinite = "null") -> float | None:
    """A float as strict JSON: NaN -> None; +-inf -> None ("null") or +-1e308 ("clamp").

    "clamp" keeps the sign of an infinite bound (e.g. a clearance of -inf), which
    :meth:`monitor.Certificate.from_dict` reads back as a huge finite value.
    """
    x = float(x)
    if math.isfinite(x):
        return x
    if math.isnan(x) or nonfinite == "null":
        return None
    return 1e308 if x > 0 else -1e308


def jsonable(x: Any, nonfinite: NonFinite = "null") -> Any:
    """Recursively convert dicts, sequences, numpy arrays and scalars to JSON values.

    Args:
        x: any nesting of dict / list / tuple / np.ndarray / numpy or Python scalars.
        nonfinite: policy for NaN and inf (see :func:`finite_or`).

    Returns:
        The same structure with str keys, lists, Python bool/int/float/None.
    """
    if isinstance(x, dict):
        return {str(k): jsonable(v, nonfinite) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v, nonfinite) for v in x]
    if isinstance(x, np.ndarray):
        if x.dtype.kind == "f" and np.isfinite(x).all():
            return x.tolist()
        return jsonable(x.tolist(), nonfinite)
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return finite_or(x, nonfinite)
    return x
