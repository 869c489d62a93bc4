"""../20261203T-qs-rt.py with the wrinkle fit's step guard off (SectionRuns' step_b_init ignored: the start's step, as
before 536105d), the springs kept: separates the guard's 1.1 % shorter step from the springs' rounding.
Run from the repository root: python qs_rt_unguarded.py OUT.json"""
import runpy
import sys
from pathlib import Path

from jaxform.calibrate import section_runs

init = section_runs.SectionRuns.__init__


def unguarded(self, *args, step_b_init=None, **kwargs):
    init(self, *args, **kwargs)


section_runs.SectionRuns.__init__ = unguarded
sys.argv = [sys.argv[0]] + sys.argv[1:]
runpy.run_path(str(Path(__file__).resolve().parents[1] / "20261203T-qs-rt.py"), run_name="__main__")
