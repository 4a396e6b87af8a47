"""Broad phase of the self-contact search: which points lie in which boxes, and which boxes
overlap, for axis-aligned boxes in the plane.

Both are found on a uniform bucket grid with numpy alone. Each box is put in the cell of
its centre, the cells being a little larger than the largest box; a point inside a box,
or a box that overlaps it, then lies in the box's cell or in one of its eight neighbours.
Only those cells are searched, so the cost grows with the boxes, the points and the pairs
near each other, not with every combination. Every overlapping pair (closed boxes) is
returned and no other, so a caller whose exact test implies the overlap finds the pairs
a test of every combination finds.
"""

from __future__ import annotations

import math

import numpy as np

_NEIGHBOURS = np.array([-1, 0, 1])


class _Grid:
    """Boxes binned by their centres' cells, as keys sorted for ``searchsorted``."""

    def __init__(self, lo: np.ndarray, hi: np.ndarray):
        self.boxes = len(lo)
        centre = 0.5 * (lo + hi)
        self.origin = centre.min(axis=0)
        extent = float((centre.max(axis=0) - self.origin).max())
        side = 1.01 * float((hi - lo).max())
        # coordinates near the largest double overflow: no grid, every box is near
        self.whole = not (math.isfinite(extent) and math.isfinite(side))
        if self.whole:
            return
        # a cell 1 % wider than the largest box: two overlapping boxes' centres are less than
        # a cell apart, whatever the rounding, so their cells are neighbours; and at most 2^20
        # cells a side (boxes scattered by a diverging iterate), so that keys fit in int64
        self.size = max(side, extent / 2**20) or 1.0
        cell = self.cell(centre)
        self.top = cell.max(axis=0)
        self.width = int(self.top[1]) + 3  # columns 1 .. top + 1 hold boxes; 0 and top + 2 none
        key = self._key(cell)
        self.order = np.argsort(key, kind="stable")
        self.keys = key[self.order]

    def cell(self, x: np.ndarray) -> np.ndarray:
        """(n, 2) integer cells. The floor of a correctly rounded, increasing map: a point
        that is a cell away from another is at most one cell index away."""
        return np.floor((x - self.origin) / self.size).astype(np.int64)

    def _key(self, cell: np.ndarray) -> np.ndarray:
        # one row of ``width`` keys per cell row; the empty first and last columns keep a
        # neighbour column of a row's edge from reaching into the next row's boxes
        return (cell[:, 0] + 1) * self.width + cell[:, 1] + 1

    def near(self, cell: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(query, box): every box whose cell neighbours the query's ``cell``."""
        if self.whole:
            return np.arange(len(cell)).repeat(self.boxes), np.tile(np.arange(self.boxes), len(cell))
        # cells off the grid are moved to its rim, where their neighbours hold no box
        cell = np.clip(cell, -1, self.top + 1)
        start = self._key(cell)[:, None] + self.width * _NEIGHBOURS - 1  # three columns of each row
        first = np.searchsorted(self.keys, start, side="left").reshape(-1)
        count = np.searchsorted(self.keys, start + 2, side="right").reshape(-1) - first
        query = np.repeat(np.arange(len(cell)).repeat(3), count)
        k = np.arange(len(query)) - np.repeat(np.cumsum(count) - count, count)  # rank within the range
        return query, self.order[np.repeat(first, count) + k]


def _all_finite(*arrays: np.ndarray) -> bool:
    # one sum each: NaN or infinite if an entry is (or if it overflows: then each entry is
    # checked)
    return bool(np.isfinite(sum(a.sum() for a in arrays)))


def points_in_boxes(points: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (point i, box j) with the point in the closed box lo[j] <= x <= hi[j].

    Args:
        points: (n, 2) coordinates.
        lo: (m, 2) lower corners of the boxes.
        hi: (m, 2) upper corners.

    Returns:
        (i, j) integer arrays, in no particular order; no pair holds a point or a box
        that is not finite.
    """
    if len(points) == 0 or len(lo) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    if not _all_finite(points, lo, hi):
        p = np.flatnonzero(np.isfinite(points).all(axis=1))
        b = np.flatnonzero(np.isfinite(lo).all(axis=1) & np.isfinite(hi).all(axis=1))
        if p.size < len(points) or b.size < len(lo):
            i, j = points_in_boxes(points[p], lo[b], hi[b])
            return p[i], b[j]
    grid = _Grid(lo, hi)
    i, j = grid.near(grid.cell(points))
    p = points[i]
    inside = (p >= lo[j]) & (p <= hi[j])
    inside = inside[:, 0] & inside[:, 1]
    return i[inside], j[inside]


def overlapping_boxes(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs of closed boxes that overlap, i < j, sorted by i and then j (the order of
    ``np.triu_indices``).

    Args:
        lo: (m, 2) lower corners of the boxes.
        hi: (m, 2) upper corners.

    Returns:
        (i, j) integer arrays; no pair holds a box that is not finite.
    """
    if len(lo) < 2:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    if not _all_finite(lo, hi):
        b = np.flatnonzero(np.isfinite(lo).all(axis=1) & np.isfinite(hi).all(axis=1))
        if b.size < len(lo):
            i, j = overlapping_boxes(lo[b], hi[b])
            return b[i], b[j]
    grid = _Grid(lo, hi)
    i, j = grid.near(grid.cell(0.5 * (lo + hi)))
    # each pair is found from both of its boxes: keep it once
    overlap = (i < j) & np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]), axis=1)
    i, j = i[overlap], j[overlap]
    order = np.argsort(i * len(lo) + j)
    return i[order], j[order]
