#!/usr/bin/env bash
# The machine split over MPI ranks against one process, side by side:
#   one process on 2 threads | 2 ranks x 1 thread | 4 ranks x 1 thread
# (4 ranks oversubscribe a 2-core machine), over shared memory (vader) and
# TCP on loopback, for Teapot and Rings4 at 512x512 on hypercube:4 and :6.
# The configurations run interleaved, REPEAT rounds, so that a noisy
# machine slows them alike; each row gives the median and the least
# render wall time (the machine's wall_seconds from --stats, set-up
# excluded, the same measure on every row), the ratio of medians to one
# process on 2 threads, and what crossed MPI: packets, their bytes, and the
# MPI messages that carried them (the ranks' bridges only; packets between
# threads of one process are not MPI traffic). After each block a line gives
# TCP's median over shared memory's for the same ranks, and MPI messages a
# packet for each. Every run's image is compared with the one-process image
# of its round; a difference stops the bench.
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

# wall FILE: the machine's render wall time in a --stats file.
wall() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["machine"]["wall_seconds"])' "$1"; }
# over_mpi NAME FILE: NAME summed over the ranks' bridges (0 for one process).
over_mpi() {
  python3 -c 'import json, sys; print(sum(k[sys.argv[1]] for k in json.load(open(sys.argv[2]))["machine"]["ranks"]))' "$1" "$2"
}

configs=("1 2 none" "2 1 vader" "2 1 tcp" "4 1 vader" "4 1 tcp")
run() {  # run SCENE TOPOLOGY RANKS THREADS BTL STATS IMAGE
  local args=("$1" --topology "$2" --width "$size" --height "$size" --threads "$4" -q -o "$7" --stats "$6")
  case $5 in
    none) "$vmpray" "${args[@]}" ;;
    vader) mpirun -np "$3" --mca btl self,vader "$vmpray" "${args[@]}" ;;
    tcp) mpirun -np "$3" --mca btl self,tcp --mca btl_tcp_if_include lo "$vmpray" "${args[@]}" ;;
  esac
}

printf '%-8s %-12s %-22s %10s %10s %8s %12s %14s %10s\n' scene topology configuration median_s least_s ratio packets bytes messages
for scene in teapot rings4; do
  for topology in hypercube:4 hypercube:6; do
    declare -A times=()
    for ((round = 0; round < repeat; ++round)); do
      for c in "${configs[@]}"; do
        read -r ranks threads btl <<<"$c"
        out="$work/$ranks-$btl-$round.json"
        run "$scene" "$topology" "$ranks" "$threads" "$btl" "$out" "$work/img.png" >/dev/null
        times[$c]+="$(wall "$out") "
        if [[ $btl == none ]]; then
          mv "$work/img.png" "$work/one.png"
        elif ! cmp -s "$work/img.png" "$work/one.png"; then
          echo "mpi_bench: $scene $topology, $ranks ranks over $btl: image differs from one process" >&2
          exit 1
        fi
      done
    done
    base=""
    declare -A medians=() per_packet=()
    for c in "${configs[@]}"; do
      read -r ranks threads btl <<<"$c"
      sorted=$(tr ' ' '\n' <<<"${times[$c]}" | sed '/^$/d' | sort -g)
      median=$(sed -n "$(( (repeat + 1) / 2 ))p" <<<"$sorted")
      least=$(head -n 1 <<<"$sorted")
      [[ -z $base ]] && base=$median
      out="$work/$ranks-$btl-0.json"
      label="$ranks x $threads thread(s)"
      [[ $btl != none ]] && label+=" $btl"
      packets=$(over_mpi packets_sent "$out") messages=$(over_mpi messages_sent "$out")
      printf '%-8s %-12s %-22s %10.3f %10.3f %8.2f %12s %14s %10s\n' "$scene" "$topology" "$label" "$median" "$least" \
        "$(awk -v a="$median" -v b="$base" 'BEGIN { print a / b }')" "$packets" \
        "$(over_mpi bytes_sent "$out")" "$messages"
      medians[$c]=$median
      per_packet[$c]=$(awk -v m="$messages" -v p="$packets" 'BEGIN { printf "%.3f", (p > 0 ? m / p : 0) }')
    done
    for ranks in 2 4; do
      printf '%-8s %-12s %d ranks: TCP over shared memory %.2fx; MPI messages a packet %s shared memory, %s TCP\n' \
        "$scene" "$topology" "$ranks" "$(awk -v a="${medians[$ranks 1 tcp]}" -v b="${medians[$ranks 1 vader]}" 'BEGIN { print a / b }')" \
        "${per_packet[$ranks 1 vader]}" "${per_packet[$ranks 1 tcp]}"
    done
    unset times medians per_packet
  done
done
