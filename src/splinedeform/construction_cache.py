"""Bounded caches of what a model's construction computes from its geometry alone.

A :class:`~splinedeform.Model` of a surface assembles ``K_r = Σ w_ab (T_uᵀ G_a^u T_u) ⊗
(T_vᵀ G_b^v T_v)`` (:mod:`splinedeform.assembly`). Everything but the weights ``w_ab``
depends only on the two 1-D bases and the edge presets, so models built again on the same
net (a benchmark's fresh model, a sweep over materials, a scenario run twice) find it here:

``gram``
    the 1-D Gram matrices ``G_a`` of a basis (:func:`splinedeform.quadrature.gram_matrix`),
    keyed by the basis (:func:`basis_key`: its kind, degree, knot vector bytes, weights and
    quadrature points per cell) and the order ``a``;
``constraint_map``
    the 1-D constraint maps ``T_1d`` of a basis and two end presets
    (:func:`splinedeform.boundary.constraint_map`);
``reduced``
    the reduced 1-D factors ``T_1dᵀ G_a T_1d`` of a basis and a map's bytes;
``layout``
    the compressed pattern of a sum of Kronecker products of two 1-D patterns
    (:class:`splinedeform.kronecker.KroneckerLayout`), keyed by the patterns' bytes.

Each cache is a least-recently-used map bounded by a number of entries and a number of
bytes (:class:`BoundedCache`); its arrays are made read-only, and what leaves the cache
for a caller to keep (a Gram matrix, a constraint map) is a copy, so no caller can change
what the next model finds. :func:`clear_caches` empties them all (to free the memory or to
time a construction from scratch); :func:`cache_info` tells their sizes.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Any, Callable, Hashable

import numpy as np

_CACHES: dict[str, "BoundedCache"] = {}


class BoundedCache:
    """A least-recently-used map of at most ``entries`` values and ``max_bytes`` bytes.

    ``nbytes(value)`` measures a value; a value larger than ``max_bytes`` is computed but
    not kept. Registered under ``name`` for :func:`clear_caches` and :func:`cache_info`.
    Safe to share between threads (a lock around the map; two threads missing the same key
    both compute it, the first result is kept).
    """

    def __init__(self, name: str, entries: int, max_bytes: int,
                 nbytes: Callable[[Any], int] = lambda value: 0) -> None:
        self.name, self.entries, self.max_bytes, self.nbytes = name, entries, max_bytes, nbytes
        self._data: OrderedDict[Hashable, tuple[Any, int]] = OrderedDict()
        self.bytes = 0
        self.hits = self.misses = 0
        self._lock = threading.Lock()
        _CACHES[name] = self

    def get(self, key: Hashable, make: Callable[[], Any]) -> Any:
        """The value kept under ``key``, else ``make()`` (kept when it fits)."""
        with self._lock:
            found = self._data.get(key)
            if found is not None:
                self._data.move_to_end(key)
                self.hits += 1
                return found[0]
            self.misses += 1
        value = make()                      # outside the lock: it may use other caches
        size = int(self.nbytes(value))
        if size <= self.max_bytes:
            with self._lock:
                if key not in self._data:
                    self._data[key] = (value, size)
                    self.bytes += size
                while len(self._data) > self.entries or self.bytes > self.max_bytes:
                    self.bytes -= self._data.popitem(last=False)[1][1]
        return value

    def clear(self) -> None:
        with self._lock:
            self._data.clear()
            self.bytes = self.hits = self.misses = 0

    def __len__(self) -> int:
        return len(self._data)


def clear_caches() -> None:
    """Empty every construction cache (the next model computes everything anew)."""
    for cache in _CACHES.values():
        cache.clear()


def cache_info() -> dict[str, dict[str, int]]:
    """``{name: {"entries", "bytes", "hits", "misses"}}`` of every construction cache."""
    return {name: {"entries": len(c), "bytes": c.bytes, "hits": c.hits, "misses": c.misses}
            for name, c in _CACHES.items()}


def read_only(*arrays: np.ndarray) -> None:
    """Make ``arrays`` read-only (what a cache keeps)."""
    for array in arrays:
        array.setflags(write=False)


def basis_key(basis: Any) -> tuple:
    """What determines a 1-D basis: its class, kind, degree, size, length, knot vector
    bytes, weights (a rational basis) and Gauss points per cell (its quadrature)."""
    inner = getattr(basis, "basis", None)            # a RationalBasis wraps a polynomial one
    weights = getattr(basis, "weights", None)
    return (type(basis).__name__, getattr(basis, "kind", None), int(basis.degree),
            int(basis.size), getattr(basis, "length", None), getattr(basis, "cells", None),
            np.asarray(basis.knots, dtype=float).tobytes() if inner is None else basis_key(inner),
            None if weights is None else np.asarray(weights, dtype=float).tobytes(),
            getattr(basis, "points_per_cell", basis.degree + 1))
