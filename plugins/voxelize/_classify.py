"""Octant states (white / black / grey) and the classifier interface of the voxelizer.

A classifier answers, for octants of one level given by their cell indices ``(i, j, k)`` at that
level, whether each is *black* (every voxel centre inside the body), *white* (none inside) or
*grey* (undecided: look at the children). At the finest level it must answer black or white.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import NDArray

__all__ = ["BLACK", "GREY", "WHITE", "OctantClassifier", "PriorityClassifier"]

WHITE = np.uint8(0)
BLACK = np.uint8(1)
GREY = np.uint8(2)


class OctantClassifier(Protocol):
    """Classifies octants of a cube of depth ``depth``."""

    depth: int

    def classify(
        self, level: int, i: NDArray[np.int64], j: NDArray[np.int64], k: NDArray[np.int64]
    ) -> NDArray[np.uint8]:
        """States (``WHITE``, ``BLACK``, ``GREY``) of the octants ``(i, j, k)`` at ``level``."""
        ...


class PriorityClassifier:
    """Several bodies in one octree: each voxel goes to the first body (in order) holding it.

    An octant is black for body ``b`` when the bodies before ``b`` are white there and ``b`` is
    black; grey when the first non-white body is grey; white when every body is white. At the
    finest level this is exactly "the first body whose classifier says inside".
    """

    def __init__(self, classifiers: list[OctantClassifier], depth: int) -> None:
        self.classifiers = classifiers
        self.depth = depth

    def classify_labelled(
        self, level: int, i: NDArray[np.int64], j: NDArray[np.int64], k: NDArray[np.int64]
    ) -> tuple[NDArray[np.uint8], NDArray[np.int64]]:
        """States and the index of the body owning each black octant (-1 elsewhere)."""
        if len(self.classifiers) == 1:
            only = self.classifiers[0].classify(level, i, j, k)
            return only, np.where(only == BLACK, 0, -1)
        state = np.full(i.shape[0], WHITE, dtype=np.uint8)
        body = np.full(i.shape[0], -1, dtype=np.int64)
        undecided = np.arange(i.shape[0])
        for index, classifier in enumerate(self.classifiers):
            if undecided.size == 0:
                break
            found = classifier.classify(level, i[undecided], j[undecided], k[undecided])
            claimed = found != WHITE
            target = undecided[claimed]
            state[target] = found[claimed]
            body[target] = np.where(found[claimed] == BLACK, index, -1)
            undecided = undecided[~claimed]
        return state, body
