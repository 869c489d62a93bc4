#!/bin/bash
# Run from the repository root, both cores, nothing else running.
R=benchmarks/results/lbm-inf-qs-20261207
PY=.venv/bin/python
$PY $R/imperfect.py $R/imperfect.jsonl case-a-woven-lbm-inf 8 0.01,0.05 > $R/lbm-inf-8mm.log 2>&1
# the speed ladder below the automatic 62.5 mm/s (../speed-8mm-20261206/ladder.py: each rung against its half and the slowest)
$PY benchmarks/results/speed-8mm-20261206/ladder.py $R/ladder.jsonl case-a-woven-lbm-inf 31.25,15.625,7.8125 8 > $R/ladder.log 2>&1
$PY $R/damped.py $R/damped.jsonl case-a-woven-lbm-inf 8 50 > $R/damped.log 2>&1
