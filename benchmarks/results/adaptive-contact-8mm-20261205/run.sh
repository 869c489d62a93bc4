# How this record was made (repository root, at 3663a31's driver code; each run alone, both cores;
# the first two with the numerics the 8 mm study used, which stopped on penetration at 9d1426b).
cd /work/main
for c in case-a-ncf-lbm-init case-a-ncf-membrane; do
  .venv/bin/jaxform run $c --element-size-mm 8 --set numerics.fibre_mass_scaling=auto \
      --set numerics.fibre_mass_momentum_term=true --out .git/stiff/$c-study > .git/stiff/$c-study.log 2>&1
done
# the preset's own numerics (fibre mass 3 without its momentum term, a shell-governed step)
.venv/bin/jaxform run case-a-ncf-lbm-init --element-size-mm 8 --out .git/stiff/case-a-ncf-lbm-init
.venv/bin/python benchmarks/results/adaptive-contact-8mm-20261205/compare.py .git/stiff > benchmarks/results/adaptive-contact-8mm-20261205/compare.log
