#!/bin/bash
# The five NCF Case A presets at 4 mm as shipped, one after the other.
cd /work/main
for p in case-a-ncf-nlbm case-a-ncf-lbm-init case-a-ncf-lbm-41 case-a-ncf-lbm-inf case-a-ncf-membrane; do
  s=$(date +%s)
  .venv/bin/jaxform run $p --element-size-mm 4 --out /tmp/ncf4/runs/$p --quiet > /tmp/ncf4/$p.log 2>&1
  rc=$?
  echo "$p rc=$rc wall=$(( $(date +%s)-s ))" >> /tmp/ncf4/runs.log
done
