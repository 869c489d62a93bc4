#!/bin/bash
# Run from the repository root, both cores: waits for queue4.sh's NCF NLBM 4 mm run, then the same
# at half its automatic speed (31.25 -> 15.625 mm/s), then compares them (compare.py).
R=benchmarks/results/strain-fix-reruns-20261207
while ! grep -q "^rc=" $R/ncf-nlbm-4mm.log 2>/dev/null; do sleep 5; done
rm -rf /tmp/runs/ncf-nlbm-4mm-half
start=$(date +%s)
.venv/bin/jaxform run case-a-ncf-nlbm --element-size-mm 4 --set process.speed_mm_per_s=15.625 --out /tmp/runs/ncf-nlbm-4mm-half --quiet > $R/ncf-nlbm-4mm-half.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))" >> $R/ncf-nlbm-4mm-half.log
cp /tmp/runs/ncf-nlbm-4mm-half/summary.json $R/ncf-nlbm-4mm-half-summary.json
.venv/bin/python $R/compare.py /tmp/runs/ncf-nlbm-4mm /tmp/runs/ncf-nlbm-4mm-half > $R/ncf-nlbm-4mm-check.json
