"""Neighbour search: the CSR lists and the unique pairs against brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.crowd.neighbors import CellList, Neighbors, find_neighbors


def brute_pairs(pos: np.ndarray, cutoff: float) -> set[tuple[int, int]]:
    """Every ``(i, j)``, ``i < j``, strictly closer than ``cutoff``, with the kernels' test."""
    d = pos[None, :, :] - pos[:, None, :]  # pos[j] - pos[i], as the scan forms it
    close = d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1] < cutoff * cutoff
    i, j = np.nonzero(np.triu(close, k=1))
    return set(zip(i.tolist(), j.tolist(), strict=True))


def scene(n: int, size: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0.0, size, (n, 2))
    if n >= 4:
        pos[1] = pos[0]  # coincident agents are neighbours (distance 0 < cutoff)
        pos[3, 1] = pos[2, 1]  # same row
    return pos


@pytest.mark.parametrize(
    ("n", "size", "cutoff"),
    [(300, 40.0, 10.0), (500, 20.0, 3.0), (50, 5.0, 10.0), (200, 1.0, 10.0), (2, 1.0, 0.5)],
)
def test_unique_pairs_match_brute_force_and_csr(n: int, size: float, cutoff: float) -> None:
    pos = scene(n, size, n)
    nb = find_neighbors(pos, cutoff)
    pi, pj = nb.unique_pairs()
    assert pi.dtype == np.int64 and pj.dtype == np.int64
    assert np.all(pi < pj)
    got = list(zip(pi.tolist(), pj.tolist(), strict=True))
    assert len(got) == len(set(got))  # each pair once
    assert set(got) == brute_pairs(pos, cutoff)
    # Same order as the CSR rows (what models relied on before): the j > i entries of pairs().
    ci, cj = find_neighbors(pos, cutoff).pairs()
    keep = cj > ci
    np.testing.assert_array_equal(pi, ci[keep])
    np.testing.assert_array_equal(pj, cj[keep])
    assert nb.unique_pairs()[0] is pi  # cached


def test_deferred_csr_equals_the_cell_list_query() -> None:
    pos = scene(400, 30.0, 1)
    nb = find_neighbors(pos, 10.0)
    ref = CellList(pos, 5.0).query(pos, 10.0, exclude_self=True)
    np.testing.assert_array_equal(nb.indptr, ref.indptr)
    np.testing.assert_array_equal(nb.indices, ref.indices)
    assert len(nb) == 400 and nb.cutoff == 10.0
    pairs = brute_pairs(pos, 10.0)
    for i in (0, 7, 399):
        want = {b for a, b in pairs if a == i} | {a for a, b in pairs if b == i}
        assert set(nb.of(i).tolist()) == want
    # Unique pairs after the CSR was read come from the CSR: the same arrays.
    pi, pj = nb.unique_pairs()
    fresh = find_neighbors(pos, 10.0).unique_pairs()
    np.testing.assert_array_equal(pi, fresh[0])
    np.testing.assert_array_equal(pj, fresh[1])


def test_results_do_not_depend_on_later_moves_of_the_positions() -> None:
    pos = scene(100, 10.0, 2)
    nb = find_neighbors(pos, 2.0)
    want = brute_pairs(pos.copy(), 2.0)
    pos += 100.0 * np.random.default_rng(0).random(pos.shape)  # caller moves its agents
    pi, pj = nb.unique_pairs()
    assert set(zip(pi.tolist(), pj.tolist(), strict=True)) == want


def test_unique_pairs_of_explicit_csr_and_all_pairs() -> None:
    indptr = np.array([0, 2, 4, 5, 6], dtype=np.int64)
    indices = np.array([3, 1, 0, 2, 1, 0], dtype=np.int64)
    pi, pj = Neighbors(indptr, indices, 1.0).unique_pairs()
    np.testing.assert_array_equal(pi, [0, 0, 1])
    np.testing.assert_array_equal(pj, [3, 1, 2])
    pi, pj = find_neighbors(scene(5, 3.0, 3), math.inf).unique_pairs()
    assert list(zip(pi.tolist(), pj.tolist(), strict=True)) == [
        (i, j) for i in range(5) for j in range(i + 1, 5)
    ]


def test_empty_and_single() -> None:
    for pos, cutoff in ((np.zeros((0, 2)), 1.0), (np.zeros((1, 2)), 1.0), (scene(5, 1, 4), 0.0)):
        nb = find_neighbors(pos, cutoff)
        pi, pj = nb.unique_pairs()
        assert pi.size == 0 and pj.size == 0
        assert len(nb) == pos.shape[0]


def test_neighbors_are_read_only() -> None:
    nb = find_neighbors(scene(10, 2.0, 5), 1.0)
    with pytest.raises(AttributeError):
        nb.indptr = np.zeros(11, dtype=np.int64)  # type: ignore[misc]
    with pytest.raises(AttributeError):
        nb.cutoff = 2.0  # type: ignore[misc]


@pytest.mark.parametrize(("n", "scale", "cell"), [(1, 1.0, 1.0), (7, 1e-3, 0.01), (300, 30.0, 5.0)])
def test_compiled_cell_list_is_the_constructors(n: int, scale: float, cell: float) -> None:
    pts = np.random.default_rng(n).normal(0.0, scale, (n, 2))
    pts[-1] = pts[0]  # a repeated point
    want = CellList(pts, cell)
    got = CellList._of_copy(pts.copy(), cell)
    assert got.origin.tobytes() == want.origin.tobytes()
    assert (got.cell, got.shape) == (want.cell, want.shape)
    assert got.shape[0].__class__ is int and isinstance(got.cell, float)
    np.testing.assert_array_equal(got.order, want.order)
    np.testing.assert_array_equal(got.starts, want.starts)


@pytest.mark.parametrize(
    ("n", "scale", "cell"), [(1, 1.0, 1.0), (50, 1e-3, 0.01), (3000, 30.0, 5.0)]
)
def test_cell_list_is_the_numpy_construction(n: int, scale: float, cell: float) -> None:
    """Bounds by numpy's min/max, cells ordered by a stable argsort of their ids."""
    pts = np.random.default_rng(n).normal(0.0, scale, (n, 2))
    pts[n // 2 :] = pts[: n - n // 2]  # repeated points: ties in the sort
    got = CellList(pts, cell)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    nx = math.floor((hi[0] - lo[0]) / cell) + 1
    ny = math.floor((hi[1] - lo[1]) / cell) + 1
    assert got.origin.tobytes() == lo.tobytes() and got.shape == (nx, ny) and got.cell == cell
    cx = np.clip(((pts[:, 0] - lo[0]) / cell).astype(np.int64), 0, nx - 1)
    cy = np.clip(((pts[:, 1] - lo[1]) / cell).astype(np.int64), 0, ny - 1)
    cid = cy * nx + cx
    np.testing.assert_array_equal(got.order, np.argsort(cid, kind="stable"))
    counts = np.bincount(cid, minlength=nx * ny)
    np.testing.assert_array_equal(got.starts, np.r_[0, np.cumsum(counts)])


def test_compiled_cell_list_leaves_odd_extents_to_the_constructor() -> None:
    huge = CellList._of_copy(np.array([[0.0, 0.0], [1e300, 1.0]]), 1.0)  # coarsened, not overflown
    want = CellList(np.array([[0.0, 0.0], [1e300, 1.0]]), 1.0)
    assert (huge.cell, huge.shape) == (want.cell, want.shape)
    with pytest.raises(ValueError, match="NaN"):
        CellList._of_copy(np.array([[0.0, 0.0], [np.nan, 1.0]]), 1.0)
