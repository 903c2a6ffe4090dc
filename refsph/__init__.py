"""refsph: a literate reference implementation of Eulerian and Total Lagrangian SPH for metal machining
(Islam, Bansal & Peng). Pure NumPy/SciPy, SI units, one module per piece of the paper's method.

The public path for a case of one's own (README, "Your own scene"): particles from :func:`refsph.state.make_state`,
a :class:`refsph.scenes.Setup` (material, strength model, boundaries from :mod:`refsph.boundaries`, numerics),
then :func:`refsph.simulate.simulate`; the output is read back with :func:`load_run`, :func:`load_snapshot` and
:func:`load_reactions`."""
__version__ = "0.1.0"

from .io import load_reactions, load_run, load_snapshot  # noqa: E402,F401
