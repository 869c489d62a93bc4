#!/bin/bash
# The device run (issue 13 item 7, issue 16 item 1 at the quasi-static speed): one NVIDIA H200, the
# image's Python 3.12 and jax 0.11.2 with CUDA (our lock pins 0.10.2 for the CPU; no 0.10 CUDA
# wheels fit the transfer), meshio/trimesh/tomli-w carried as wheels in .whl/. Side by side on the
# one GPU, each at most T s: `jaxform run case-a-woven-nlbm` as shipped (2 mm, automatic numerics,
# 62.5 mm/s) and the gradient check at 8 mm in float64 (20261204T-qs-gradient.py).
# Run (repository root): bash benchmarks/results/20261204T-gpu.sh OUTDIR [T]
set -u
O=$1; T=${2:-540}; mkdir -p "$O"
export PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=/tmp/site:$PWD
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv > "$O/gpu.txt"
python3 -c "import jax, jaxform; print('jax', jax.__version__, jax.devices())" >> "$O/gpu.txt" 2>&1
cat "$O/gpu.txt"; grep -q cuda "$O/gpu.txt" || grep -qi gpu "$O/gpu.txt" || exit 1
start=$(date +%s)
( timeout "$T" python3 -m jaxform run case-a-woven-nlbm --out /tmp/run2 > "$O/run2.log" 2>&1
  echo "rc=$? wall=$(( $(date +%s) - start )) s" >> "$O/run2.log"; cp /tmp/run2/summary.json "$O/run2-summary.json" ) &
( timeout "$T" python3 benchmarks/results/20261204T-qs-gradient.py "$O/grad.json" > "$O/grad.log" 2>&1
  echo "rc=$? wall=$(( $(date +%s) - start )) s" >> "$O/grad.log" ) &
wait
tail -n 4 "$O/run2.log"; tail -n 12 "$O/grad.log"
