#!/usr/bin/env bash
# A cluster in a box: vmpray over MPI across hosts that are really separate,
# on one computer. Each host is a network namespace with an address of its
# own on a private bridge; mpirun starts its daemons there through a small
# launch agent (in place of ssh), and the TCP transport and the launcher's
# own channel are held to the bridge, so ranks talk over the veth links, not
# over loopback or shared memory. It checks:
#  - images identical to one process for 2, 3 and 4 hosts on hypercube,
#    torus and ring, with the bytes the ranks sent seen on the veth links;
#  - a replay recorded on 3 hosts counts what one process counts, under
#    the static schedule, and shows the packets that crossed hosts;
#  - a host whose processes are all killed mid-run, and a rank killed alone,
#    end the job within 10 s, non-zero, with no output file, and the
#    launcher's message names the lost host or rank.
# Every namespace, link and bridge it made is removed at the end, whatever
# happened. Needs root, `ip` and `unshare`; without them it says so and
# skips (exit 0), unless --require is given (CI gives it): then exit 1.
# With --bench ROUNDS SIZE it instead times two ranks across two hosts'
# veth links beside two ranks over TCP on loopback and over shared memory
# (teapot and rings4, hypercube:4 and :6, SIZE x SIZE, ROUNDS interleaved
# rounds; medians of the render's wall time, images checked equal).
#
# usage: scripts/cluster-check.sh [--require] [--bench ROUNDS SIZE] [BUILD_DIR]
#        (default build/release)
set -euo pipefail
require=0 bench_rounds=0 bench_size=0
while [[ ${1:-} == --* ]]; do
  case $1 in
    --require) require=1; shift ;;
    --bench) bench_rounds=${2:?--bench ROUNDS SIZE}; bench_size=${3:?--bench ROUNDS SIZE}; shift 3 ;;
    *) echo "usage: scripts/cluster-check.sh [--require] [--bench ROUNDS SIZE] [BUILD_DIR]" >&2; exit 2 ;;
  esac
done
vmpray=$(realpath "${1:-build/release}/app/vmpray")

skip() {
  echo "cluster-check: skipped: $1" >&2
  if ((require)); then exit 1; fi
  exit 0
}
[[ $(id -u) == 0 ]] || skip "making network namespaces needs root"
for tool in ip unshare mpirun; do command -v "$tool" >/dev/null || skip "no '$tool' on this machine"; done
[[ -x $vmpray ]] || { echo "cluster-check: no vmpray at $vmpray" >&2; exit 2; }

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
hosts_max=4
tag="vmc$$"  # names of this run's namespaces and links (at most 15 characters)
work=$(mktemp -d)

# A /24 that no route of this machine uses yet.
subnet=""
for third in 213 214 215 216 217; do
  if ! ip -4 route show | grep -q "^10\.$third\.77\."; then
    subnet="10.$third.77"
    break
  fi
done
[[ -n $subnet ]] || skip "no free private subnet among 10.213-217.77.0/24"

cleanup() {
  local h pid
  for ((h = 1; h <= hosts_max; ++h)); do
    if ip netns list | grep -q "^$tag-h$h\b"; then
      for pid in $(ip netns pids "$tag-h$h" 2>/dev/null); do kill -9 "$pid" 2>/dev/null || true; done
      ip netns del "$tag-h$h" 2>/dev/null || true
    fi
  done
  ip link del "$tag-br" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Host h (1..hosts_max) is namespace $tag-h$h at $subnet.(h+1), its eth0 the
# far end of veth $tag-v$h, whose near end is on the bridge at $subnet.1.
ip link add "$tag-br" type bridge
ip addr add "$subnet.1/24" dev "$tag-br"
ip link set "$tag-br" up
for ((h = 1; h <= hosts_max; ++h)); do
  ns="$tag-h$h"
  ip netns add "$ns"
  ip link add "$tag-v$h" type veth peer name eth0 netns "$ns"
  ip link set "$tag-v$h" master "$tag-br" up
  ip -n "$ns" addr add "$subnet.$((h + 1))/24" dev eth0
  ip -n "$ns" link set eth0 up
  ip -n "$ns" link set lo up
done

# The launch agent mpirun calls as `agent HOST COMMAND`: the command runs in
# the host's namespace, under a host name of its own (Open MPI keys its
# session folders and its idea of "same node" on the host name).
cat >"$work/agent" <<EOF
#!/bin/sh
host=\$1
shift
ns=$tag-h\$((\${host##*.} - 1))
exec ip netns exec "\$ns" unshare --uts sh -c 'hostname "\$0" && exec sh -c "\$1"' "\$ns" "\$*"
EOF
chmod +x "$work/agent"
cd "$work"

# on_hosts N: sets `launch` to an mpirun with one rank on each of hosts 1..N.
on_hosts() {
  local n=$1 h
  : >"hosts$n"
  for ((h = 1; h <= n; ++h)); do echo "$subnet.$((h + 1)) slots=1" >>"hosts$n"; done
  # shellcheck disable=SC2054  # the commas are inside MCA values
  launch=(timeout -k 5 120 mpirun --hostfile "hosts$n" -np "$n" --bind-to none --mca plm_rsh_agent "$work/agent"
    --mca plm_rsh_no_tree_spawn 1 --mca oob_tcp_if_include "$subnet.0/24"
    --mca btl self,tcp --mca btl_tcp_if_include "$subnet.0/24")
}

# Bytes the hosts sent into the bridge so far (the near ends' receive counts).
veth_bytes() {
  local h total=0
  for ((h = 1; h <= hosts_max; ++h)); do total=$((total + $(cat "/sys/class/net/$tag-v$h/statistics/rx_bytes"))); done
  echo "$total"
}
# wire_bytes STATS: what the ranks' transports sent, summed.
wire_bytes() {
  python3 -c 'import json, sys; print(sum(r["wire_bytes_sent"] for r in json.load(open(sys.argv[1]))["machine"]["ranks"]))' "$1"
}

# bench: each configuration's render wall time, interleaved rounds, medians.
bench() {
  local scene topology round c med
  local -a configs=(shared loopback veth)
  printf '%-8s %-12s %-26s %9s %8s %10s\n' scene topology "2 ranks x 1 thread" median_s ratio msg/packet
  for scene in teapot rings4; do
    for topology in hypercube:4 hypercube:6; do
      declare -A times=() ratio_of=()
      for ((round = 0; round < bench_rounds; ++round)); do
        for c in "${configs[@]}"; do
          local args=("$vmpray" "$scene" --topology "$topology" --width "$bench_size" --height "$bench_size" --threads 1 -q
            -o "$c.png" --stats "$c.json")
          case $c in
            veth) on_hosts 2; "${launch[@]}" "${args[@]}" ;;
            loopback) mpirun -np 2 --mca btl self,tcp --mca btl_tcp_if_include lo "${args[@]}" ;;
            shared) OMPI_MCA_btl_vader_single_copy_mechanism=none mpirun -np 2 --mca btl self,vader "${args[@]}" ;;
          esac
          times[$c]+="$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["machine"]["wall_seconds"])' "$c.json") "
        done
        cmp -s veth.png loopback.png && cmp -s veth.png shared.png ||
          { echo "cluster-check: $scene $topology: images differ between transports" >&2; exit 1; }
      done
      for c in "${configs[@]}"; do
        med=$(tr ' ' '\n' <<<"${times[$c]}" | sed '/^$/d' | sort -g | sed -n "$(((bench_rounds + 1) / 2))p")
        ratio_of[$c]=$med
        printf '%-8s %-12s %-26s %9.3f %8.2f %10.2f\n' "$scene" "$topology" "$c" "$med" \
          "$(python3 -c 'import sys; print(float(sys.argv[1]) / float(sys.argv[2]))' "$med" "${ratio_of[shared]:-$med}")" \
          "$(python3 -c 'import json,sys; r=json.load(open(sys.argv[1]))["machine"]["ranks"]; print(sum(x["messages_sent"] for x in r) / max(1, sum(x["packets_sent"] for x in r)))' "$c.json")"
      done
      unset times ratio_of
    done
  done
}
if ((bench_rounds > 0)); then
  bench
  exit 0
fi

size=96
for topology in hypercube:4 torus:4x4 ring:16; do
  "$vmpray" teapot --topology "$topology" --width $size --height $size -q -o one.png
  for n in 2 3 4; do
    before=$(veth_bytes)
    on_hosts "$n"
    "${launch[@]}" "$vmpray" teapot --topology "$topology" --width $size --height $size \
      -q -o many.png --stats many.json
    sent=$(wire_bytes many.json)
    carried=$(($(veth_bytes) - before))
    if ! cmp -s one.png many.png; then
      echo "cluster-check: $topology on $n hosts: image differs from one process" >&2
      exit 1
    fi
    if ((sent == 0 || carried < sent)); then
      echo "cluster-check: $topology on $n hosts: ranks sent $sent bytes but the veth links carried $carried" >&2
      exit 1
    fi
    echo "cluster-check: $topology on $n hosts: image identical to one process; $sent bytes over MPI, $carried on the veth links"
  done
done

# replay_counts PAGE: what a replay page recorded, as one line: packets,
# hops, packets by kind, the totals, packets never recorded, the ranks its
# nodes ran on, and how many recorded packets crossed from rank to rank.
replay_counts() {
  python3 - "$1" <<'PY'
import collections, json, re, sys
page = open(sys.argv[1], encoding="utf-8").read()
d = json.loads(re.search(r'<script type="application/json" id="replay-data">(.*?)</script>', page, re.S).group(1))
p, ranks = d["packets"], d["ranks"] or [0] * d["nodes"]
routes, at = [], 0
for h in p["hops"]:
    routes.append(p["route"][at:at + h + 1])
    at += h + 1
crossed = sum(any(ranks[a] != ranks[b] for a, b in zip(r, r[1:])) for r in routes)
print(len(p["hops"]), sum(p["hops"]), sorted(collections.Counter(p["kind"]).items()), d["totals"],
      d["unrecorded"]["packets"], "|", sorted(set(ranks)), crossed)
PY
}

# A replay recorded across 3 hosts counts what one process counts under
# the static schedule (the same packets of each kind, hops and totals, none
# left unrecorded), shows each node's rank, and has packets that crossed.
replay_args=(teapot --topology hypercube:4 --width 48 --height 48 --schedule static -q)
"$vmpray" "${replay_args[@]}" -o one.png --replay one.html
on_hosts 3
"${launch[@]}" "$vmpray" "${replay_args[@]}" -o many.png --replay many.html
one=$(replay_counts one.html)
many=$(replay_counts many.html)
if [[ ${one%%|*} != "${many%%|*}" || ${many##*|} != " [0, 1, 2] "* || ${many##* } == 0 ]]; then
  echo "cluster-check: a replay recorded on 3 hosts: $many; in one process: $one" >&2
  exit 1
fi
echo "cluster-check: a replay recorded on 3 hosts counts what one process counts (${one%%|*}); ${many##* } packets crossed hosts"

# lose WHAT: starts a long render on 3 hosts, waits until host 2 runs its
# rank, kills the host's every process (WHAT=host) or its rank alone
# (WHAT=rank), and checks how the job ends.
lose() {
  local what=$1 ns="$tag-h2" pid rc=0 seconds lost failed=""
  rm -f out.png
  on_hosts 3
  "${launch[@]}" "$vmpray" teapot:6 --width 1024 --height 1024 -q -o out.png >lose.out 2>lose.err &
  local job=$!
  for ((tries = 0; tries < 300; ++tries)); do
    pid=""
    for p in $(ip netns pids "$ns"); do [[ $(cat "/proc/$p/comm" 2>/dev/null) == vmpray ]] && pid=$p; done
    [[ -n $pid ]] && break
    sleep 0.1
  done
  [[ -n $pid ]] || { echo "cluster-check: host 2 never ran its rank" >&2; exit 1; }
  sleep 1
  lost=$(date +%s.%N)
  if [[ $what == host ]]; then
    for p in $(ip netns pids "$ns"); do kill -9 "$p" 2>/dev/null || true; done
  else
    kill -9 "$pid"
  fi
  wait "$job" || rc=$?
  seconds=$(python3 -c "import sys; print(f'{float(sys.argv[1]) - float(sys.argv[2]):.1f}')" "$(date +%s.%N)" "$lost")
  ((rc != 0)) || failed="the job exited 0"
  python3 -c 'import sys; sys.exit(float(sys.argv[1]) > 10)' "$seconds" || failed="the job took $seconds s to end"
  [[ ! -e out.png ]] || failed="an output file was written"
  grep -Eq "rank 1 |$subnet\.3" lose.err || failed="no message names the lost rank or host"
  if [[ -n $failed ]]; then
    echo "cluster-check: $what lost mid-run: $failed" >&2
    cat lose.err >&2
    exit 1
  fi
  echo "cluster-check: $what lost mid-run: the job ended $seconds s later, exit $rc, no output; the launcher says:"
  grep -E "rank 1 |$subnet\.3" lose.err | head -2 | sed 's/^ */  /'
}
lose host
lose rank
echo "cluster-check: passed"
