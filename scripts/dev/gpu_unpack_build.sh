# Sourced by the GPU scripts. unxz_beside DIR: each FILE.xz in DIR decompressed beside it, unless there
# already (libdeal.ii*.xz into $DL/lib, the unpacked deal.II runtime, default /opt/dl; the device's
# python3 has lzma where xz may be missing). unpack_build DIR makes a build folder carried to the GPU
# machine runnable: unxz_beside DIR, and dealii-mpm made executable.
unxz_beside() {
  local dir=$1 xz target
  for xz in "$dir"/*.xz; do
    [ -f "$xz" ] || continue
    target=$dir/$(basename "$xz" .xz)
    case $(basename "$xz") in libdeal.ii*) target=${DL:-/opt/dl}/lib/$(basename "$xz" .xz) ;; esac
    [ -e "$target" ] || python3 -c "import lzma,shutil,sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2],'wb'))" "$xz" "$target"
  done
}
unpack_build() {
  unxz_beside "$1"
  chmod +x "$1/dealii-mpm"
}

# prepare_build DIR OUT: unpack_build DIR, put DIR first on the library path, let a singleton start without
# mpirun's daemon, and record the GPU in OUT/machine.txt.
prepare_build() {
  unpack_build "$1"
  export LD_LIBRARY_PATH="$1${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  export OMPI_MCA_ess_singleton_isolated=1
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$2/machine.txt"
}

# prepare_mpi_runs DIR OUT: prepare_build DIR OUT (OUT created), `exe` set to DIR's dealii-mpm (absolute), and
# mpirun allowed as root.
prepare_mpi_runs() {
  mkdir -p "$2"
  prepare_build "$1" "$2"
  exe=$(readlink -f "$1/dealii-mpm")
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
}

# check NAME LIMIT COMMAND...: runs it, logs to $out/NAME.log, prints rc, time and the log's last lines, and
# sets failed=1 where it fails (the caller sets out and failed=0).
check() {
  local name=$1 limit=$2 start rc
  shift 2
  start=$(date +%s)
  timeout "$limit" "$@" >"$out/$name.log" 2>&1
  rc=$?
  echo "== $name: rc $rc ($(($(date +%s) - start)) s)"
  grep -E "largest|FAILED|migrated|repartition|ok" "$out/$name.log" | tail -8 | cut -c1-300
  [ $rc = 0 ] || failed=1
}
