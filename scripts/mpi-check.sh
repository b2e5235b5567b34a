#!/usr/bin/env bash
# The README's commands for several machines, run on this one: a hostfile
# of localhost slots, 4 ranks over shared memory and over TCP on loopback,
# each image compared byte for byte with the one-process render; then how
# much CPU a rank uses while it only waits (rank 1 while rank 0 builds the
# Tetra10 database), bounded. Exits non-zero on any difference or failure.
#
# usage: scripts/mpi-check.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
vmpray=$(realpath "${1:-build/release}/app/vmpray")
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
echo "localhost slots=4" >hosts

"$vmpray" teapot --topology hypercube:6 -q -o one.png
for btl in "self,vader" "self,tcp --mca btl_tcp_if_include lo"; do
  # shellcheck disable=SC2086  # the MCA options are words
  timeout -k 10 300 mpirun --hostfile hosts -np 4 --mca btl $btl "$vmpray" teapot --topology hypercube:6 -o four.png \
    >summary.txt
  cmp one.png four.png
  grep '^ranks' summary.txt
  echo "mpi-check: 4 ranks over ${btl%% *}: image identical to one process"
done

# CPU of a waiting rank: rank 1 waits for its pages while rank 0 reads and
# builds the scene, then renders a tiny frame. A rank that only waits must
# sleep: its CPU time (user + system, its start, its pages and its pixels
# included) at most half its wall time (a rank that spun while waiting
# would use about as much CPU as wall time). Quiet, it uses a quarter; with
# another program busy on the cores up to a third, as MPI's own progress
# spins through a page transfer that a slowed rank 0 stretches.
# The run's whole output is kept, and shown if it fails or lacks a time.
if ! timeout -k 10 300 mpirun -np 2 --oversubscribe --mca btl self,vader \
  sh -c 'exec /usr/bin/time -f "rank $OMPI_COMM_WORLD_RANK: %e s wall, %U s user, %S s system" "$0" "$@"' \
  "$vmpray" tetra10 --width 16 --height 16 --topology hypercube:1 -q -o tetra.png >waiting.txt 2>&1; then
  cat waiting.txt >&2
  echo "mpi-check: the run of a waiting rank failed (its output above)" >&2
  exit 1
fi
grep '^rank' waiting.txt || true
python3 - waiting.txt <<'CHECK'
import re, sys
ranks = {}
text = open(sys.argv[1]).read()
for line in text.splitlines():
    m = re.match(r"rank (\d+): ([\d.]+) s wall, ([\d.]+) s user, ([\d.]+) s system", line)
    if m:
        ranks[int(m[1])] = (float(m[2]), float(m[3]) + float(m[4]))
if set(ranks) != {0, 1}:
    sys.exit(text + "mpi-check: expected the times of ranks 0 and 1, got " + repr(sorted(ranks)))
(wall0, cpu0), (wall1, cpu1) = ranks[0], ranks[1]
if cpu1 > wall1 / 2:
    sys.exit(f"mpi-check: the waiting rank used {cpu1:.2f} s of CPU in {wall1:.2f} s, rank 0 {cpu0:.2f} s: it did not sleep")
print(f"mpi-check: the waiting rank used {cpu1:.2f} s of CPU in {wall1:.2f} s (rank 0: {cpu0:.2f} s)")
CHECK
