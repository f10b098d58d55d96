#!/usr/bin/env bash
# The learning loop of docs/learning.md, end to end: noisy demonstrations of the flagship, a
# behaviour-cloned pick in numpy, exported as ONNX, swept alone and inside a tree beside the
# scripted pick on a held-out seed. Run from the repository root after `tools/bootstrap` and
# `cargo build --release`, with the Python package and pyarrow installed
# (`pip install ./python[learning]`). 4 min 40 s on 2 cores (`/usr/bin/time`, 2026-11-30).
#
#   examples/learning/loop.sh [WORK_DIR]      (default: target/learning)
#
# The model goes to WORK_DIR/cube_pick.onnx; compare it with the shipped
# trees/policies/cube_pick.onnx (byte for byte with OPENBLAS_NUM_THREADS=1), or copy it there to
# sweep the trees with it (step 4).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
work=${1:-target/learning}
macrotree=target/release/macrotree
mkdir -p "$work"

# A sweep exits 1 when some scenario failed (a figure, not an error); 2 is bad input.
sweep() { "$macrotree" sweep "$@" || [ $? -eq 1 ]; }

# 1. 800 demonstrations of the flagship (seed 1) with DART noise: the arm is pushed off its path
#    (0.02 rad per joint, held 0.1 s) while the dataset records the clean command.
#    Two of the 800 noisy episodes fail; --only-success keeps the 798 others.
sweep trees/cube_to_bowl.yaml --scenarios 800 --seed 1 --jobs 2 \
    --dataset "$work/demos" --cameras none --noise 0.02,10 --only-success --overwrite

# 2. + 3. Clone the pick (the frames inside `subtree[pick]`), chunks of 20 commands, 120 epochs;
#    export ONNX with the normalisation and the dataset's digest in its metadata.
OPENBLAS_NUM_THREADS=1 python -m macrotree.bc "$work/demos" --leaf 'subtree[pick]' \
    --state joints --epochs 120 --out "$work/cube_pick.onnx"
cmp -s "$work/cube_pick.onnx" trees/policies/cube_pick.onnx \
    && echo "the model is the shipped one, byte for byte" \
    || echo "the model differs from the shipped one (another BLAS, or thread count)"

# 4. + 5. The shipped learned pick alone, then with the scripted pick as its fallback, on
#    held-out seed 7 (the figures of docs/learning.md).
sweep trees/learned_pick_alone.yaml --scenarios 200 --seed 7 --jobs 2
sweep trees/learned_cube_to_bowl.yaml --scenarios 200 --seed 7 --jobs 2
