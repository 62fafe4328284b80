#!/bin/bash
# Fresh Debian 12, as root: install, build, run the default scene (V1 elastic column, 2D).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p results && cd results
../build/dealii-mpm ../prm/elastic_column_2d.prm
/usr/bin/python3 ../scripts/validation/column_error.py output-elastic-column-2d
/usr/bin/python3 ../scripts/final_state_picture.py output-elastic-column-2d elastic-column-2d.png
echo "Results are in $(pwd)/output-elastic-column-2d (particles.pvd for ParaView);"
echo "the final state, as a picture any image viewer opens: $(pwd)/elastic-column-2d.png"
