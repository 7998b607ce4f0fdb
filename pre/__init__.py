"""voiga pre-processing: exact coarse NURBS scenes, case namelists, and an
independent (splipy-based) refinement of the varying-order discretization.

Subcommands live in :mod:`pre.__main__` (``python -m pre --help``).
"""

__all__ = ["__version__"]

__version__ = "0.1.0"
