#!/bin/bash
# extra convergence runs: very fine spanwise meshes (4 chordwise panels: chordwise count barely matters), Weissinger-like nc=1
cd "$(dirname "$0")" && . venv/bin/activate
export NUMBA_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
python asb_run.py 384 4 uniform uniform 2>&1 | grep "^asb"
python asb_run.py 192 4 cosine uniform 2>&1 | grep "^asb"
python asb_run.py 384 4 cosine uniform 2>&1 | grep "^asb"
python ptera_run.py 192 4 cosine uniform 2>&1 | grep "^ptera"
python ptera_run.py 48 1 uniform uniform 2>&1 | grep "^ptera"
