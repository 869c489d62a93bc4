#!/bin/bash
cd /work/main
start=$(date +%s)
.venv/bin/jaxform run case-a-woven-nlbm --out /tmp/v/new-w2-half --set process.speed_mm_per_s=31.25 > /tmp/v/new-w2-half.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> /tmp/v/new-w2-half.log
.venv/bin/jaxform check-quasi-static /tmp/v/new-w2 /tmp/v/new-w2-half --json /tmp/v/new-w2-check.json > /tmp/v/new-w2-check.log 2>&1
echo "rc=$?" >> /tmp/v/new-w2-check.log
