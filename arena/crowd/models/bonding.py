r"""Escape panic with bonding: the evacuation model plus an attraction between related agents.

Arena 3.0 (Table I, "Bonding") cites Xu, S. & Duh, H. B.-L. (2010) "A simulation of bonding
effects and their impacts on pedestrian dynamics", *IEEE Trans. Intell. Transp. Syst.* 11(1),
153–161, as "a variation of the evacuation model including a bonding term". Only that paper's
abstract was retrievable here: it "derives an exponential formulation of the bonding force, as
opposed to the repulsive force" on top of the social force model and calibrates its
parameters by simulation runs. Its exact equation and calibrated values could not be read, so
**the bonding term below is our own derivation**, following that description, not a
transcription of the paper:

.. math::

    \mathbf f^{b}_{ij} = C\,\big[1 - e^{-s_{ij}/D}\big]\,\frac{\mathbf x_j - \mathbf x_i}{d_{ij}},
    \qquad s_{ij} = d_{ij} - r_{ij} - c, \quad \text{applied only if } s_{ij} > 0,

for every pair ``i ≠ j`` with the same ``state.group`` id (``≥ 0``), whatever their distance
(group members are not limited to the neighbour cutoff). ``c`` is a comfort gap between body
surfaces inside which relatives feel no pull; beyond it the pull grows like a spring
(slope ``C/D`` at the comfort distance) and saturates at ``C``, so a member far behind is pulled
with a bounded force instead of one growing without limit. It is the mirror image of
Helbing's exponential repulsion: an exponential in the gap, attracting instead of repelling.

Parameter choices (ours, not the paper's): ``C = 200 N`` is of the order of the driving force
``m·v0/τ = 160 N`` (80 kg, 1 m/s, 0.5 s), so a bond can hold an agent back or drag it along
but does not dominate panic pushing (``A = 2000 N`` at contact); ``D = 1 m`` saturates the
pull over about one body length; ``c = 0.5 m`` is a close-walking gap between relatives.

Everything else (equations, parameters, sub-stepping, differences from Arena's plugin) is
:mod:`arena.crowd.models.evacuation`; the bonding term is reported as ``forces["bonding"]``.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.base import CROWD_MODELS, CrowdFrame
from arena.crowd.models.evacuation.model import TERMS, Evacuation
from arena.crowd.models.evacuation.params import BondingParams

IntArray = NDArray[np.int64]


@CROWD_MODELS.register("bonding", tags=("panic",))
class Bonding(Evacuation):
    """Evacuation model plus a saturating attraction between members of the same group.

    The bonding term is our derivation after Xu & Duh (2010); see the module docstring.
    """

    Params = BondingParams

    params: BondingParams

    def __init__(self, params: BondingParams | None = None) -> None:
        super().__init__(params or self.Params())

    def _bond_pairs(self, frame: CrowdFrame) -> tuple[IntArray, IntArray]:
        """Every other member of the agent's group (group id ``≥ 0``)."""
        return group_partners(np.ascontiguousarray(frame.state.group, dtype=np.int64))

    def _bond_params(self) -> tuple[float, float, float]:
        p = self.params
        return p.bond_strength, p.bond_range, p.comfort_gap

    def _term_names(self) -> tuple[str, ...]:
        return TERMS


@njit(cache=True)
def group_partners(group: IntArray) -> tuple[IntArray, IntArray]:
    """CSR lists of the other members of each agent's group.

    Args:
        group: ``(n,)`` group ids, ``-1`` for agents walking alone.

    Returns:
        ``(indptr, indices)``: ``(n + 1,)`` and ``(m,)``; loners have no partners.
    """
    n = group.shape[0]
    order = np.argsort(group, kind="mergesort")
    # Run boundaries of equal ids in sorted order.
    start = np.zeros(n, dtype=np.int64)
    stop = np.zeros(n, dtype=np.int64)
    k = 0
    while k < n:
        e = k
        while e < n and group[order[e]] == group[order[k]]:
            e += 1
        for q in range(k, e):
            start[order[q]] = k
            stop[order[q]] = e
        k = e
    indptr = np.zeros(n + 1, dtype=np.int64)
    for i in range(n):
        indptr[i + 1] = indptr[i] + (stop[i] - start[i] - 1 if group[i] >= 0 else 0)
    indices = np.empty(indptr[n], dtype=np.int64)
    for i in range(n):
        if group[i] < 0:
            continue
        m = indptr[i]
        for q in range(start[i], stop[i]):
            j = order[q]
            if j != i:
                indices[m] = j
                m += 1
    return indptr, indices
