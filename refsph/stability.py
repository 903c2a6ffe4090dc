"""Settings the stability map shows unstable, and the warning a run with them gets when it starts.

``benchmarks/stability_map.py`` runs every hard case (an undamped bar, a spinning disc, two colliding rings, a
Taylor bar at twice the speed, a long pressing run) with each method at the paper's settings and with one change at
a time; ``benchmarks/stability_map_report.md`` is the map. The rules below are what it shows failing, each with the map
entries behind it (``evidence``, the map's keys case|method|setting); ``tests/test_hard_cases.py`` checks every
rule against the committed map, so a rule cannot claim more than was measured. :func:`warnings_for` gives the
messages for a run; :func:`refsph.simulate.simulate` issues them as ``UserWarning`` (they never stop a run).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

__all__ = ["Rule", "RULES", "warnings_for"]


@dataclass(frozen=True)
class Rule:
    """A setting the map shows unstable: ``applies(scene, method, numerics)``, the ``message``, the map entries that
    failed (``evidence``)."""

    name: str
    applies: Callable[[str | None, str, object], bool]
    message: str
    evidence: tuple


def _undamped_pc(scene, method, nm) -> bool:
    return nm.integrator == "predictor_corrector" and nm.beta1 == 0 and nm.beta2 == 0


RULES = (
    Rule("undamped predictor-corrector", _undamped_pc,
         "the predictor-corrector amplifies every undamped oscillation (|amplification| = sqrt(1 + (w dt)^4/4) > 1); "
         "without artificial viscosity (beta1 = beta2 = 0) the particle-scale modes grow until the run fails. Use "
         "--set integrator=leapfrog, or beta1, beta2 > 0",
         ("bar|tlsph|beta 0", "bar|esph|beta 0")),
    Rule("uncorrected ESPH on a rotating body",
         lambda scene, method, nm: method == "esph" and not nm.esph_correction and scene == "spinning_disc",
         "uncorrected ESPH (Eq. (23)) reads a rigid rotation at a free surface as a strain rate: the body builds "
         "stress and loses its spin. Use --set esph_correction=true",
         ("spinning|esph|baseline",)),
    Rule("ESPH bodies in collision without artificial pressure",
         lambda scene, method, nm: method == "esph" and nm.gamma == 0 and scene == "rings",
         "ESPH without artificial pressure (gamma = 0): the tension of a rebound clumps particles and tears the "
         "bodies (the tensile instability). Use gamma = 0.3, or TLSPH",
         ("rings|esph|gamma 0",)),
    Rule("TLSPH impact without artificial viscosity",
         lambda scene, method, nm: method == "tlsph" and nm.beta1 == 0 and nm.beta2 == 0 and
         scene in ("taylor", "pressing", "cutting"),
         "TLSPH without artificial viscosity (beta1 = beta2 = 0) under a plastic impact: the shock rings on at the "
         "particle scale until a particle inverts (J <= 0), with either time stepper. Keep beta1, beta2 > 0",
         ("taylor2x|tlsph|leapfrog + beta 0", "pressing10x|tlsph|leapfrog + beta 0", "taylor2x|tlsph|beta 0")),
)


def warnings_for(scene: str | None, method: str, numerics) -> list[str]:
    """The warnings of the rules that apply to a run of ``scene`` (None: a user's own setup) with ``method`` and
    ``numerics`` (:class:`refsph.scenes.Numerics`), each naming the map entries that failed."""
    return [f"{r.message} (stability map, benchmarks/stability_map_report.md: {', '.join(r.evidence)} failed)"
            for r in RULES if r.applies(scene, method, numerics)]
