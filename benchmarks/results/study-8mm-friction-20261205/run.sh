# How this record was made (run from the repository root, both cores; at 1f6e95a's code, the
# friction integrated backward). Nothing else ran except the fresh-clone CI, which overlapped with
# Case B NCF's first minute (that run was then stopped; see README.md).
cd /work/main
start=$(date +%s)
.venv/bin/jaxform study paper --out .git/study/fric8 --element-size-mm 8 > .git/study/fric8.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> .git/study/fric8.log
# stopped during case-b-ncf-nlbm (it would not have finished within the session), then:
.venv/bin/jaxform study paper --out .git/study/fric8 --element-size-mm 8 --analyse-only > .git/study/fric8-analyse.log 2>&1
.venv/bin/python .git/prof/runs_json.py .git/study/fric8 runs.json
python3 .git/fric/compare_study.py benchmarks/results/study-8mm-qs-20261205 .git/study/fric8 > compare-with-study-8mm-qs.md
.venv/bin/jaxform study paper --out .git/study/fric8 --element-size-mm 8 --only case-b > .git/study/fric8-b.log 2>&1   # Case B NCF alone: 2,797 s
.venv/bin/jaxform study paper --out .git/study/fric8 --element-size-mm 8 --analyse-only > .git/study/fric8-analyse2.log 2>&1
