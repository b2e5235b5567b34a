#!/usr/bin/env bash
# The machine split over MPI ranks against one process, side by side:
#   one process on 2 threads | 2 ranks x 1 thread | 4 ranks x 1 thread
# (4 ranks oversubscribe a 2-core machine), over shared memory (vader) and
# TCP on loopback, for Teapot and Rings4 at 512x512 on hypercube:4 and :6.
# The configurations run interleaved, REPEAT rounds, so that a noisy
# machine slows them alike; each row gives the median and the least
# render wall time (the machine's wall_seconds from --stats, set-up
# excluded), the ratio of medians to one process on 2 threads, and the
# packets and bytes that crossed MPI.
#
# usage: examples/bench/mpi_bench.sh [BUILD_DIR] [REPEAT] [SIZE]
#        (defaults: build/release 5 512)
set -euo pipefail
build=${1:-build/release}
repeat=${2:-5}
size=${3:-512}
vmpray=$(realpath "$build/app/vmpray")
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_rmaps_base_oversubscribe=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# field NAME FILE: the first number after "NAME": in a --stats file.
field() { grep -o "\"$1\": [0-9.e+-]*" "$2" | head -n 1 | sed 's/.*: //'; }
# sum NAME FILE: the sum of every "NAME": number (one per rank).
sum() { grep -o "\"$1\": [0-9]*" "$2" | sed 's/.*: //' | awk '{ s += $1 } END { print s + 0 }'; }

configs=("1 2 none" "2 1 vader" "2 1 tcp" "4 1 vader" "4 1 tcp")
run() {  # run SCENE TOPOLOGY RANKS THREADS BTL OUT
  local args=("$1" --topology "$2" --width "$size" --height "$size" --threads "$4" -q -o "$work/img.png" --stats "$6")
  case $5 in
    none) "$vmpray" "${args[@]}" ;;
    vader) mpirun -np "$3" --mca btl self,vader "$vmpray" "${args[@]}" ;;
    tcp) mpirun -np "$3" --mca btl self,tcp --mca btl_tcp_if_include lo "$vmpray" "${args[@]}" ;;
  esac
}

printf '%-8s %-12s %-22s %10s %10s %8s %12s %14s\n' scene topology configuration median_s least_s ratio packets bytes
for scene in teapot rings4; do
  for topology in hypercube:4 hypercube:6; do
    declare -A times=()
    for ((round = 0; round < repeat; ++round)); do
      for c in "${configs[@]}"; do
        read -r ranks threads btl <<<"$c"
        out="$work/$ranks-$btl-$round.json"
        run "$scene" "$topology" "$ranks" "$threads" "$btl" "$out" >/dev/null
        times[$c]+="$(field wall_seconds "$out") "
      done
    done
    base=""
    for c in "${configs[@]}"; do
      read -r ranks threads btl <<<"$c"
      sorted=$(tr ' ' '\n' <<<"${times[$c]}" | sed '/^$/d' | sort -g)
      median=$(sed -n "$(( (repeat + 1) / 2 ))p" <<<"$sorted")
      least=$(head -n 1 <<<"$sorted")
      [[ -z $base ]] && base=$median
      out="$work/$ranks-$btl-0.json"
      label="$ranks x $threads thread(s)"
      [[ $btl != none ]] && label+=" $btl"
      printf '%-8s %-12s %-22s %10.3f %10.3f %8.2f %12s %14s\n' "$scene" "$topology" "$label" "$median" "$least" \
        "$(awk -v a="$median" -v b="$base" 'BEGIN { print a / b }')" "$(sum packets_sent "$out")" "$(sum bytes_sent "$out")"
    done
    unset times
  done
done
