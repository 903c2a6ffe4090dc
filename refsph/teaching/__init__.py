"""The chapters' tooling (teaching, not physics): :mod:`~refsph.teaching.notebook` (a chapter's three-line set-up),
:mod:`~refsph.teaching.book` (``refsph book``: the chapters executed and rendered), :mod:`~refsph.teaching.plots`
(particle pictures) and :mod:`~refsph.teaching.material_point` (one particle under a prescribed velocity gradient,
the material-point driver of chapter 4). Nothing here is re-exported: import the module you need."""
