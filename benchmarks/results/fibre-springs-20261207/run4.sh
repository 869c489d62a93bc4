#!/bin/bash
# The 4 mm A/B of this record, one after the other (both cores, nothing else running).
# BASE: a worktree of the code before (e0681a9); OUT: where the pickles go.
set -x
D=$(dirname "$0"); BASE=${BASE:-/tmp/base}; OUT=${OUT:-/tmp/fs4}
py=/work/main/.venv/bin/python
$py $D/cost.py 4 2000 12,24,48,74 > $D/cost-4mm.jsonl
PYTHONPATH=$BASE $py $D/run.py 4 $OUT base12
$py $D/run.py 4 $OUT new12
$py $D/run.py 4 $OUT new48 case-a-woven-nlbm 48
$py $D/../step-cost-20261206/check.py $OUT base12 new12 > /dev/null; cp $OUT/check.json $D/check-4mm-base12-new12.json
$py $D/../step-cost-20261206/check.py $OUT new12 new48 > /dev/null; cp $OUT/check.json $D/check-4mm-new12-new48.json
echo DONE
