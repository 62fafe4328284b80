#!/bin/bash
# Grid/Nodes = near material gives the results of Nodes = all bit for bit: runs a scene both
# ways (overrides appended to both) and asserts that the full-precision particle tables of
# every output are identical, that the near-material run kept fewer nodes than the lattice
# has and chose them again at least MIN_REFRESHES times (so the refresh was exercised), with
# the drift bound verified every step (MPM_VERIFY_DRIFT_BOUND); and that its grid files hold
# fewer cells with the same nodal values wherever there is mass (compare_grid_mass.py; on several
# ranks as many cells).
# On several ranks deal.II's grid is fine only near the material and must have been refined at least
# MIN_GRID_REFINEMENTS (default 1) times as it spread.
# Usage: [NP=n] nodes_near_material.sh EXE PRM OUTDIR MIN_REFRESHES [override lines...]
# NP (default 1): both runs on that many MPI ranks; the particles then agree to round-off (the
# partitions differ) and each rank starts with at most 1.1 times the mean number of points
# (unless UNEVEN_OK is set: a partition by cells, Parallel/Load balance threshold = 0). SPREAD_NP
# (float): the particles and nodal values may differ by up to 10x the difference of Nodes = all on
# SPREAD_NP ranks from Nodes = all on NP (the round-off of another partition).
set -eu
exe=$1 prm=$2 out=$3 min_refreshes=$4
shift 4
np=${NP:-1}
here=$(dirname "$0")
table=("subsection Output" "  set Write particle table = true" "end")
bash "$here/run_scene.sh" "$exe" "$prm" "$out/all" "$np" "${table[@]}" "$@" \
  "subsection Grid" "  set Nodes = all" "end" > "$out-all.log" 2>&1 ||
  { cat "$out-all.log"; echo "FAILED: the run with Nodes = all failed"; exit 1; }
MPM_VERIFY_DRIFT_BOUND=1 bash "$here/run_scene.sh" "$exe" "$prm" "$out/near" "$np" "${table[@]}" "$@" \
  "subsection Grid" "  set Nodes = near material" "end" > "$out-near.log" 2>&1 ||
  { cat "$out-near.log"; echo "FAILED: the run with Nodes = near material failed"; exit 1; }
grep "nodes near the material" "$out-near.log"
lattice=$(sed -n 's/.*material: [0-9]* of the \([0-9]*\) .*/\1/p' "$out-near.log")
most=$(sed -n 's/.* at the end, \([0-9]*\) at most.*/\1/p' "$out-near.log")
refreshes=$(sed -n 's/.*chosen again \([0-9]*\) times.*/\1/p' "$out-near.log")
[ -n "$lattice" ] && [ -n "$most" ] && [ -n "$refreshes" ] || { echo "FAILED: no node report in the log"; exit 1; }
[ "$most" -lt "$lattice" ] || { echo "FAILED: $most nodes kept, the lattice has $lattice"; exit 1; }
[ "$refreshes" -ge "$min_refreshes" ] ||
  { echo "FAILED: the nodes were chosen again $refreshes times, fewer than $min_refreshes"; exit 1; }
n=0
if [ "$np" -eq 1 ]; then
  for f in "$out"/all/particle_table_*.csv; do
    cmp "$f" "$out/near/$(basename "$f")" || { echo "FAILED: $(basename "$f") differs"; exit 1; }
    n=$((n + 1))
  done
  [ "$n" -gt 0 ] || { echo "FAILED: no particle tables"; exit 1; }
  /usr/bin/python3 "$here/compare_grid_mass.py" "$out/all" "$out/near"
else
  # Several ranks: near the material the partition weighs only the cells with points, so the
  # runs sum over other partitions: equal to round-off, and the points shared out evenly.
  spread=()
  if [ -n "${SPREAD_NP:-}" ]; then # float: Nodes = all on SPREAD_NP ranks shows the partition's round-off
    bash "$here/run_scene.sh" "$exe" "$prm" "$out/spread" "$SPREAD_NP" "${table[@]}" "$@" \
      "subsection Grid" "  set Nodes = all" "end" > "$out-spread.log" 2>&1 ||
      { cat "$out-spread.log"; echo "FAILED: the run with Nodes = all on $SPREAD_NP ranks failed"; exit 1; }
    spread=(--spread "$out/spread")
  fi
  /usr/bin/python3 "$here/compare_np.py" "$out/all" "$out/near" --rtol 1e-10 "${spread[@]}"
  /usr/bin/python3 "$here/compare_grid_mass.py" "$out/all" "$out/near" --rtol 1e-10 "${spread[@]}"
  refinements=$(sed -n "s/.*deal.II's grid: fine only near the material.* refined \([0-9]*\) times.*/\1/p" "$out-near.log")
  echo "deal.II's grid refined ${refinements:-?} times as the material spread"
  [ "${refinements:-0}" -ge "${MIN_GRID_REFINEMENTS:-1}" ] ||
    { echo "FAILED: deal.II's grid was refined ${refinements:-0} times as the material spread"; exit 1; }
  counts=$(for f in "$out"/near/particle_table_00000.*.csv; do echo $(($(wc -l < "$f") - 1)); done)
  echo "points per rank at the start, near the material:" $counts
  [ -n "${UNEVEN_OK:-}" ] || echo "$counts" | awk -v np="$np" '{ n++; s += $1; if ($1 > m) m = $1 }
    END { if (n != np || m > 1.1 * s / n) { print "FAILED: the points are not shared out evenly"; exit 1 } }'
  n=$(ls "$out"/near/particle_table_*.csv | wc -l)
fi
echo "$n particle tables compared; at most $most of $lattice nodes kept, chosen again $refreshes times"
