#!/bin/bash
while ! grep -q "^rc=" /tmp/v/new-w2-check.log 2>/dev/null; do sleep 10; done
cd /work/main
start=$(date +%s)
.venv/bin/python benchmarks/results/20261203T-qs-rt.py /tmp/v/qs-rt-16.json 16 > /tmp/v/qs-rt-16.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> /tmp/v/qs-rt-16.log
