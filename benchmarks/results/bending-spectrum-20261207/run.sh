#!/bin/bash
# The step from the shell's own bending spectrum (8807ec9) against the code before (e3bebb6, a worktree at
# /tmp/base, first on sys.path through PYTHONPATH). Both cores, nothing else running, one after the other.
# Run from the repository root: bash benchmarks/results/bending-spectrum-20261207/run.sh
set -u
R=benchmarks/results/bending-spectrum-20261207
S=benchmarks/results/step-cost-20261206
PY=.venv/bin/python
rm -rf /tmp/bs2 /tmp/bs4
# 1. the presets' numerics (steps, what governs the step) in both codes
$PY $R/numerics.py > $R/numerics-new.log 2>&1
PYTHONPATH=/tmp/base $PY $R/numerics.py > $R/numerics-base.log 2>&1
# 2. ms a step at 2 mm from the flat start, 3,000 steps, alternating (the compiled step is the same code)
for t in base new base new; do
  if [ $t = base ]; then PYTHONPATH=/tmp/base $PY $S/ab_windows.py start 3000 | tail -1; else $PY $S/ab_windows.py start 3000 | tail -1; fi
done > $R/ms-a-step-2mm.jsonl 2>&1
# 3. woven Case A NLBM at 4 mm as shipped, before and after; the quasi-static check between them
PYTHONPATH=/tmp/base $PY $S/run.py 4 /tmp/bs4 base > $R/ab4mm.log 2>&1
$PY $S/run.py 4 /tmp/bs4 new >> $R/ab4mm.log 2>&1
$PY $S/check.py /tmp/bs4 base new > $R/ab4mm-check.log 2>&1; cp /tmp/bs4/check.json $R/ab4mm-check.json
# 4. the 2 mm preset as shipped, as a user runs it
start=$(date +%s)
.venv/bin/jaxform run case-a-woven-nlbm --out /tmp/bs2 > $R/run2mm.log 2>&1
echo "rc=$? wall=$(( $(date +%s) - start ))s" >> $R/run2mm.log
cp /tmp/bs2/summary.json $R/run2mm-summary.json
