#!/bin/bash
# the conjugate reading's follow-ups at 8 mm, one after the other (run from this folder; OUT=/tmp/c1)
J=/work/main/.venv/bin/jaxform
start=$(date +%s)
$J run case-a-woven-nlbm --element-size-mm 8 --set fabric.shear_reading=conjugate --verify-quasi-static \
   --out /tmp/c1/qs-conjugate-8mm --quiet > qs-conjugate-8mm.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))" >> qs-conjugate-8mm.log
start=$(date +%s)
$J study paper --out /tmp/c1/study-conjugate-8mm --element-size-mm 8 --only case-a-woven \
   --set fabric.shear_reading=conjugate --quiet > study-conjugate-8mm.log 2>&1
echo "rc=$? wall=$(( $(date +%s)-start ))" >> study-conjugate-8mm.log
