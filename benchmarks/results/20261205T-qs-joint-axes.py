"""The joint fit of issue 16 (done-when 3) run exactly as 20261205T-qs-joint-2profiles.py (the
cstart script: max_iter 16, no gradient check, the fit's defaults, both cores, two cantilever
specimens), with the sigma check along the covariance's principal axes, each probed further out
while the loss stays flatter than modelled, the moment band and the Voce split's reach rule (the
commit after f09056f); the benchmark also reports where the truth lies in the fit's own sds
(``truth_in_sds``). Run: python 20261205T-qs-joint-axes.py OUT.json (nothing else running)."""
import pathlib
import runpy

runpy.run_path(str(pathlib.Path(__file__).with_name("20261204T-qs-joint-cstart.py")), run_name="__main__")
