"""The grader of the chapters' "write it yourself" tasks: a student's function against the package's, on cases chosen
to catch the usual mistakes, with a message that says what went wrong where.

    from refsph.teaching.grader import case, check
    report = check(my_kernel, reference, [case(xij, 1e-5, 2, label="2D, h = 10 um"), ...], names=("W", "grad W"))

:func:`check` calls ``student(*args, **kwargs)`` and ``reference(*args, **kwargs)`` for every case (NumPy arrays among
the arguments are copied for each call, so a function that writes into its input spoils nothing) and compares what
they return: one array or number, or a tuple of them (``names`` names them in the messages), element by element:

    |got - expected| <= rtol |expected| + atol,   atol = rtol max|expected| of that output unless given,

so an output's zeros are compared at the output's own scale; booleans and integers must be equal; a shape or a number
of outputs that differs, or a NaN where a number is expected, fails. It never raises for a wrong answer: a notebook
that grades keeps running. It prints ``PASS`` with the number of cases and the tolerance, or ``FAIL`` with the first
case that went wrong (its label), the output and element, the value got and the value expected, the difference and
what was allowed; a stub that still raises ``NotImplementedError`` is "not written yet", any other exception is shown
with the case that raised it. It returns a :class:`Report`, true when every case passed (``assert check(...)`` in a
worked solution; ``assert not check(...)`` for a mistake the grader must catch).

An exception from the *reference* is a broken case, not the student's fault: it is raised.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

__all__ = ["Case", "Report", "case", "check"]


@dataclass(frozen=True)
class Case:
    """The arguments of one call, and a label that says what the case probes."""
    args: tuple
    kwargs: dict
    label: str | None = None


def case(*args, label: str | None = None, **kwargs) -> Case:
    """One case of :func:`check`: the positional and keyword arguments of the call; ``label``: what it probes."""
    return Case(args, kwargs, label)


@dataclass
class Report:
    """What :func:`check` found: ``passed`` (also the report's truth value), cases passed out of ``n_cases``, and
    the ``message`` it printed."""
    name: str
    passed: bool
    n_passed: int
    n_cases: int
    message: str

    def __bool__(self) -> bool:
        return self.passed

    def __repr__(self) -> str:
        return f"Report({self.name!r}: {'PASS' if self.passed else 'FAIL'}, {self.n_passed}/{self.n_cases} cases)"


def _as_case(c) -> Case:
    if isinstance(c, Case):
        return c
    if isinstance(c, dict):
        return Case((), dict(c))
    return Case(tuple(c) if isinstance(c, (tuple, list)) else (c,), {})


def _fresh(a):
    return a.copy() if isinstance(a, np.ndarray) else a


def _short(a) -> str:
    if isinstance(a, np.ndarray):
        return f"array{a.shape}" if a.size > 4 else np.array2string(a, precision=3, separator=", ")
    if isinstance(a, float):
        return f"{a:.4g}"
    if isinstance(a, (int, bool, str, type(None))):
        return repr(a)
    return type(a).__name__


def _describe(k: int, c: Case) -> str:
    if c.label:
        return f"case {k} ({c.label})"
    parts = [_short(a) for a in c.args] + [f"{key}={_short(v)}" for key, v in c.kwargs.items()]
    return f"case {k} ({', '.join(parts)})"


def _outputs(value) -> list:
    return list(value) if isinstance(value, (tuple, list)) else [value]


def _compare(got, exp, rtol: float, atol: float | None):
    """None if ``got`` matches ``exp``, else a sentence on the first mismatch."""
    if got is None and exp is not None:
        return "got None (no value returned: a missing `return`?)"
    try:
        g = np.asarray(got)
        e = np.asarray(exp)
    except Exception as err:                                # noqa: BLE001 -- anything a student may return
        return f"got a {type(got).__name__} that is not an array ({err})"
    if g.dtype.kind not in "biuf":
        return f"got a {type(got).__name__} ({_short(got)}) that is not an array of numbers"
    if g.shape != e.shape:
        return f"shape {g.shape}, expected {e.shape}"
    if e.dtype == bool or np.issubdtype(e.dtype, np.integer):
        bad = g != e
        if not bad.any():
            return None
        idx = np.unravel_index(int(np.argmax(bad)), e.shape) if e.shape else ()
        return f"element {tuple(int(i) for i in idx)}: got {g[idx]!r}, expected {e[idx]!r} (must be equal)"
    g = g.astype(float)
    e = e.astype(float)
    scale = float(np.max(np.abs(e[np.isfinite(e)]))) if np.isfinite(e).any() else 0.0
    floor = rtol * scale if atol is None else atol
    with np.errstate(invalid="ignore", over="ignore"):
        diff = np.abs(g - e)
        allowed = rtol * np.abs(e) + floor
        ok = (diff <= allowed) | (np.isnan(e) & np.isnan(g)) | (np.isinf(e) & (g == e))
    if ok.all():
        return None
    n_bad = int(np.count_nonzero(~ok))
    idx = np.unravel_index(int(np.argmax(~ok)), e.shape) if e.shape else ()
    where = f"element {tuple(int(i) for i in idx)}: " if e.shape else ""
    gv, ev = float(g[idx]) + 0.0, float(e[idx]) + 0.0                  # + 0.0: no '-0' in a message
    count = f"{n_bad} of {e.size} element{'s' if e.size > 1 else ''} differ{'s' if n_bad == 1 else ''}"
    if not np.isfinite(gv):
        return f"{where}got {gv} where {ev:.6g} is expected (a division by zero?); {count}"
    return (f"{where}got {gv:.6g}, expected {ev:.6g}: differs by {abs(gv - ev):.2g}, "
            f"allowed {float(allowed[idx]):.2g}; {count}")


def check(student: Callable, reference: Callable, cases: Sequence, *, rtol: float = 1e-10,
          atol: float | None = None, names: Sequence[str] | None = None, name: str | None = None,
          quiet: bool = False) -> Report:
    """Call ``student`` and ``reference`` on every case and compare what they return (module text).

    cases: :func:`case` objects, or tuples of positional arguments, or dicts of keyword arguments. rtol, atol: the
    tolerance (module text). names: the names of the outputs, for the messages. name: what is graded (default: the
    student function's name). quiet: do not print the message (it is in the report). Returns a :class:`Report`."""
    name = name or getattr(student, "__name__", "your function")
    cases = [_as_case(c) for c in cases]
    floor = f"{atol:.0e}" if atol is not None else f"{rtol:.0e} x each output's largest |value|"
    tol = f"rtol = {rtol:.0e}, atol = {floor}"
    n_passed, failure, written = 0, None, True
    for k, c in enumerate(cases, 1):
        expected = reference(*[_fresh(a) for a in c.args], **{key: _fresh(v) for key, v in c.kwargs.items()})
        try:
            with np.errstate(all="ignore"):
                got = student(*[_fresh(a) for a in c.args], **{key: _fresh(v) for key, v in c.kwargs.items()})
        except NotImplementedError as err:
            failure = (f"not written yet ({type(err).__name__}{': ' + str(err) if str(err) else ''}). Replace the "
                       "`raise` by your code and run the cell again.")
            written = False
            break
        except Exception as err:                            # noqa: BLE001 -- a student's bug is reported, not raised
            failure = f"{_describe(k, c)} raised {type(err).__name__}: {err}"
            break
        exp_out, got_out = _outputs(expected), _outputs(got)
        labels = list(names) if names is not None else [f"output {i + 1}" for i in range(len(exp_out))]
        if len(got_out) != len(exp_out):
            failure = (f"{_describe(k, c)}: returned {len(got_out)} value{'s' if len(got_out) != 1 else ''}, "
                       f"expected {len(exp_out)} ({', '.join(labels)})")
            break
        for label, g, e in zip(labels, got_out, exp_out):
            why = _compare(g, e, rtol, atol)
            if why is not None:
                failure = f"{_describe(k, c)}, {label if len(exp_out) > 1 or names else 'the result'}: {why}"
                break
        if failure:
            break
        n_passed += 1
    if failure is None:
        message = f"PASS  {name}: all {len(cases)} cases agree with the package ({tol})."
    elif not written:
        message = f"FAIL  {name}: {failure}"
    else:
        message = (f"FAIL  {name}: {failure}\n      {n_passed} of {len(cases)} cases passed before it; "
                   f"tolerance: {tol}.")
    if not quiet:
        print(message)
    return Report(name=name, passed=failure is None, n_passed=n_passed, n_cases=len(cases), message=message)
