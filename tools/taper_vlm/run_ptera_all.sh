#!/bin/bash
# runs all pterasoftware cases sequentially
cd "$(dirname "$0")" && . venv/bin/activate
export NUMBA_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
for c in "24 8 uniform uniform" "48 8 uniform uniform" "96 8 uniform uniform" "48 4 uniform uniform" "48 16 uniform uniform" \
         "24 8 cosine uniform" "48 8 cosine uniform" "96 8 cosine uniform" "48 8 uniform cosine" "96 16 uniform uniform" "192 8 uniform uniform" "96 16 cosine uniform"; do
  python ptera_run.py $c 2>&1 | grep "^ptera"
done
