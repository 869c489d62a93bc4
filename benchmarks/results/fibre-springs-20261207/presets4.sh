#!/bin/bash
# The woven Case A presets at 4 mm as shipped (NLBM: qs4mm.log), one after the other, both cores.
D=$(dirname "$0"); RUNS=${RUNS:-/tmp/fsp4}
for p in case-a-woven-lbm-init case-a-woven-lbm-41 case-a-woven-lbm-inf case-a-woven-membrane; do
  rm -rf $RUNS/$p; start=$(date +%s)
  /work/main/.venv/bin/jaxform run $p --element-size-mm 4 --out $RUNS/$p --quiet > $RUNS-$p.log 2>&1
  echo "$p rc=$? wall=$(( $(date +%s)-start ))s" >> $D/presets4.log
done
/work/main/.venv/bin/python $D/../presets-4mm-20261206/collect.py $RUNS case-a-woven-lbm-init case-a-woven-lbm-41 case-a-woven-lbm-inf case-a-woven-membrane > $D/presets4.json
echo DONE >> $D/presets4.log
