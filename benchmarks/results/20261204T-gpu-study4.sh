#!/bin/bash
# The device run of issue 15: `jaxform study paper --element-size-mm 4` at the presets' automatic
# (quasi-static) punch speeds, 62.5 mm/s woven and 31.25 mm/s NCF (the study at 4 mm so far ran at
# 500 mm/s), on one NVIDIA H200: the image's Python 3.12 and jax 0.11.2 with CUDA (our lock pins
# 0.10.2 for the CPU), meshio/trimesh/tomli-w carried as wheels in .whl/. Four processes side by
# side on the one GPU, each at most T s: the study's woven Case A and NCF Case A parts (five runs
# each, one batch), and Case B woven and NCF as `jaxform run` with the study's own overrides (so the
# study reuses them); then the runs are put in one study folder and measured (--analyse-only;
# .gpu/standard_test.json, carried, holds claim 9's standard tests computed on the CPU).
# Run (repository root): bash benchmarks/results/20261204T-gpu-study4.sh OUTDIR [T]
set -u
O=$1; T=${2:-470}; mkdir -p "$O"
export PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=/tmp/site:$PWD
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv > "$O/gpu.txt"
python3 -c "import jax, jaxform; print('jax', jax.__version__, jax.devices())" >> "$O/gpu.txt" 2>&1
cat "$O/gpu.txt"; grep -qi cuda "$O/gpu.txt" || exit 1
W=/tmp/s; rm -rf $W; mkdir -p $W
start=$(date +%s)
stamp() { echo "rc=$1 wall=$(( $(date +%s) - start )) s"; }
( timeout -k 20 "$T" python3 -m jaxform study paper --out $W/aw --element-size-mm 4 --only case-a-woven > $W/aw.log 2>&1; stamp $? >> $W/aw.log ) &
( timeout -k 20 "$T" python3 -m jaxform study paper --out $W/an --element-size-mm 4 --only case-a-ncf > $W/an.log 2>&1; stamp $? >> $W/an.log ) &
for f in woven ncf; do
  extra=(); [ $f = ncf ] && extra=(--set numerics.fibre_mass_momentum_term=true)
  ( timeout -k 20 "$T" python3 -m jaxform run case-b-$f-nlbm --out $W/b/case-b-$f-nlbm --quiet --set "name=\"case-b-$f-nlbm\"" \
      --set numerics.fibre_mass_scaling=auto "${extra[@]}" --set blank.element_size_mm=4.0 > $W/b$f.log 2>&1
    stamp $? >> $W/b$f.log ) &
done
wait
mkdir -p $W/study/runs
for d in $W/aw/runs/* $W/an/runs/* $W/b/*; do [ -d "$d" ] && mv "$d" $W/study/runs/; done
cp .gpu/standard_test.json $W/study/ 2>/dev/null  # claim 9's cantilever tests, computed on the CPU (cached per law)
python3 -m jaxform study paper --out $W/study --element-size-mm 4 --analyse-only --force > $W/analyse.log 2>&1; stamp $? >> $W/analyse.log
for f in aw an bwoven bncf analyse; do echo "== $f"; grep -v "it/s\]" $W/$f.log | tail -n 8; done
(cd $W && tar czf "$O/logs.tgz" *.log)
tar czf "$O/study.tgz" -C $W --exclude='frames_*.vtu' --exclude='frames.pvd' study
(cd $W/study && tar czf "$O/final-frames.tgz" runs/*/frames_00010.vtu)
ls -la "$O"
