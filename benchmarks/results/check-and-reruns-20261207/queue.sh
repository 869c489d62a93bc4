cd /work/main
R=benchmarks/results
start=$(date +%s)
.venv/bin/python $R/20261203T-qs-rt.py /tmp/q/qs-rt-seed17.json 17 > /tmp/q/qs-rt-seed17.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> /tmp/q/qs-rt-seed17.log
start=$(date +%s)
.venv/bin/jaxform run case-a-woven-nlbm --out /tmp/q/woven-2mm > /tmp/q/woven-2mm.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> /tmp/q/woven-2mm.log
start=$(date +%s)
.venv/bin/jaxform study paper --out /tmp/q/study4 --element-size-mm 4 --only case-a-woven > /tmp/q/study4.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> /tmp/q/study4.log
