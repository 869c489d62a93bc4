"""Round trip of bench_wrinkle_fit at the automatic (quasi-static) speed, without the gradient check
(20261203T-qs-rt.py, run as it is), with the contacts' normal forces integrated backward
(contact.implicit_normal = true: the shell's step, 35,600 steps instead of 48,000; the synthetic
truth's part formed the same way). Run: python 20261205T-qs-rt-implicit.py OUT.json (both cores).
(The run recorded in 20261205T-qs-rt-implicit.log ran a copy of that script with the override
written into it: the same program.)"""
import runpy
import sys
from pathlib import Path

here = Path(__file__).resolve().parent
sys.path.insert(0, str(here.parent))
import bench_wrinkle_fit  # noqa: E402

bench_wrinkle_fit.OVERRIDES = tuple(bench_wrinkle_fit.OVERRIDES) + ("contact.implicit_normal=true",)
runpy.run_path(str(here / "20261203T-qs-rt.py"), run_name="__main__")
