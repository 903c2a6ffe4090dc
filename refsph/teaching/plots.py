"""Plots of particle fields, kept apart from the physics (used by the chapters and the benchmark scripts), and
the size rule that makes every chapter's figure fit a slide.

Only matplotlib's object interface is used: every function draws on an ``Axes`` it is given. Fields use a
perceptual colour map (viridis by default) with a labelled colour bar (:func:`colorbar`).

**Figures for slides: the size rule.** A figure is drawn at the size it is shown at on a 16:9 slide (13.3 x 7.5
in), not scaled down afterwards: **at most 10 in wide and 6.5 in tall** (it fills a slide under its title), and
**every text in it at least 14 pt at that size** (titles, axis labels, tick labels, legends, colour-bar labels,
annotations): about 1/40 of the slide's height, readable from the back of a lecture hall. :data:`SLIDE`
holds the numbers; :func:`slide_style` is the matplotlib style that applies them (14 pt text, a default size
of 8 x 4.5 in, saved figures cropped to what is drawn, so that no label is clipped), and every chapter gets it
from its set-up (:func:`refsph.teaching.notebook.chapter`). A chapter keeps to the rule by choosing its
``figsize`` (at most 10 x 6.5) and no smaller ``fontsize``; :func:`slide_problems` measures a drawn figure against
it, and the tests apply it to every figure the chapters show (``tests/test_figures.py``). In the book a figure is
at most 10 in wide too (1000 px at 100 dpi: the page's width).
"""
from __future__ import annotations

import numpy as np

__all__ = ["particle_field", "colorbar", "SLIDE", "slide_style", "slide_problems"]

SLIDE = {"max_width_in": 10.0, "max_height_in": 6.5, "min_font_pt": 14.0}   # the size rule (module docstring)


def slide_style() -> dict:
    """The rcParams of the size rule: every text 14 pt (figure titles 16), a default figure of 8 x 4.5 in at
    100 dpi, lines 1.8 pt, saved figures cropped to what is drawn (``savefig.bbox = tight``: a label that sticks
    out is kept, not clipped). ``matplotlib.rcParams.update(slide_style())`` applies it."""
    pt = SLIDE["min_font_pt"]
    return {"font.size": pt, "axes.titlesize": pt, "axes.labelsize": pt, "xtick.labelsize": pt,
            "ytick.labelsize": pt, "legend.fontsize": pt, "legend.title_fontsize": pt, "figure.titlesize": pt + 2,
            "figure.labelsize": pt, "figure.figsize": (8.0, 4.5), "figure.dpi": 100, "lines.linewidth": 1.8,
            "savefig.bbox": "tight", "savefig.pad_inches": 0.05, "legend.framealpha": 0.85}


def slide_problems(fig) -> list[str]:
    """How a drawn matplotlib figure breaks the size rule (:data:`SLIDE`): its extent as saved (cropped to what
    is drawn) wider or taller than allowed, or visible text smaller than allowed; empty when it fits a slide."""
    from matplotlib.text import Text

    renderer = fig.canvas.get_renderer()
    box = fig.get_tightbbox(renderer)                      # in inches
    problems = []
    if box.width > SLIDE["max_width_in"] + 0.05:
        problems.append(f"{box.width:.1f} in wide (at most {SLIDE['max_width_in']:g})")
    if box.height > SLIDE["max_height_in"] + 0.05:
        problems.append(f"{box.height:.1f} in tall (at most {SLIDE['max_height_in']:g})")
    small = sorted({(t.get_fontsize(), t.get_text()) for t in fig.findobj(Text)
                    if t.get_visible() and t.get_text().strip() and t.get_fontsize() < SLIDE["min_font_pt"] - 0.01})
    if small:
        problems.append(f"text of {small[0][0]:g} pt (at least {SLIDE['min_font_pt']:g}): "
                        + ", ".join(repr(text[:30]) for _, text in small[:3]))
    return problems


def particle_field(ax, x: np.ndarray, value: np.ndarray, dp: float, *, body: np.ndarray | None = None,
                   xlim=None, ylim=None, scale: float = 1e3, cmap: str = "viridis", vmin=None, vmax=None,
                   rigid_color: str = "0.6", spread: float = 1.5, fill: float | None = 2.5):
    """2D particles as squares ``spread`` spacings ``dp`` wide (1.5: a deformed, stretched continuum still looks
    like one, with no white gaps between particles), coloured by ``value``; particles with ``body > 0`` (rigid
    tools) in grey. Coordinates are multiplied by ``scale`` (default: metres to mm); ``xlim``, ``ylim`` in those
    units (default: the particles' extent plus one spacing; the marker size is set from them). Higher values are drawn
    last, so thin bands of high value stay visible. ``fill``: an underlay of squares that many spacings wide in
    the same colours, drawn first, so that where the material has opened up (a chip stretched to several spacings
    between particles) no white speckles show (None: no underlay). Returns the scatter of the deformable particles
    (for :func:`colorbar`)."""
    x = np.asarray(x) * scale
    deform = np.ones(len(x), dtype=bool) if body is None else np.asarray(body) == 0
    ax.set_aspect("equal")
    pad = dp * scale                                        # no limits given: the particles' extent + one spacing
    ax.set_xlim(*(xlim if xlim is not None else (x[:, 0].min() - pad, x[:, 0].max() + pad)))
    ax.set_ylim(*(ylim if ylim is not None else (x[:, 1].min() - pad, x[:, 1].max() + pad)))
    ax.apply_aspect()
    x0, x1 = ax.get_xlim()
    fig = ax.get_figure()
    pt_per_unit = ax.get_position().width * fig.get_figwidth() * 72 / (x1 - x0)
    size = (spread * pt_per_unit * dp * scale) ** 2         # marker area [pt^2]
    if not deform.all():
        ax.scatter(x[~deform, 0], x[~deform, 1], c=rigid_color, s=size, lw=0, marker="s")
    v = np.asarray(value)[deform]
    order = np.argsort(v, kind="stable")
    if fill is not None:
        ax.scatter(x[deform][order, 0], x[deform][order, 1], c=v[order], s=(fill / spread) ** 2 * size, lw=0,
                   marker="s", cmap=cmap, vmin=vmin, vmax=vmax)
    return ax.scatter(x[deform][order, 0], x[deform][order, 1], c=v[order], s=size, lw=0, marker="s", cmap=cmap,
                      vmin=vmin, vmax=vmax)


def colorbar(fig, mappable, ax, label: str, **kwargs):
    """A colour bar beside ``ax`` with its quantity and unit as ``label`` (e.g. "effective plastic strain [-]")."""
    cb = fig.colorbar(mappable, ax=ax, **kwargs)
    cb.set_label(label)
    return cb


# ------------------------------------------------------------------------------------------------------------------
# Benchmark maps (chapters 10 and 11, issue 25): figures drawn from the benchmarks' committed JSON records, shared by
# the chapters and the benchmark scripts (benchmarks/stability_map.py, benchmarks/thermal_cutting.py).
# ------------------------------------------------------------------------------------------------------------------

__all__ += ["stability_map", "measured_cuts", "cut_record", "CUT_SERIES"]


def stability_map(axes, runs: dict, cases=None, variants: dict | None = None) -> None:
    """The stability map of ``benchmarks/stability_map.py`` on one Axes per method (``axes``, ESPH then TLSPH): a
    row per setting, a column per hard case, 'yes' (blue) where the run survived, 'NO' (orange) where it failed,
    blank where it has no verdict. ``runs``: the JSON's records ({"case|method|setting": {"survived": ...}});
    ``cases`` and ``variants`` ({method: [settings]}): default, in the order the records list them."""
    from matplotlib.colors import ListedColormap

    keys = [k.split("|") for k, r in runs.items() if "survived" in r]
    cases = list(cases) if cases is not None else list(dict.fromkeys(c for c, _, _ in keys))
    if variants is None:
        variants = {}
        for _, m, v in keys:
            variants.setdefault(m, [])
            if v not in variants[m]:
                variants[m].append(v)
    colours = ListedColormap(["#f4a582", "#92c5de"])                     # failed, survived (colour-blind safe)
    for ax, (method, vs) in zip(np.atleast_1d(axes), variants.items()):
        grid = np.full((len(vs), len(cases)), np.nan)
        for i, v in enumerate(vs):
            for j, c in enumerate(cases):
                r = runs.get(f"{c}|{method}|{v}")
                if r is not None and "survived" in r:
                    grid[i, j] = float(r["survived"])
                    ax.text(j, i, "yes" if r["survived"] else "NO", ha="center", va="center",
                            weight="normal" if r["survived"] else "bold")
        ax.imshow(grid, cmap=colours, vmin=0, vmax=1, aspect="auto")
        ax.set_xticks(range(len(cases)), cases)
        ax.set_yticks(range(len(vs)), vs)
        ax.set_xticks(np.arange(len(cases) + 1) - 0.5, minor=True)
        ax.set_yticks(np.arange(len(vs) + 1) - 0.5, minor=True)
        ax.grid(which="minor", color="white", lw=2)
        ax.tick_params(which="minor", length=0)
        ax.set_title(f"{method.upper()}: did the run survive?")


# (label, record key suffix, marker, colour) of refsph's series in :func:`measured_cuts`
CUT_SERIES = (("refsph SPH, t_u/5", " n_tu 5", "o", "C0"), ("refsph SPH, t_u/10", "", "D", "C1"),
              ("refsph PFEM, t_u/5", " pfem n_tu 5", "P", "C2"), ("refsph PFEM, t_u/10", " pfem", "X", "C2"))
# a series' case that failed, run again under 'case N' + suffix + one of these (the sweep's retries, in the order it
# takes them: benchmarks/thermal_cutting.py's RETRIES): SPH at a quarter of the step, the PFEM with damped rules
CUT_RETRIES = {"": (" courant 0.075",), " pfem": (" n_tu 10 bossak -0.1", " n_tu 10 gamma 0.6"),
               " ref update 0.1 frequency step 0.5": (" courant 0.15",)}
# a series' case made again by a later version of the solver, under 'case N' + suffix + one of these: taken before
# the record itself where it ended well (benchmarks/thermal_cutting.py's REDONE; the PFEM's cuts that an earlier
# contact made, again with today's)
CUT_REDONE = {" pfem": (" rerun",), " pfem n_tu 5": (" rerun",)}


def cut_record(runs: dict, key: str, retries=(), redone=()) -> tuple[str, dict | None]:
    """(key, record) that the sweep's tables and :func:`measured_cuts` take for ``key``: its run made again by a later
    solver, ``key + suffix`` (``redone``: the suffixes, in order), where one is recorded 'ok'; where that run failed,
    the first retry below recorded 'ok', else the record itself; else the run itself (None if not recorded), or
    where it failed, its first retry ``key + suffix`` (``retries``: the suffixes, in order) recorded 'ok', else the
    failed run."""
    again = next(((key + t, runs[key + t]) for t in redone if runs.get(key + t, {}).get("status") == "ok"), None)
    if again is not None:
        return again
    r = runs.get(key)
    retry = next(((key + t, runs[key + t]) for t in retries if runs.get(key + t, {}).get("status") == "ok"), (key, r))
    if any(runs.get(key + t, {}).get("status", "ok") != "ok" for t in redone):
        return retry      # made again by today's solver and failed: its retry where one ended well, else the record
    if r is None or r.get("status") == "ok":
        return key, r
    return retry


def measured_cuts(axes, runs: dict, series=CUT_SERIES, retries: dict | None = None) -> dict:
    """The 18 measured cuts of Rodriguez Prieto, Larsson & Afrasiabi (2023) against refsph and the paper, case by case,
    on three Axes: the rake-face temperature, the free chip surface temperature and the force ratio Fp/Fc. The
    measurement is a black bar, the paper's SPH and PFEM grey open squares and triangles, refsph's runs (``runs``:
    the records of ``benchmarks/thermal_cutting.json``, ``'case N' + suffix`` for each of ``series``) filled
    markers, only where a run is recorded and ended well; where it failed, its first retry that did (``retries``:
    {series suffix: the retries' key suffixes}, default :data:`CUT_RETRIES`); where a later solver made it again
    (:data:`CUT_REDONE`), that run. Returns {series label: the cases drawn}."""
    from ..paper_data import rla_cutting_case

    quantities = (("TRF", "rake_face_temperature_K", "T$_{RF}$ [K]"),
                  ("TFCS", "free_chip_surface_temperature_K", "T$_{FCS}$ [K]"), ("ratio", "force_ratio", "Fp / Fc"))
    paper = [rla_cutting_case(n) for n in range(1, 19)]
    drawn = {label: [] for label, *_ in series}
    retries = CUT_RETRIES if retries is None else retries

    def record(m: int, suffix: str):
        return cut_record(runs, f"case {m}{suffix}", retries.get(suffix, ()), CUT_REDONE.get(suffix, ()))[1]
    for k, (ax, (q, key, ylabel)) in enumerate(zip(axes, quantities)):
        def value(c, src):
            return c[f"Fp_{src}_N"] / c[f"Fc_{src}_N"] if q == "ratio" else c[f"{q}_{src}_K"]
        n = np.arange(1, 19)
        ax.hlines([value(c, "exp") for c in paper], n - 0.42, n + 0.42, color="k", lw=3,
                  label="measured" if k == 0 else None)
        for dx, src, mk, lab in ((-0.28, "sph", "s", "paper SPH"), (-0.14, "pfem", "^", "paper PFEM")):
            ax.plot(n + dx, [value(c, src) for c in paper], mk, mfc="none", color="0.45", ms=7,
                    label=lab if k == 0 else None)
        for j, (label, suffix, mk, col) in enumerate(series):
            pts = [(m, r["metrics"][key]) for m in range(1, 19) for r in [record(m, suffix)]
                   if r is not None and r.get("status") == "ok" and r.get("metrics", {}).get(key) is not None]
            if pts:
                p = np.array(pts, dtype=float)
                ax.plot(p[:, 0] + 0.14 * (1 + j % 2), p[:, 1], mk, color=col, ms=8, label=label if k == 0 else None)
                if k == 0:
                    drawn[label] = [int(m) for m in p[:, 0]]
        ax.axvline(9.5, color="0.6", lw=1)
        ax.set_ylabel(ylabel)
        ax.set_xlim(0.4, 18.6)
    axes[0].text(0.25, 1.02, "AISI 1045", transform=axes[0].transAxes, ha="center", va="bottom")
    axes[0].text(0.75, 1.02, "Ti6Al4V", transform=axes[0].transAxes, ha="center", va="bottom")
    axes[-1].set_xticks(np.arange(1, 19))
    axes[-1].set_xlabel("case (Appendix B: v_c rises every three cases, t_u within each three)")
    return drawn
