#!/bin/bash
# The V6 sweep (doc/validation-v6.md): column collapses over aspect ratios, local damping and
# bases, each measured by scripts/validation/column_runout.py. One JSON line per run in RESULTS.
#
# Usage: v6_sweep.sh EXE WORKDIR RESULTS "LAMBDAS" "DAMPINGS" "BASES" [CELLS_PER_RADIUS] [BACKEND] [METHOD]
#   METHOD: GIMP (default, FLIP 0.99), GIMP-PIC (FLIP 0), linear (linear shapes, FLIP 0.99)
#   e.g. v6_sweep.sh build-cuda/dealii-mpm /tmp/v6 /tmp/v6/results.jsonl "0.5 1 2" "0 0.05" "friction no-slip" 20 cuda
# A run already in RESULTS (same lambda, damping, base, cells) is skipped, so that a sweep cut
# by a time limit resumes where it stopped. Each run's output is deleted once measured; its
# history and log stay in WORKDIR. Needs python3 with numpy.
set -u
exe=$(readlink -f "$1") work=$2 results=$3 lambdas=$4 dampings=$5 bases=$6 cells=${7:-20} backend=${8:-cuda}
method=${9:-GIMP}
case $method in
  GIMP) method_options="--shape-function GIMP --flip-fraction 0.99" suffix="" ;;
  GIMP-PIC) method_options="--shape-function GIMP --flip-fraction 0" suffix="_GIMP-PIC" ;;
  linear) method_options="--shape-function linear --flip-fraction 0.99" suffix="_linear" ;;
  *) echo "v6_sweep.sh: METHOD must be GIMP, GIMP-PIC or linear, got '$method'"; exit 2 ;;
esac
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
touch "$results"
for lambda in $lambdas; do
  for damping in $dampings; do
    for base in $bases; do
      tag="lambda${lambda}_D${damping}_${base}_c${cells}${suffix}"
      if grep -q "\"tag\": \"$tag\"" "$results"; then continue; fi
      out="$work/$tag"
      python3 "$here/../column_aspect_ratio.py" --lambda "$lambda" --damping "$damping" --base "$base" \
        --cells-per-radius "$cells" --backend "$backend" $method_options --table-only --output "$out" \
        > "$work/$tag.prm" || exit 1
      start=$(date +%s.%N)
      (cd "$work" && "$exe" "$work/$tag.prm" > "$work/$tag.log" 2>&1); rc=$?
      wall=$(python3 -c "print(f'{$(date +%s.%N) - $start:.2f}')")
      if [ $rc -ne 0 ]; then
        echo "{\"tag\": \"$tag\", \"method\": \"$method\", \"lambda\": $lambda, \"damping\": $damping, \"base\": \"$base\", \"cells\": $cells, \"rc\": $rc, \"wall\": $wall}" >> "$results"
        tail -5 "$work/$tag.log"
        continue
      fi
      python3 "$here/column_runout.py" "$out" --cell "$(python3 -c "print(1 / $cells)")" --lambda "$lambda" \
        --json "$work/$tag.json" | tee -a "$work/$tag.log"
      cp "$out/history.csv" "$work/$tag.history.csv"
      python3 - "$work/$tag.json" "$tag" "$lambda" "$damping" "$base" "$cells" "$wall" "$work/$tag.log" "$work/$tag.history.csv" "$method" >> "$results" <<'EOF'
import json, re, sys
result = json.load(open(sys.argv[1]))
tag, lam, damping, base, cells, wall, log, history, method = sys.argv[2:]
text = open(log).read()
done = re.findall(r"after (\d+) steps in ([\d.]+) s wall", text)
rows = [l.split(",") for l in open(history).read().split("\n")[1:] if l]
header = open(history).readline().strip().split(",")
last = dict(zip(header, rows[-1]))
result.update(tag=tag, method=method, damping=float(damping), base=base, cells=int(cells), wall=float(wall), rc=0,
              n_steps=int(done[-1][0]) if done else None, program_seconds=float(done[-1][1]) if done else None,
              kinetic_energy_end=float(last["kinetic_energy"]), work_of_gravity=float(last["work_of_gravity"]),
              n_removed=int(float(last["n_removed"])))
print(json.dumps(result))
EOF
      rm -rf "$out"
    done
  done
done
