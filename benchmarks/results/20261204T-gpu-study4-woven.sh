#!/bin/bash
# The device run after common_form (966992a): the paper study's woven Case A NLBM and three LBM
# runs at 4 mm, automatic quasi-static speed (62.5 mm/s), as ONE batched program on one NVIDIA H200
# (jax 0.11.2 with CUDA; wheels in .whl/), at most T s; then measured (--analyse-only; claim 9's
# standard tests carried in .gpu/standard_test.json). Run: bash THIS OUTDIR [T]
set -u
O=$1; T=${2:-150}; mkdir -p "$O"
export PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=/tmp/site:$PWD
W=/tmp/s; rm -rf $W; mkdir -p $W/study; cp .gpu/standard_test.json $W/study/
start=$(date +%s)
timeout -k 10 "$T" python3 -m jaxform study paper --out $W/study --element-size-mm 4 --only case-a-woven \
  --bending nlbm,lbm-init,lbm-41,lbm-inf --force > $W/run.log 2>&1; echo "rc=$? wall=$(( $(date +%s) - start )) s" >> $W/run.log
timeout 40 python3 -m jaxform study paper --out $W/study --element-size-mm 4 --only case-a-woven \
  --bending nlbm,lbm-init,lbm-41,lbm-inf --analyse-only > $W/analyse.log 2>&1; echo "rc=$? wall=$(( $(date +%s) - start )) s" >> $W/analyse.log
grep -v "it/s\]" $W/run.log | tail -n 14; tail -n 3 $W/analyse.log
cp $W/run.log $W/analyse.log "$O/"
tar czf "$O/study.tgz" -C $W --exclude='frames_*.vtu' --exclude='frames.pvd' study
