"""The default test run uses pytest-xdist with two workers (pyproject.toml: ``-n 2``; the CI machine has two
cores). Each worker is pinned to a core of its own and its libraries to one thread, so the two share the machine
without oversubscription: refsph's pair sums see one available core (:func:`refsph.neighbours.available_cores` reads
the affinity mask), BLAS and OpenMP run one thread, and a chapter's kernel (tests/test_chapters.py) inherits the
worker's core, so its wall time is a student's one-core run.

The tests of a module that defines a module-scoped fixture (the quick runs of tests/test_taylor.py,
test_pressing.py, test_cutting.py, the regenerated golden cases of test_golden.py, ...) all go to one worker
(:class:`ModuleFixtureScheduling`), so that fixture runs once per session instead of once on each worker that
happens to get one of its tests; every other test is scheduled on its own. (xdist's ``--dist loadgroup`` with
``xdist_group`` marks would say the same per test, but pytest-xdist 3.8 cannot rename the node ids of pytest 9.2, so
its groups are ignored there.) With ``-n 0`` (one process, no workers) nothing is pinned."""
import functools
import os
from pathlib import Path

import pytest

WORKER = os.environ.get("PYTEST_XDIST_WORKER")          # gw0, gw1, ... in an xdist worker, else None
if WORKER is not None:
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):    # before NumPy is imported
        os.environ[var] = "1"
    if hasattr(os, "sched_getaffinity"):
        cores = sorted(os.sched_getaffinity(0))
        if len(cores) >= int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1")):
            os.sched_setaffinity(0, {cores[int(WORKER.removeprefix("gw")) % len(cores)]})


@functools.lru_cache(maxsize=None)
def shares_a_module_fixture(path: Path) -> bool:
    """Whether the test module at ``path`` defines a module-scoped fixture."""
    try:
        return 'scope="module"' in path.read_text()
    except OSError:
        return False


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    from xdist.scheduler import LoadScopeScheduling

    class ModuleFixtureScheduling(LoadScopeScheduling):
        """Load scheduling in which a scope is a whole module where the module shares a module-scoped fixture,
        else a single test."""

        def _split_scope(self, nodeid: str) -> str:
            module = nodeid.split("::", 1)[0]
            return module if shares_a_module_fixture(config.rootpath / module) else nodeid

    return ModuleFixtureScheduling(config, log)
