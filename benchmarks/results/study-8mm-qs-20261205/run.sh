# How this record was made (run from the repository root, both cores, nothing else running; at 27ef054's code):
cd /work/main
start=$(date +%s)
.venv/bin/jaxform study paper --out .git/study/qs8 --element-size-mm 8 > .git/study/qs8.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> .git/study/qs8.log
