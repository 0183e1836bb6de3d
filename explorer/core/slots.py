"""Named slots of a flat layout, each declared once with its width (and value, if it has one).

The compiled kernels read their inputs and their scratch through fixed layouts: a light's row of
parameters (:mod:`explorer.core.lightrow`), the scratch rows, option slots, constants and chunk
bounds (:mod:`explorer.shading.layout`). Each layout is one table of plain int constants, one
line per slot, each slot taking the next offset::

    _rows = Slots()
    R_PX = _rows.slot()  # positions, x
    R_TWO = _rows.slot(3)  # a slot three wide
    N_ROWS = _rows.count

so that no offset, count or value list is written twice: numba freezes plain module ints into
the compiled code (a name read at compile time), and every user imports the same names.
"""

from __future__ import annotations


class Slots:
    """The offsets of one layout, handed out in order (see the module docstring)."""

    def __init__(self) -> None:
        self.count = 0  #: slots so far: the layout's length once every slot is declared
        self.values: list[float] = []  #: each slot's value, when the layout has values

    def slot(self, width: int = 1) -> int:
        """The offset of a slot ``width`` wide, after those declared before it."""
        if width < 1:
            raise ValueError(f"a slot is at least 1 wide, got {width}")
        at = self.count
        self.count += width
        return at

    def value(self, v: float) -> int:
        """The offset of a one-wide slot holding ``v`` (:attr:`values`: every slot's, in
        order; a layout declares all its slots this way or none)."""
        if len(self.values) != self.count:
            raise ValueError("a layout with values gives every slot one")
        self.values.append(v)
        return self.slot()
