#!/bin/bash
# Run from the repository root, both cores, one run at a time (took over from queue2.sh while its
# woven 4 mm run went on): waits for that run, then the round trip with another noise seed, then
# the NCF NLBM preset at 2 mm as shipped.
R=benchmarks/results/strain-fix-reruns-20261207
while pgrep -f "jaxform run case-a-woven-nlbm --element-size-mm 4" > /dev/null; do sleep 5; done
echo "(ended; rc not kept: its queue was replaced)" >> $R/woven-nlbm-4mm-qs.log
cp /tmp/runs/woven-nlbm-4mm/summary.json $R/woven-nlbm-4mm-qs-summary.json
start=$(date +%s)
# (ran as a copy, qs_rt.py, with the same seed argument, since folded into the original)
.venv/bin/python benchmarks/results/20261203T-qs-rt.py $R/qs-rt-seed17.json 17 > $R/qs-rt-seed17.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))" >> $R/qs-rt-seed17.log
start=$(date +%s)
.venv/bin/jaxform run case-a-ncf-nlbm --out /tmp/runs/ncf-nlbm-2mm --quiet > $R/ncf-nlbm-2mm.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))" >> $R/ncf-nlbm-2mm.log
cp /tmp/runs/ncf-nlbm-2mm/summary.json $R/ncf-nlbm-2mm-summary.json
