# How this record was made (run from the repository root, both cores): the study's woven part, then Case B woven as its own run with the study's overrides into the same folder, then `jaxform study paper --out DIR --element-size-mm 4 --analyse-only` (the standard-test cache copied in from the GPU record).
cd /work/main
start=$(date +%s)
.venv/bin/jaxform study paper --out .git/study/qs4 --element-size-mm 4 --only case-a-woven > .git/study/qs4-woven.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> .git/study/qs4-woven.log
.venv/bin/jaxform run case-b-woven-nlbm --out .git/study/qs4/runs/case-b-woven-nlbm --set 'name="case-b-woven-nlbm"' --set numerics.fibre_mass_scaling=auto --set blank.element_size_mm=4.0 > .git/study/qs4-bwoven.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> .git/study/qs4-bwoven.log
# Added on 2026-12-04 (next session, at 7d0bd28): the NCF Case A bending laws (the four in one program; membrane-only and
# Case B NCF not run), then the report again over every run in the folder.
start=$(date +%s)
.venv/bin/jaxform study paper --out .git/study/qs4 --element-size-mm 4 --only case-a-ncf --bending nlbm,lbm-init,lbm-41,lbm-inf > .git/study/qs4-ncf.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> .git/study/qs4-ncf.log
.venv/bin/jaxform study paper --out .git/study/qs4 --element-size-mm 4 --analyse-only > .git/study/qs4-analyse2.log 2>&1
# Added on 2026-12-04/05 (the session after, with the code of 965a23e: the run started before 39b736b): NCF membrane-only,
# then the report again over every run in the folder (the wrapper's own rc line is missing from
# qs4-ncf-membrane.log: the wrapper was stopped while the command ran on; the command's end time is there).
start=$(date +%s)
.venv/bin/jaxform study paper --out .git/study/qs4 --element-size-mm 4 --only case-a-ncf --bending membrane > .git/study/qs4-ncf-membrane.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> .git/study/qs4-ncf-membrane.log
.venv/bin/jaxform study paper --out .git/study/qs4 --element-size-mm 4 --analyse-only > .git/study/qs4-analyse3.log 2>&1
# Added on 2026-12-05 (the session after, at 3663a31's code: the step cut and the adaptive contact): NCF NLBM again
# alone (the failed run of 2026-12-04 moved out of runs/ first, since the study reuses a run folder),
# then the report again over every run in the folder.
mv .git/study/qs4/runs/case-a-ncf-nlbm .git/study/qs4-failed-case-a-ncf-nlbm-20261204
start=$(date +%s)
.venv/bin/jaxform study paper --out .git/study/qs4 --element-size-mm 4 --only case-a-ncf --bending nlbm > .git/study/qs4-ncf-nlbm2.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))s" >> .git/study/qs4-ncf-nlbm2.log
.venv/bin/jaxform study paper --out .git/study/qs4 --element-size-mm 4 --analyse-only > .git/study/qs4-analyse4.log 2>&1
