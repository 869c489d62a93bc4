#!/bin/bash
# run.sh went on after case-a-ncf-lbm-init with membrane, lbm-inf, lbm-41 (reordered so that the
# membrane-only preset runs before the session's time ends); lbm-init itself ran from run.sh.
cd /work/main
pid=$1
start=$(date -d "$(ps -o lstart= -p $pid)" +%s)
while kill -0 $pid 2>/dev/null; do sleep 5; done
echo "case-a-ncf-lbm-init rc=? wall=$(( $(date +%s)-start ))" >> /tmp/ncf4/runs.log
for p in case-a-ncf-membrane case-a-ncf-lbm-inf case-a-ncf-lbm-41; do
  s=$(date +%s)
  .venv/bin/jaxform run $p --element-size-mm 4 --out /tmp/ncf4/runs/$p --quiet > /tmp/ncf4/$p.log 2>&1
  rc=$?
  echo "$p rc=$rc wall=$(( $(date +%s)-s ))" >> /tmp/ncf4/runs.log
done
