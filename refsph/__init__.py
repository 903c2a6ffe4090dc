"""refsph: a literate reference implementation of Eulerian and Total Lagrangian SPH for metal machining
(Islam, Bansal & Peng). Pure NumPy/SciPy, SI units, one module per piece of the paper's method."""
__version__ = "0.1.0"

from .io import load_reactions, load_run, load_snapshot  # noqa: E402,F401
