#!/usr/bin/env bash
# Runs the NFF parser fuzzer for a bounded time, seeded from the checked-in
# corpus (tracer/fuzz/corpus, left untouched: new inputs go to a scratch
# directory). Exits non-zero if the fuzzer finds a crash; the reproducer is
# kept in the scratch directory, whose path is printed.
# Usage: tracer/fuzz/run.sh BINARY SECONDS
set -euo pipefail
if [[ $# -ne 2 || ! -x "$1" || ! "$2" =~ ^[0-9]+$ ]]; then
  echo "usage: $0 FUZZER_BINARY SECONDS" >&2
  exit 2
fi
binary=$1
seconds=$2
seeds="$(cd "$(dirname "$0")" && pwd)/corpus"
work=$(mktemp -d "${TMPDIR:-/tmp}/nff_fuzz.XXXXXX")
mkdir -p "$work/corpus" "$work/artifacts"
echo "nff fuzzer: ${seconds}s, seeds $seeds, scratch $work"
status=0
timeout $((seconds + 60)) "$binary" -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 \
  -timeout=10 -print_final_stats=1 -artifact_prefix="$work/artifacts/" "$work/corpus" "$seeds" \
  >"$work/log" 2>&1 || status=$?
tail -n 15 "$work/log"
if [[ $status -ne 0 ]]; then
  echo "nff fuzzer: FAILED (exit $status); reproducers in $work/artifacts" >&2
  exit "$status"
fi
echo "nff fuzzer: no crash in ${seconds}s"
rm -rf "$work"
