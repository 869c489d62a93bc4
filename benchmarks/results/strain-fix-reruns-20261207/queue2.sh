#!/bin/bash
# Run from the repository root, both cores, one run at a time: waits for the round trip, then woven
# NLBM at 4 mm with its half-speed check, then the NCF NLBM preset at 2 mm as shipped.
R=benchmarks/results/strain-fix-reruns-20261207
while ! grep -q "^rc=" $R/qs-rt.log 2>/dev/null; do sleep 10; done
mkdir -p /tmp/runs; rm -rf /tmp/runs/woven-nlbm-4mm /tmp/runs/ncf-nlbm-2mm
start=$(date +%s)
.venv/bin/jaxform run case-a-woven-nlbm --element-size-mm 4 --verify-quasi-static --out /tmp/runs/woven-nlbm-4mm > $R/woven-nlbm-4mm-qs.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))" >> $R/woven-nlbm-4mm-qs.log
cp /tmp/runs/woven-nlbm-4mm/summary.json $R/woven-nlbm-4mm-qs-summary.json
start=$(date +%s)
.venv/bin/jaxform run case-a-ncf-nlbm --out /tmp/runs/ncf-nlbm-2mm --quiet > $R/ncf-nlbm-2mm.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))" >> $R/ncf-nlbm-2mm.log
cp /tmp/runs/ncf-nlbm-2mm/summary.json $R/ncf-nlbm-2mm-summary.json
