"""The joint fit of issue 16 (done-when 3) run exactly as 20261204T-qs-joint-cstart.py (max_iter 16, no
gradient check, the fit's defaults, both cores), with the benchmark as of 9b33947: two cantilever
specimens (80 and 65 mm overhang; until then one, 80 mm). Run: python 20261205T-qs-joint-2profiles.py
OUT.json (nothing else running)."""
import pathlib
import runpy

runpy.run_path(str(pathlib.Path(__file__).with_name("20261204T-qs-joint-cstart.py")), run_name="__main__")
