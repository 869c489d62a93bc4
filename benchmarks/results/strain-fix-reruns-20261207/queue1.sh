#!/bin/bash
# Run from the repository root, both cores, one run at a time: waits for the ladder, then the wrinkle-fit round trip.
R=benchmarks/results/strain-fix-reruns-20261207
while ! grep -q "^rc=" $R/ladder-lbm-inf-8mm.log 2>/dev/null; do sleep 10; done
start=$(date +%s)
.venv/bin/python benchmarks/results/20261203T-qs-rt.py $R/qs-rt.json > $R/qs-rt.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))" >> $R/qs-rt.log
