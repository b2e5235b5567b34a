#!/usr/bin/env bash
# The figures of docs/performance.md that need a machine of many cores, in
# one run of a few minutes (about four on 16 cores), from programs built
# elsewhere: a build folder, or a folder packed with every library the
# programs load (bin/NAME and a `run` script that starts bin/NAME through
# the packed loader), for a bare machine.
#
#   1. `scaling_bench` on the cases of "Several threads": machine and plain
#      renderer at 1, 2, 4, ... threads up to the CPUs, 512x512, medians of
#      3, the default thread count beside the fastest, and for the most
#      threads their running, spinning and sleeping shares and the packets
#      that crossed threads per packet.
#   2. The cases that only the most threads and one are asked for: a 64-page
#      cache, four pixel computers a node, 256 nodes.
#   3. For every built-in scene on 16, 64 and 256 nodes, the default thread
#      count beside the fastest of a quarter, half and all of the CPUs.
#   4. `commstime`: a cache line's round trip between two cores.
#   5. The rule by which pixel computers answer a packet for their thread at
#      once (at most four a thread), against forcing it on or off
#      (scaling_bench's :a1 and :a0), at half and all of the CPUs.
#   6. Threads that poll the relays' rings (the default) against relays
#      that signal each batch (scaling_bench's :s), at half and all of the
#      CPUs.
# Last (OUT/summary.txt), the cases where the default thread count was more
# than 10% slower than the fastest, part 1's times on 4 threads or more
# that the model of T threads, fitted to its runs on 1 and 2 threads,
# missed by more than 25%, and parts 5's and 6's times beside the
# default's.
#
# Each part has its own time limit, so one that runs long leaves the others
# their turn; its output so far is kept. Each part's output goes to OUT
# (default: many-cores-HOSTNAME) and to the terminal. A bench that finds an
# image different from the plain renderer's exits 1, and so does this script.
#
# usage: examples/bench/many_cores.sh DIR [OUT]
#   DIR: a build folder (DIR/examples/bench/scaling_bench) or a packed one
#   (DIR/run, DIR/bin/scaling_bench)
set -uo pipefail
usage() { echo "usage: examples/bench/many_cores.sh DIR [OUT]  (the script's head says more)"; }
# bad ARGS...: one line naming the script, then the usage, exit 2.
bad() {
  echo "many_cores.sh: $*" >&2
  usage >&2
  exit 2
}
case ${1:-} in -h | --help) usage; awk 'NR > 1 && /^#/ {print; next} NR > 1 {exit}' "$0"; exit 0 ;; esac
if [ $# -lt 1 ] || [ $# -gt 2 ]; then bad "expected DIR [OUT], got $# arguments"; fi
[ -d "$1" ] || bad "DIR '$1' is not a folder"
dir=$(realpath "$1")
out=${2:-many-cores-$(hostname)}

# prog NAME: the command that starts program NAME from DIR.
prog() {
  if [ -x "$dir/run" ] && [ -x "$dir/bin/$1" ]; then
    echo "$dir/run $1"
  elif [ -x "$dir/examples/bench/$1" ]; then
    echo "$dir/examples/bench/$1"
  elif [ -x "$dir/examples/$1/$1" ]; then
    echo "$dir/examples/$1/$1"
  else
    bad "no program $1 in $dir (a build folder, or a packed one with bin/$1)"
  fi
}
scaling=$(prog scaling_bench) || exit 2
commstime=$(prog commstime) || exit 2
mkdir -p "$out" || exit 1

cpus=$(nproc)
threads=1
for ((t = 2; t < cpus; t *= 2)); do threads+=",$t"; done
[ "$cpus" -gt 1 ] && threads+=",$cpus"
quarter=$(( cpus / 4 > 0 ? cpus / 4 : 1 ))
half=$(( cpus / 2 > 0 ? cpus / 2 : 1 ))
some=$(printf '%s\n' "$quarter" "$half" "$cpus" | sort -nu | paste -sd,)
ends=$(printf '%s\n' 1 "$cpus" | sort -nu | paste -sd,)
status=0

# part NAME LIMIT_S COMMAND...: runs COMMAND, its output to OUT/NAME.txt too.
part() {
  local name=$1 limit=$2
  shift 2
  echo "== $name ($(date -u +%H:%M:%S), at most ${limit} s): $*"
  timeout --kill-after=5 "$limit" "$@" 2>&1 | tee "$out/$name.txt"
  local rc=${PIPESTATUS[0]}
  case $rc in
    0) ;;
    124 | 137) echo "== $name: stopped after ${limit} s" ; status=1 ;;
    *) echo "== $name: exit status $rc"; status=1 ;;
  esac
}

# $scaling and $commstime may be "DIR/run NAME": split on purpose.
echo "many_cores: $cpus CPUs, threads $threads; $(uname -srm); output in $out"
grep -m1 'model name' /proc/cpuinfo || true
# shellcheck disable=SC2086
part threads 150 $scaling rings4:16,rings4:64,teapot:16,teapot:64 "$threads" 512 3
# shellcheck disable=SC2086
part most-threads 60 $scaling rings4:64:c64,rings4:16:w4,teapot:256 "$ends" 512 3
cases=""
for scene in teapot tetra mount rings balls gears tree mountain; do
  for nodes in 16 64 256; do cases+="${cases:+,}$scene:$nodes"; done
done
# shellcheck disable=SC2086
part default 120 $scaling "$cases" "$some" 512 3
# shellcheck disable=SC2086
part commstime 20 $commstime 50000 3
halfall=$(printf '%s\n' "$half" "$cpus" | sort -nu | paste -sd,)
# shellcheck disable=SC2086
part answer-at-once 60 $scaling rings4:16,rings4:16:a0,rings4:64,rings4:64:a1,teapot:256,teapot:256:a1 "$halfall" 512 3
# shellcheck disable=SC2086
part signal 60 $scaling rings4:16,rings4:16:s,rings4:64,rings4:64:s,teapot:64,teapot:64:s "$halfall" 512 3

# The default thread count against the fastest, over every case of the
# runs above: the cases where it is more than 10% slower.
cat "$out"/threads.txt "$out"/most-threads.txt "$out"/default.txt 2>/dev/null |
  awk '/ machine .*x the fastest/ {
         n++; r = $0; sub(/x the fastest.*/, "", r); sub(/.* /, "", r)
         if (r + 0 > 1.10) { slow++; print "  default beyond 10% of the fastest: " $1 " " r "x" }
       }
       END { printf "== default thread count: %d of %d cases more than 10%% slower than the fastest\n", slow, n }' |
  tee "$out/summary.txt"
# The model's predictions for 4 threads or more against the measured times
# (fields THREADS:MEASURED/PREDICTED on the line after a case's model).
awk '/ machine  / { label = $1 }
     /measured \/ model/ {
       for (i = 1; i <= NF; i++) {
         if ($i !~ /^[0-9]+:[0-9.]+x$/) continue
         split($i, f, ":"); t = f[1] + 0; r = f[2]; sub(/x$/, "", r)
         if (t < 4) continue
         n++
         if (r + 0 > 1.25 || r + 0 < 0.8) { off++; print "  model off by more than 25%: " label " on " t " threads, measured " r "x the prediction" }
       }
     }
     END { printf "== model of T threads: %d of %d predictions (4 threads or more) off by more than 25%%\n", off, n }' \
  "$out/threads.txt" 2>/dev/null | tee -a "$out/summary.txt"
# Each case with a suffix (SUFFIX, a regular expression) against the same
# case without it: forced (:a1, :a0) against the rule, signalled (:s)
# against polled.
beside() {
  awk -v suffix="$2" -v title="$3" \
    '/per thread count:/ { sub(/.*per thread count: */, ""); nt = split($0, threads, " ") }
     / machine  / { for (i = 1; i <= nt; i++) time[$1, i] = $(2 + i); labels[++n] = $1 }
     END {
       print "== " title ":"
       for (j = 1; j <= n; j++) {
         l = labels[j]
         if (l !~ (suffix "$")) continue
         base = l
         sub(suffix "$", "", base)
         for (i = 1; i <= nt; i++)
           if ((base, i) in time && time[base, i] > 0)
             printf "  %s on %s threads: %.3f s, by default %.3f s (%.2fx)\n", l, threads[i], time[l, i], time[base, i], time[l, i] / time[base, i]
       }
     }' "$out/$1.txt" 2>/dev/null | tee -a "$out/summary.txt"
}
beside answer-at-once ':a[01]' 'answering at once, forced (:a1 on, :a0 off) against the rule'
beside signal ':s' 'relays signalling each batch (:s) against threads polling their rings'
exit $status
