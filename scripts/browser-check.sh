#!/usr/bin/env bash
# Opens the HTML pages vmpray writes (a render's --report page, a sweep's
# page and a --replay page) in headless Chromium with the network cut off, and fails unless each
# page loads, fetches nothing (no resource but data: URLs), shows every image
# decoded and not blank, has its tables and SVG figures, raises no script
# error, and screenshots to something that is not blank. The replay page
# must also step, and its counters at its end must equal the same run's
# --stats (packets, hops, page misses, pixels); so must a replay recorded
# over two MPI ranks, when mpirun is installed.
#
# The page is opened inside a checking page (scripts/browser-check.html)
# whose script inspects it once it has loaded and writes one line, PASS or
# FAIL, that --dump-dom prints.
#
# usage: scripts/browser-check.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:-build/release}" && pwd)
vmpray=$build/app/vmpray
browser=$(command -v chromium || command -v chromium-browser || true)
[[ -x "$vmpray" ]] || { echo "browser-check: no $vmpray; build first" >&2; exit 1; }
[[ -n "$browser" ]] || { echo "browser-check: chromium is not installed (scripts/install-deps.sh --dev)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Chromium as root needs --no-sandbox; the resolver and proxy rules leave it
# no way to reach a network, so a page that needed one would fail to load.
run_browser() {
  timeout 120 "$browser" --headless=new --no-sandbox --disable-gpu --no-first-run --disable-extensions \
    --host-resolver-rules='MAP * ~NOTFOUND' --proxy-server='127.0.0.1:9' --allow-file-access-from-files \
    --enable-logging=stderr --v=0 --user-data-dir="$work/profile" "$@"
}

# check PAGE IMAGES SVGS TABLES [REPLAY]: the page and the least it must
# hold; REPLAY: the counters a replay page must end with.
check() {
  local page=$1 images=$2 svgs=$3 tables=$4 replay=${5:-} name
  name=$(basename "$page" .html)
  local query="page=$(basename "$page")&images=$images&svgs=$svgs&tables=$tables"
  [[ -n "$replay" ]] && query+="&replay=$replay"
  cp "$here/browser-check.html" "$(dirname "$page")/check-$name.html"
  run_browser --virtual-time-budget=10000 --dump-dom "file://$(dirname "$page")/check-$name.html?$query" \
    >"$work/$name.dom" 2>"$work/$name.log" || true
  local verdict
  verdict=$(grep -o 'id="verdict">BROWSER-CHECK [^<]*' "$work/$name.dom" | sed 's/^id="verdict">//' ||
    echo "BROWSER-CHECK FAIL no verdict: the checking page did not run")
  if grep -q 'Uncaught' "$work/$name.log"; then
    verdict="BROWSER-CHECK FAIL script error: $(grep -m1 'Uncaught' "$work/$name.log")"
  fi
  run_browser --screenshot="$work/$name.png" --window-size=1280,1600 "file://$page" >/dev/null 2>&1 || true
  if ! python3 "$here/png-not-blank.py" "$work/$name.png"; then
    verdict="BROWSER-CHECK FAIL the screenshot of $name is blank or missing"
  fi
  echo "$name: ${verdict#BROWSER-CHECK }"
  [[ "$verdict" == "BROWSER-CHECK PASS"* ]]
}

cd "$work"
"$vmpray" teapot --width 128 --height 128 --topology mesh:4x4 -q -o teapot.png --report "$work/run.html"
"$vmpray" sweep nodes --scene teapot:2 --size 16 --nodes 1,2,4 --topology hypercube,ring -q --out "$work/sweep"
"$vmpray" teapot --width 96 --height 96 --topology torus:4x2 --timing virtual -q -o replay.png \
  --replay "$work/replay.html" --stats "$work/replay.json"
# A bounded replay: most packets, waits and serves only counted.
"$vmpray" teapot --width 64 --height 64 --topology hypercube:3 --cache-pages 2 -q -o bounded.png \
  --replay "$work/bounded.html" --replay-packets 30 --stats "$work/bounded.json"
# The run's own figures, as the page's counters must end: packets, hops, misses, pixels.
stats_of() {
  python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))["machine"]
n = m["network"]
print(",".join(str(v) for v in (n["packets"], round(n["packets"] * n["mean_hops"]), m["svm"]["misses"],
                                sum(x["pixels"] for x in m["per_node"]))))' "$1"
}
replay_stats=$(stats_of "$work/replay.json")
# A replay recorded over two MPI ranks, when Open MPI is installed (CI has it).
mpi_replay=""
if command -v mpirun >/dev/null; then
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none \
    timeout -k 10 120 mpirun -np 2 --oversubscribe --mca btl self,vader "$vmpray" teapot --width 64 --height 64 \
    --topology hypercube:3 -q -o ranks.png --replay "$work/ranks.html" --stats "$work/ranks.json"
  mpi_replay=$(stats_of "$work/ranks.json")
fi

status=0
check "$work/run.html" 2 2 3 || status=1
check "$work/sweep/nodes.html" 0 1 1 || status=1
check "$work/replay.html" 0 0 0 "$replay_stats" || status=1
check "$work/bounded.html" 0 0 0 "$(stats_of "$work/bounded.json")" || status=1
[[ -z "$mpi_replay" ]] || check "$work/ranks.html" 0 0 0 "$mpi_replay" || status=1

# The check itself must catch what it is for: each of these pages fails it.
mkdir "$work/bad"
sed 's|<img src="[^"]*"|<img src="http://example.invalid/x.png"|' "$work/run.html" >"$work/bad/fetches.html"
sed 's|</body>|<script>undefined_function();</script></body>|' "$work/run.html" >"$work/bad/throws.html"
printf '<!DOCTYPE html><html><head><title>x</title></head><body><p> </p></body></html>\n' >"$work/bad/blank.html"
# So must a replay whose counters end one packet short of the stats it is held to.
cp "$work/replay.html" "$work/bad/miscounts.html"
# And a replay that never becomes ready: its checks never settle, so no PASS.
sed 's|const ready = Promise.all(|const ready = new Promise(() => {}), decoded = Promise.all(|' "$work/replay.html" \
  >"$work/bad/hangs.html"
cmp -s "$work/replay.html" "$work/bad/hangs.html" && { echo "browser-check: cannot make the hanging replay" >&2; exit 1; }
for bad in fetches throws blank miscounts hangs; do
  least=(2 2 3) expect=""
  [[ $bad == miscounts ]] && least=(0 0 0) expect=$(awk -F, -v OFS=, '{ $1 += 1; print }' <<<"$replay_stats")
  [[ $bad == hangs ]] && least=(0 0 0) expect=$replay_stats
  if check "$work/bad/$bad.html" "${least[@]}" "$expect" 2>/dev/null; then
    echo "browser-check: the page that $bad passed the check" >&2
    status=1
  fi
done
((status == 0)) && echo "browser-check: the check fails a page that fetches, throws, is blank, miscounts or never settles"
exit $status
