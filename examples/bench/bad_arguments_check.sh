#!/usr/bin/env bash
# Every benchmark answers a bad argument with one line naming it, then its
# usage, and exit 2; an error after the arguments are read with one line
# and exit 1; --help with the usage on standard output and exit 0. Never an
# abort. Run by ctest (bench.BadArgumentsGetOneLineTheUsageAndExit2).
#
# usage: examples/bench/bad_arguments_check.sh BENCH_DIR
set -uo pipefail
dir=${1:?usage: bad_arguments_check.sh BENCH_DIR}
failed=0
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

# expect RC PROGRAM ARGS...: exit RC, a first stderr line naming PROGRAM, a
# usage after it when RC is 2, nothing on standard output.
expect() {
  local want=$1 program=$2
  shift 2
  if [[ ! -x "$dir/$program" ]]; then
    echo "not built: $dir/$program"
    failed=1
    return
  fi
  timeout 60 "$dir/$program" "$@" >"$scratch/out" 2>"$scratch/err"
  local rc=$?
  local first
  first=$(head -n 1 "$scratch/err")
  if [[ $rc -ne $want || $first != "$program: "* || -s "$scratch/out" ]] ||
     [[ $want -eq 2 && $(sed -n 2p "$scratch/err") != usage:* ]] ||
     [[ $want -eq 1 && $(wc -l <"$scratch/err") -ne 1 ]]; then
    echo "FAIL: $program $* -> exit $rc (want $want); stderr: $(head -c 300 "$scratch/err")"
    failed=1
  fi
}

for program in tracer_bench nff_bench build_bench machine_bench packet_bench network_bench scaling_bench; do
  if [[ -x "$dir/$program" ]] && ! "$dir/$program" --help | head -n 1 | grep -q '^usage: '; then
    echo "FAIL: $program --help prints no usage"
    failed=1
  fi
done
expect 2 machine_bench nosuch
expect 2 machine_bench teapot abc
expect 2 machine_bench teapot -5
expect 2 nff_bench nosuch
expect 2 nff_bench teapot abc
expect 2 tracer_bench nosuch
expect 2 tracer_bench --density -1
expect 2 build_bench 0 abc
expect 2 build_bench -1
expect 2 packet_bench 0
expect 2 network_bench abc
expect 2 scaling_bench teapot:3
expect 2 scaling_bench teapot:16 2,1
expect 2 scaling_bench teapot:16:a2
expect 1 nff_bench --read /nonexistent

# many_cores.sh, a script beside this one: the same rules, for a missing or
# wrong DIR, before it runs anything.
script=$(dirname "$0")/many_cores.sh
for args in "" "$scratch/nosuch" "$scratch"; do
  # shellcheck disable=SC2086 # "" is no argument at all
  bash "$script" $args >"$scratch/out" 2>"$scratch/err"
  rc=$?
  if [[ $rc -ne 2 || $(head -n 1 "$scratch/err") != "many_cores.sh: "* || $(sed -n 2p "$scratch/err") != usage:* ||
        -s "$scratch/out" ]]; then
    echo "FAIL: many_cores.sh $args -> exit $rc (want 2); stderr: $(head -c 300 "$scratch/err")"
    failed=1
  fi
done
if ! bash "$script" --help | head -n 1 | grep -q '^usage: '; then
  echo "FAIL: many_cores.sh --help prints no usage"
  failed=1
fi
exit $failed
