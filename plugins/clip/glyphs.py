"""A minimal stroke font for the printable ASCII characters (geobrep's own, public domain).

Each glyph is drawn on a grid 5 units wide (x = 0..4) and 9 tall (y = 0..8): the baseline is at
y = 2, capitals and digits reach y = 8, lowercase letters y = 6, descenders y = 0. A glyph is one
or more strokes separated by ``|``; a stroke is a run of points, two digits ``xy`` each. Glyphs
advance by :data:`ADVANCE` units. Characters outside ASCII 32–126 are drawn as a box. The font
exists so that annotations can be clipped at stroke precision without a font dependency; it is
meant to be legible, not beautiful.
"""

from __future__ import annotations

from functools import cache

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "ADVANCE",
    "BASELINE",
    "CAP_HEIGHT",
    "DESCENDER",
    "GLYPHS",
    "WIDTH",
    "glyph_strokes",
    "text_strokes",
]

#: Horizontal distance between consecutive characters, in grid units.
ADVANCE = 6
#: Width of a character cell in grid units.
WIDTH = 4
#: Grid row of the baseline.
BASELINE = 2
#: Height of capitals above the baseline, in grid units (the annotation's ``height``).
CAP_HEIGHT = 6
#: Depth of descenders below the baseline, in grid units.
DESCENDER = 2

_MISSING = "0208484202"

#: Strokes of every printable ASCII character.
GLYPHS: dict[str, str] = {
    " ": "",
    "!": "2824|2322",
    '"': "1817|3837",
    "#": "1218|3238|0444|0646",
    "$": "473818070615354443321203|2821",
    "%": "0248|0708181707|3233434232",
    "&": "420607182837360403122244",
    "'": "2827",
    "(": "38272332",
    ")": "18272312",
    "*": "2327|0446|0644",
    "+": "2327|0545",
    ",": "232211",
    "-": "0545",
    ".": "2223",
    "/": "0248",
    "0": "120307183847433212|0347",
    "1": "172822|1232",
    "2": "07183847460242",
    "3": "0718384746351535|354443321203",
    "4": "3238|380444",
    "5": "480805354443321203",
    "6": "38180703123243443505",
    "7": "084822",
    "8": "150607183847463515|1504031232434435",
    "9": "12324347381807061545",
    ":": "2223|2526",
    ";": "232211|2526",
    "<": "470543",
    "=": "0444|0646",
    ">": "074503",
    "?": "0718384746352524|2322",
    "@": "44433324253646|4647381807031242",
    "A": "022842|1535",
    "B": "02083847463505|3544433202",
    "C": "4738180703123243",
    "D": "02083847433202",
    "E": "48080242|0535",
    "F": "480802|0535",
    "G": "47381807031232434525",
    "H": "0208|4248|0545",
    "I": "1838|2822|1232",
    "J": "484332120304",
    "K": "0208|4804|1542",
    "L": "080242",
    "M": "0208254842",
    "N": "02084248",
    "O": "120307183847433212",
    "P": "02083847463505",
    "Q": "120307183847433212|2442",
    "R": "02083847463505|2542",
    "S": "473818070615354443321203",
    "T": "0848|2822",
    "U": "080312324348",
    "V": "082248",
    "W": "0812253248",
    "X": "0248|0842",
    "Y": "082548|2522",
    "Z": "08480242",
    "[": "38181232",
    "\\": "0842",
    "]": "18383212",
    "^": "062846",
    "_": "0141",
    "`": "1827",
    "a": "4642|4536160503123243",
    "b": "0802|0516364543321203",
    "c": "4536160503123243",
    "d": "4842|4536160503123243",
    "e": "04444536160503123243",
    "f": "47382822|1636",
    "g": "4641301001|4536160504133344",
    "h": "0802|0516364542",
    "i": "2622|2728",
    "j": "26211000|2728",
    "k": "0802|4503|1442",
    "l": "18282332",
    "m": "0602|05162522|25364542",
    "n": "0602|0516364542",
    "o": "160503123243453616",
    "p": "0600|0516364543321203",
    "q": "4640|4536160503123243",
    "r": "0602|042646",
    "s": "45361605143443321203",
    "t": "28233242|1636",
    "u": "0603123243|4642",
    "v": "062246",
    "w": "0612253246",
    "x": "0246|0642",
    "y": "0623|4610",
    "z": "06460242",
    "{": "3828272514232232",
    "|": "2820",
    "}": "1828272534232212",
    "~": "0516253446",
}


@cache
def glyph_strokes(character: str) -> tuple[NDArray[np.float64], ...]:
    """The strokes of one character: ``(k, 2)`` arrays in grid units, baseline at y = 0.

    >>> [s.tolist() for s in glyph_strokes("L")]
    [[[0.0, 6.0], [0.0, 0.0], [4.0, 0.0]]]
    """
    code = GLYPHS.get(character, _MISSING)
    strokes = []
    for stroke in code.split("|") if code else []:
        digits = np.array([int(c) for c in stroke], dtype=np.float64).reshape(-1, 2)
        digits[:, 1] -= BASELINE
        digits.flags.writeable = False
        strokes.append(digits)
    return tuple(strokes)


def text_strokes(text: str) -> list[NDArray[np.float64]]:
    """The strokes of a string laid out along x, in grid units (character ``i`` at x = 6·i).

    >>> len(text_strokes("HI"))  # three strokes each
    6
    """
    return [
        stroke + np.array([ADVANCE * index, 0.0])
        for index, character in enumerate(text)
        for stroke in glyph_strokes(character)
    ]
