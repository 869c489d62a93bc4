cd /work/main
while ! grep -q "^rc=" /tmp/q/study4.log 2>/dev/null; do sleep 10; done
start=$(date +%s)
.venv/bin/jaxform run case-a-woven-nlbm --out /tmp/q/woven-2mm-half --set process.speed_mm_per_s=31.25 > /tmp/q/woven-2mm-half.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> /tmp/q/woven-2mm-half.log
.venv/bin/jaxform check-quasi-static /tmp/q/woven-2mm /tmp/q/woven-2mm-half --json /tmp/q/woven-2mm-check.json > /tmp/q/woven-2mm-check.log 2>&1
echo "rc=$?" >> /tmp/q/woven-2mm-check.log
