"""Pair selection people can write: geom/body patterns for ``hazards=`` and ``allow=``.

A *pattern* is a string that selects a set of geoms of an ``MjModel``:

==================  =======================================================================
``group:N``         every geom whose ``geom_group`` is ``N`` (MuJoCo geom groups 0..5)
``NAME/**``         every geom of body ``NAME`` and of all its descendant bodies (subtree);
                    ``NAME`` may itself be a glob (``"*arm*/**"``)
``BODY/K``          the ``K``-th geom (0-based, in model order) of body ``BODY``: the way to
                    address unnamed geoms (``"object/0"`` instead of the generated ``geom18``)
anything else       an ``fnmatch`` glob (case-sensitive) matched against geom names *and*
                    body names: a matching geom is selected, and so is every geom carried
                    by a matching body (not its descendants: use ``/**`` for a subtree)
==================  =======================================================================

Geom names are MuJoCo's names, ``"geom<id>"`` for unnamed geoms (as in
:class:`monitor.Scene`); body names are ``"body<id>"`` for unnamed bodies.

An *item* of ``hazards=`` / ``allow=`` is either one pattern, selecting every
candidate pair with at least one geom in the set, or a pair of patterns
``(P, Q)``, selecting the candidate pairs with one geom in ``P`` and the other in
``Q``. A single string is one item. The resolved sets:

* monitored = candidate pairs (``pairs=`` mode) ∩ (union of the ``hazards`` items;
  all candidates when ``hazards`` is None) − pairs allowed by ``allow`` (reason
  ``User``) − pairs allowed by the ACM (its reasons, see :mod:`monitor.acm`);
* every removed pair is reported with its reason (``python -m monitor pairs``).

A pattern that matches no geom raises :class:`~monitor.errors.InvalidInputError`
naming the argument and listing the names available.
"""

from __future__ import annotations

import fnmatch
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from monitor.errors import InvalidInputError

_GROUP = re.compile(r"^group:(\d+)$")
_INDEX = re.compile(r"^(.+)/(\d+)$")
_MAX_LISTED = 40


def object_names(model: Any, adr: np.ndarray, prefix: str) -> list[str]:
    """MuJoCo's object names at offsets ``adr`` (n,) of ``model.names``; ``f"{prefix}{i}"`` when empty.

    The same strings as ``model.geom(i).name`` / ``model.body(i).name`` (each name runs from its
    offset to the next NUL byte of the names buffer), read in one pass over the buffer.
    """
    blob = model.names
    adr = np.asarray(adr, dtype=np.int64)
    nul = np.flatnonzero(np.frombuffer(blob, dtype=np.uint8) == 0)
    end = nul[np.searchsorted(nul, adr)]
    return [blob[a:e].decode() or f"{prefix}{i}" for i, (a, e) in enumerate(zip(adr.tolist(), end.tolist()))]


@dataclass(frozen=True)
class ModelNames:
    """Names and tree structure of a model, as pattern resolution needs them.

    Attributes:
        geom_names: (ngeom,) geom names (``"geom<id>"`` when unnamed).
        body_names: (nbody,) body names (``"body<id>"`` when unnamed).
        geom_body: (ngeom,) int body id of each geom.
        body_parent: (nbody,) int parent body id (world's parent is 0).
        geom_group: (ngeom,) int MuJoCo geom group.
    """

    geom_names: tuple[str, ...]
    body_names: tuple[str, ...]
    geom_body: np.ndarray
    body_parent: np.ndarray
    geom_group: np.ndarray

    @classmethod
    def from_model(cls, model: Any) -> ModelNames:
        """Read names/tree from a ``mujoco.MjModel``."""
        return cls(tuple(object_names(model, model.name_geomadr, "geom")),
                   tuple(object_names(model, model.name_bodyadr, "body")),
                   np.asarray(model.geom_bodyid, dtype=np.int64).copy(),
                   np.asarray(model.body_parentid, dtype=np.int64).copy(),
                   np.asarray(model.geom_group, dtype=np.int64).copy())

    def body_geoms(self, b: int) -> list[int]:
        """Geom ids of body ``b`` in model order."""
        return [int(g) for g in np.flatnonzero(self.geom_body == b)]

    def alias(self, g: int) -> str:
        """``"body/index"`` address of geom ``g``."""
        b = int(self.geom_body[g])
        return f"{self.body_names[b]}/{self.body_geoms(b).index(g)}"

    def label(self, g: int) -> str:
        """Geom name, followed by its ``body/index`` alias when the geom is unnamed."""
        name = self.geom_names[g]
        return f"{name} ({self.alias(g)})" if re.fullmatch(r"geom\d+", name) else name

    def subtree(self, b: int) -> set[int]:
        """Body ``b`` and all its descendants."""
        out, changed = {b}, True
        while changed:
            changed = False
            for c in range(len(self.body_names)):
                if c not in out and c != 0 and int(self.body_parent[c]) in out:
                    out.add(c)
                    changed = True
        return out


def _available(names: ModelNames) -> str:
    geoms = [names.label(g) for g in range(len(names.geom_names))]
    bodies = list(names.body_names)

    def cut(xs: list[str]) -> str:
        s = ", ".join(xs[:_MAX_LISTED])
        return s + (f", ... ({len(xs) - _MAX_LISTED} more)" if len(xs) > _MAX_LISTED else "")
    groups = sorted(set(int(x) for x in names.geom_group))
    return (f"geoms: {cut(geoms)}; bodies: {cut(bodies)}; groups: "
            + ", ".join(f"group:{k}" for k in groups))


def resolve_pattern(names: ModelNames, pattern: str, *, arg: str = "pattern") -> frozenset[int]:
    """Geom ids selected by one pattern (see module docstring).

    Args:
        names: the model's :class:`ModelNames`.
        pattern: the pattern string.
        arg: argument name used in error messages (e.g. ``"hazards[2]"``).

    Returns:
        frozenset of geom ids (never empty).

    Raises:
        InvalidInputError: not a string, empty, or it matches no geom (the message lists
            the available geom names, body names and groups).
    """
    if not isinstance(pattern, str) or not pattern.strip():
        raise InvalidInputError(f"{arg}: a pattern must be a non-empty string, got {pattern!r}")
    p = pattern.strip()
    sel: set[int] = set()
    m = _GROUP.match(p)
    if m:
        sel = {int(g) for g in np.flatnonzero(names.geom_group == int(m.group(1)))}
    elif p.endswith("/**"):
        stem = p[:-3]
        for b, bn in enumerate(names.body_names):
            if fnmatch.fnmatchcase(bn, stem):
                for c in names.subtree(b):
                    sel.update(names.body_geoms(c))
    else:
        m = _INDEX.match(p)
        if m:
            stem, k = m.group(1), int(m.group(2))
            for b, bn in enumerate(names.body_names):
                if fnmatch.fnmatchcase(bn, stem):
                    gs = names.body_geoms(b)
                    if k < len(gs):
                        sel.add(gs[k])
        for g, gn in enumerate(names.geom_names):
            if fnmatch.fnmatchcase(gn, p):
                sel.add(g)
        for b, bn in enumerate(names.body_names):
            if fnmatch.fnmatchcase(bn, p):
                sel.update(names.body_geoms(b))
    if not sel:
        raise InvalidInputError(f"{arg}: pattern {pattern!r} matches no geom; available {_available(names)}")
    return frozenset(sel)


def _items(spec: Any, arg: str) -> list[tuple[str, str | None]]:
    """Normalise ``hazards``/``allow`` to a list of (pattern, pattern-or-None)."""
    if spec is None:
        return []
    if isinstance(spec, str):
        return [(spec, None)]
    try:
        raw = list(spec)
    except TypeError:
        raise InvalidInputError(f"{arg} must be a pattern, a list of patterns or of pattern pairs, "
                                f"got {type(spec).__name__}") from None
    out: list[tuple[str, str | None]] = []
    for k, it in enumerate(raw):
        if isinstance(it, str):
            out.append((it, None))
        elif isinstance(it, Sequence) and len(it) == 2 and all(isinstance(x, str) for x in it):
            out.append((it[0], it[1]))
        else:
            raise InvalidInputError(f"{arg}[{k}] must be a pattern string or a (pattern, pattern) pair, "
                                    f"got {it!r}")
    return out


def pair_mask(names: ModelNames, pair_ids: np.ndarray, spec: Any, *, arg: str) -> np.ndarray:
    """Which rows of ``pair_ids`` (P, 2) the items of ``spec`` select (union over items).

    Returns:
        (P,) bool.
    """
    pair_ids = np.asarray(pair_ids, dtype=np.int64).reshape(-1, 2)
    mask = np.zeros(len(pair_ids), dtype=bool)
    ng = len(names.geom_names)
    for k, (p, q) in enumerate(_items(spec, arg)):
        sa = np.zeros(ng, dtype=bool)
        sa[list(resolve_pattern(names, p, arg=f"{arg}[{k}]"))] = True
        a_in, b_in = sa[pair_ids[:, 0]], sa[pair_ids[:, 1]]
        if q is None:
            mask |= a_in | b_in
        else:
            sb = np.zeros(ng, dtype=bool)
            sb[list(resolve_pattern(names, q, arg=f"{arg}[{k}][1]"))] = True
            mask |= (a_in & sb[pair_ids[:, 1]]) | (b_in & sb[pair_ids[:, 0]])
    return mask


def geom_pairs(names: ModelNames, pair_ids: Iterable[Sequence[int]]) -> list[tuple[str, str]]:
    """(name_a, name_b) per geom id pair."""
    return [(names.geom_names[int(a)], names.geom_names[int(b)]) for a, b in pair_ids]


__all__ = ["object_names", "ModelNames", "resolve_pattern", "pair_mask", "geom_pairs"]
