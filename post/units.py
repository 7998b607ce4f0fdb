"""Units of a result file, for axis labels.

voiga works in any consistent units; the result file's root attribute ``units``
(``docs/hdf5.md``) says which. When it names a length and a force, ``"mm, N"``,
the labels use them; otherwise (e.g. ``"consistent (...)"``, free text) they read
``length`` and ``force``. In 2D plane strain every force is per unit thickness:
reactions and contact forces are force/length, contact pressure, tractions and
stresses force/length^2; a solid's (3D) reactions are forces.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_PAIR = re.compile(r"^\s*([A-Za-z\u00b5]+)\s*,\s*([A-Za-z]+)\s*$")


@dataclass(frozen=True)
class Units:
    """A length unit and a force unit, and the derived labels."""

    length: str = "length"
    force: str = "force"

    @classmethod
    def parse(cls, text: str | None) -> Units:
        """Units from a ``units`` attribute: ``"<length>, <force>"`` (e.g. ``"mm, N"``);
        anything else gives the generic ``length`` / ``force``."""
        m = _PAIR.match(text or "")
        return cls(m.group(1), m.group(2)) if m else cls()

    @property
    def known(self) -> bool:
        """True when the file named its units."""
        return self != Units()

    @property
    def line_force(self) -> str:
        """Force per unit thickness (reactions, contact forces, P)."""
        return f"{self.force}/{self.length}"

    def resultant(self, dimension: int) -> str:
        """The unit of a resultant force (a reaction) of a result file of spatial
        ``dimension``: force per unit thickness in 2D, force in 3D."""
        return self.line_force if dimension == 2 else self.force

    @property
    def pressure(self) -> str:
        """Force per area (contact pressure, tractions, stresses)."""
        return f"{self.force}/{self.length}^2"

    def __str__(self) -> str:
        return f"{self.length}, {self.force}"
