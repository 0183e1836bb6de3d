"""How the suite's tests are shared between pytest-xdist's worker processes (pyproject.toml's
addopts run two, ``-n 2``: the developers' guide's 2 cores; ``-n 0`` runs every test in the
pytest process). tests/conftest.py's ``pytest_xdist_make_scheduler`` hands out
:class:`ModuleScheduling`'s units; this module imports xdist, so only a run with workers
imports it.
"""

from __future__ import annotations

from xdist.scheduler import LoadScopeScheduling

from helpers.imagecompare import is_golden_test_name

#: the one unit of every module that holds a golden test, and tests/test_goldens.py
GOLDENS = "the modules of the golden tests, with tests/test_goldens.py"


class ModuleScheduling(LoadScopeScheduling):
    """Whole test modules to the workers, in the order of the collection (tests/conftest.py's):
    a worker asks for the next module when it has two tests or fewer left, so each worker runs
    its modules in that order, the modules of ``BEFORE_KERNELS`` first and those of tests/app/qt
    last (they change the process's VTK, tests/app/conftest.py), and a module's fixtures (its
    page server and browser, its off-screen window) are made once, in one worker.

    Every module that holds a golden test goes, with tests/test_goldens.py, to one worker as
    one unit (at the place of the first of them): test_golden_files_all_used, last of the unit,
    reads which goldens the tests of its own process used (tests/helpers/imagecompare.py)."""

    def __init__(self, config, log=None):
        super().__init__(config, log)
        # the units in the collection's order (xdist's loadscope sorts them biggest first)
        config.option.loadscopereorder = False
        #: the modules (their paths in the node ids) of the golden unit, once collected
        self._golden: set[str] | None = None

    def _split_scope(self, nodeid: str) -> str:
        """The unit of test ``nodeid``: its module's path, or :data:`GOLDENS`."""
        module = nodeid.split("::", 1)[0]
        if self._golden is None and self.collection is not None:
            self._golden = {
                n.split("::", 1)[0]
                for n in self.collection
                if is_golden_test_name(n.rsplit("::", 1)[-1])
            }
        return GOLDENS if module in (self._golden or ()) else module
