#!/bin/bash
# validation queue: each run alone
J=/work/main/.venv/bin/jaxform
run() { # label dir code args...
  local label=$1 code=$2; shift 2
  local start=$(date +%s)
  if [ "$code" = base ]; then (cd /tmp/base && PYTHONPATH=/tmp/base $J run "$@" > /tmp/v/$label.log 2>&1); else (cd /work/main && $J run "$@" > /tmp/v/$label.log 2>&1); fi
  echo "rc=$? wall=$(( $(date +%s)-start ))s" >> /tmp/v/$label.log
}
run base-w4 base case-a-woven-nlbm --element-size-mm 4 --out /tmp/v/base-w4
run new-w4 new case-a-woven-nlbm --element-size-mm 4 --out /tmp/v/new-w4
run new-w2 new case-a-woven-nlbm --out /tmp/v/new-w2
run base-w2 base case-a-woven-nlbm --out /tmp/v/base-w2
run new-n4 new case-a-ncf-nlbm --element-size-mm 4 --out /tmp/v/new-n4
echo done > /tmp/v/queue.done
