"""Scenes as data (after pyro2's ``problems/``): one module per scene, each defining ``SCENE``, a
:class:`~refsph.scenes.base.Scene` with its geometry, material, numerics, what to record and which metrics to
report. The registry :data:`SCENES` is what ``refsph list`` prints.

* :mod:`.base` -- :class:`Numerics`, :class:`Setup`, :class:`Scene` and option parsing;
* :mod:`.measure` -- what the scenes share: lattices, the Table 3 material, time averages, energies, momentum;
* :mod:`.bar`, :mod:`.tension` -- elastic test cases; :mod:`.spinning_disc`, :mod:`.rings` -- hard cases
  (objectivity; contact and fracture); :mod:`.taylor`, :mod:`.pressing`, :mod:`.cutting` -- the
  paper's three benchmarks (Sections 3.1-3.3); :mod:`.thermal_cutting` -- the second paper's 18 measured cuts;
  :mod:`.contact_checks` -- contact checks with closed-form answers (issue 22).
"""
from __future__ import annotations

from . import bar, cutting, pressing, rings, spinning_disc, taylor, tension, thermal_cutting
from .base import Numerics, Scene, Setup, convert_options, parse_bool
from .measure import (aisi4340_johnson_cook, aisi4340_material, block_lattice, elastic_energy, kinetic_energy,
                      lattice, linear_momentum, min_pair_distance)

__all__ = ["Numerics", "Setup", "Scene", "SCENES", "get_scene", "convert_options", "parse_bool", "lattice",
           "block_lattice", "aisi4340_material", "aisi4340_johnson_cook", "kinetic_energy", "elastic_energy",
           "linear_momentum", "min_pair_distance"]

SCENES: dict[str, Scene] = {m.SCENE.name: m.SCENE for m in (bar, tension, spinning_disc, rings, taylor,
                                                              pressing, cutting, thermal_cutting)}


def get_scene(name: str) -> Scene:
    """The registered scene ``name`` (ValueError listing the scenes otherwise)."""
    try:
        return SCENES[name]
    except KeyError:
        raise ValueError(f"unknown scene {name!r}; available: {', '.join(sorted(SCENES))}") from None
