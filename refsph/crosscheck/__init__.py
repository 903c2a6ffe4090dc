"""Comparing and exchanging runs with other codes (tooling, not physics): :mod:`~refsph.crosscheck.oracle` (the
rates of any state of a scene), :mod:`~refsph.crosscheck.golden` (the golden cases, ``refsph oracle DIR``),
:mod:`~refsph.crosscheck.compare` (``refsph compare REF TEST``), :mod:`~refsph.crosscheck.lammps` (LAMMPS-SMD's
output as refsph run folders) and :mod:`~refsph.crosscheck.export` (``refsph export RUN_DIR --vtk`` for ParaView).
Nothing here is re-exported: import the module you need."""
