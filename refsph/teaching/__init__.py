"""The chapters' tooling (teaching, not physics): :mod:`~refsph.teaching.notebook` (a chapter's three-line set-up),
:mod:`~refsph.teaching.book` (``refsph book``: the chapters executed and rendered), :mod:`~refsph.teaching.plots`
(particle pictures), :mod:`~refsph.teaching.material_point` (one particle under a prescribed velocity gradient, the
material-point driver of chapter 4), :mod:`~refsph.teaching.grader` (the "write it yourself" tasks' grader) and
:mod:`~refsph.teaching.handout` (``refsph handout``: the student's and the lecturer's copies). Nothing here is
re-exported: import the module you need."""
