// The replay page's script (see app/experiments/replay.hpp), inlined into the page at
// build time (app/CMakeLists.txt, cmake/embed_text.cmake) so the page needs
// no file beside it and vmpray reads no file to write it; this opening
// comment is left out of the page, the rest goes in as it is.
// The script reads the JSON of #replay-data, draws the run at a time t on a
// canvas over the machine's SVG (node places come from the machine picture,
// in its user units) and on a canvas of the frame, and exposes
// window.vmprayReplay for scripted checks: stepToEnd() and counters()
// (packets delivered, hops, misses, pixels), and over MPI ranks how many
// ranks ran the machine and how many recorded packets crossed between them.
// Cost: a frame walks the packets injected by t and the hops left by t, so a
// recording of 36 000 packets draws in a few milliseconds.

"use strict";
(function () {
const D = JSON.parse(document.getElementById("replay-data").textContent);
const N = D.nodes, END = D.end, TICK = D.tick;
const KIND_COLOURS = ["#000000", "#1f77b4", "#2ca02c", "#7f7f7f", "#9467bd", "#ff7f0e", "#d62728", "#8c564b",
                      "#e377c2", "#17becf"];
const STATE = {idle: "#c8c8c8", tracing: "#2ca02c", waiting: "#d62728", serving: "#1f77b4"};
const $ = (id) => document.getElementById(id);

// ---- The data, decoded once ----
const P = D.packets, count = P.kind.length;
const routeStart = new Int32Array(count + 1);
for (let i = 0, r = 0; i <= count; ++i) { routeStart[i] = r; if (i < count) r += P.hops[i] + 1; }
const T = new Float64Array(2 * routeStart[count]);  // absolute ticks, 2 per route node
for (let i = 0; i < count; ++i) {
  const k = 2 * routeStart[i], n = 2 * (P.hops[i] + 1);
  T[k] = P.times[k];
  for (let j = 1; j < n; ++j) T[k + j] = T[k + j - 1] + P.times[k + j];
}
const injected = (i) => T[2 * routeStart[i]];
const delivered = (i) => T[2 * routeStart[i + 1] - 1];
const departs = (i, h) => T[2 * routeStart[i] + 1 + 2 * h];
const arrives = (i, h) => T[2 * routeStart[i] + 2 + 2 * h];
const node = (i, h) => P.route[routeStart[i] + h];
// Over several MPI ranks, the rank of each node, and which packets crossed
// between ranks (a hop whose ends ran on different ranks).
const RANK = D.ranks && D.ranks.length === N ? D.ranks : null;
const RANKS = RANK ? Math.max(...RANK) + 1 : 1;
const betweenRanks = (a, b) => RANK !== null && RANK[a] !== RANK[b];
const crossed = new Uint8Array(count);
for (let i = 0; i < count; ++i)
  for (let h = 0; h < P.hops[i]; ++h) if (betweenRanks(node(i, h), node(i, h + 1))) crossed[i] = 1;
const crossedCount = crossed.reduce((a, b) => a + b, 0);

function sorted(values) { const a = Float64Array.from(values); a.sort(); return a; }
// How many of the sorted values are at most t.
function upTo(a, t) {
  let lo = 0, hi = a.length;
  while (lo < hi) { const mid = (lo + hi) >> 1; if (a[mid] <= t) lo = mid + 1; else hi = mid; }
  return lo;
}
const deliveries = sorted(Array.from({length: count}, (_, i) => delivered(i)));
const linkIndex = new Map();
D.links.forEach(([a, b], k) => linkIndex.set(a * N + b, k));
const hopDepart = [], hopArrive = [], hopLink = [];
for (let i = 0; i < count; ++i)
  for (let h = 0; h < P.hops[i]; ++h) {
    hopDepart.push(departs(i, h));
    hopArrive.push(arrives(i, h));
    hopLink.push(linkIndex.get(node(i, h) * N + node(i, h + 1)));
  }
const arrivals = sorted(hopArrive);
const hopOrder = Array.from(hopDepart.keys()).sort((a, b) => hopDepart[a] - hopDepart[b]);
const finalLoad = new Float64Array(D.links.length);
for (const l of hopLink) finalLoad[l] += 1;
const maxLoad = Math.max(1, ...finalLoad);
const misses = sorted(D.fetches.start);
const tileEnds = Float64Array.from(D.tiles.end);  // tiles come in the order they ended
const pixelsBefore = new Float64Array(tileEnds.length + 1);
D.tiles.count.forEach((c, k) => { pixelsBefore[k + 1] = pixelsBefore[k] + c; });
// Every moment something happens to a packet, once each: what the step buttons visit.
const events = (() => {
  const out = [0];
  for (const v of Float64Array.from(T).sort()) if (v !== out[out.length - 1]) out.push(v);
  if (out[out.length - 1] !== END) out.push(END);
  return Float64Array.from(out);
})();

// Per node and worker: the tiles and the waits, as sorted intervals.
function intervals(starts, ends, keys, key) {
  const s = [], e = [];
  for (let k = 0; k < starts.length; ++k) if (keys(k) === key) { s.push(starts[k]); e.push(ends[k]); }
  const order = Array.from(s.keys()).sort((a, b) => s[a] - s[b]);
  return {start: Float64Array.from(order, (k) => s[k]), end: Float64Array.from(order, (k) => e[k])};
}
function within(iv, t) {
  const k = upTo(iv.start, t) - 1;
  return k >= 0 && iv.end[k] > t;
}
const W = D.workers;
const tracing = [], waiting = [], serving = [];
for (let n = 0; n < N; ++n) {
  tracing.push([]);
  waiting.push([]);
  for (let w = 0; w < W; ++w) {
    tracing[n].push(intervals(D.tiles.start, D.tiles.end, (k) => D.tiles.node[k] * W + D.tiles.worker[k], n * W + w));
    waiting[n].push(intervals(D.fetches.start, D.fetches.end, (k) => D.fetches.node[k] * W + D.fetches.worker[k],
                              n * W + w));
  }
  serving.push(intervals(D.serves.start, D.serves.end, (k) => D.serves.node[k], n));
}

// ---- Time and counters ----
let t = 0, playing = false, speed = 1, lastFrame = null;
function counters(at = t) {
  const done = at >= END;
  return {
    packets: upTo(deliveries, at) + (done ? D.unrecorded.packets : 0),
    hops: upTo(arrivals, at) + (done ? D.unrecorded.hops : 0),
    misses: upTo(misses, at) + (done ? D.unrecorded.fetches : 0),
    pixels: pixelsBefore[upTo(tileEnds, at)],
  };
}
function seconds(ticks) { return ticks * TICK; }
// A duration to three significant digits, for labels that only compare.
function brief(ticks) {
  const s = seconds(ticks);
  for (const [unit, per] of [["s", 1], ["ms", 1e-3], ["\u00b5s", 1e-6]])
    if (s >= per) return Number((s / per).toPrecision(3)) + " " + unit;
  return Number((s * 1e9).toPrecision(3)) + " ns";
}
function format(ticks) {
  const s = seconds(ticks);
  if (s >= 60) return Math.floor(s / 60) + " min " + (s % 60).toFixed(1) + " s";
  if (s >= 1) return s.toFixed(3) + " s";
  if (s >= 1e-3) return (s * 1e3).toFixed(3) + " ms";
  if (s >= 1e-6) return (s * 1e6).toFixed(1) + " \u00b5s";
  return (s * 1e9).toFixed(0) + " ns";
}

// ---- The machine ----
const svg = document.querySelector("#stage svg");
const overlay = $("overlay"), g = overlay.getContext("2d");
const view = svg.viewBox && svg.viewBox.baseVal && svg.viewBox.baseVal.width ? svg.viewBox.baseVal
                                                                             : {width: svg.width.baseVal.value,
                                                                                height: svg.height.baseVal.value};
// The picture's legend below the nodes speaks of the run's totals, all zero on
// this stage: cut the picture under the lowest node instead (the page has its own legend).
(() => {
  const bottom = Math.max(...D.places.map(([, y, r]) => y + 1.6 * r)) + 0.04 * view.width;
  if (bottom < view.height) {
    svg.setAttribute("viewBox", `0 0 ${view.width} ${bottom}`);
    svg.removeAttribute("height");
  }
})();
let scale = 1;
function fit() {
  const box = svg.getBoundingClientRect();
  const ratio = window.devicePixelRatio || 1;
  overlay.style.width = box.width + "px";
  overlay.style.height = box.height + "px";
  overlay.width = Math.max(1, Math.round(box.width * ratio));
  overlay.height = Math.max(1, Math.round(box.height * ratio));
  scale = (box.width / view.width) * ratio;
}
const dots = [];  // where each packet in flight was drawn: [x, y, packet]
function drawMachine() {
  g.setTransform(1, 0, 0, 1, 0, 0);
  g.clearRect(0, 0, overlay.width, overlay.height);
  g.setTransform(scale, 0, 0, scale, 0, 0);
  // Links: every hop left by t adds to its link's load.
  const load = new Float64Array(D.links.length);
  for (const k of hopOrder) { if (hopDepart[k] > t) break; load[hopLink[k]] += 1; }
  D.links.forEach(([a, b], k) => {
    if (!load[k]) return;
    const [ax, ay, ar] = D.places[a], [bx, by, br] = D.places[b];
    const len = Math.hypot(bx - ax, by - ay) || 1, ux = (bx - ax) / len, uy = (by - ay) / len;
    const ox = uy * 2.5, oy = -ux * 2.5;
    // From ring to ring, as the static picture draws it: never over a node's number.
    const from = ar * 1.5, to = len - br * 1.5;
    if (to <= from) return;
    const share = load[k] / maxLoad;
    g.strokeStyle = `rgba(230, 120, 0, ${0.25 + 0.75 * share})`;
    g.lineWidth = 1 + 5 * share;
    g.setLineDash(betweenRanks(a, b) ? [6, 4] : []);
    g.beginPath();
    g.moveTo(ax + ux * from + ox, ay + uy * from + oy);
    g.lineTo(ax + ux * to + ox, ay + uy * to + oy);
    g.stroke();
  });
  g.setLineDash([]);
  // Nodes: one arc per pixel computer (tracing, waiting for a page, idle), a
  // blue outer ring while its page server serves.
  for (let n = 0; n < N; ++n) {
    const [x, y, r] = D.places[n];
    for (let w = 0; w < W; ++w) {
      const state = within(waiting[n][w], t) ? "waiting" : within(tracing[n][w], t) ? "tracing" : "idle";
      g.strokeStyle = STATE[state];
      g.lineWidth = Math.max(2, r * 0.28);
      g.beginPath();
      const a0 = -Math.PI / 2 + (2 * Math.PI * w) / W, a1 = -Math.PI / 2 + (2 * Math.PI * (w + 1)) / W;
      g.arc(x, y, r * 1.12, a0 + (W > 1 ? 0.06 : 0), a1 - (W > 1 ? 0.06 : 0));
      g.stroke();
    }
    if (within(serving[n], t)) {
      g.strokeStyle = STATE.serving;
      g.lineWidth = Math.max(1.5, r * 0.14);
      g.beginPath();
      g.arc(x, y, r * 1.42, 0, 2 * Math.PI);
      g.stroke();
    }
  }
  // Packets: on a link between its departure and arrival, else queued at a node.
  dots.length = 0;
  for (let i = 0; i < count && injected(i) <= t; ++i) {
    if (delivered(i) <= t) continue;
    let x, y;
    const hops = P.hops[i];
    let h = 0;
    while (h < hops && arrives(i, h) <= t) ++h;
    const [px, py, pr] = D.places[node(i, h)];
    if (h < hops && departs(i, h) <= t) {
      const [qx, qy] = D.places[node(i, h + 1)];
      const f = (t - departs(i, h)) / Math.max(1e-12, arrives(i, h) - departs(i, h));
      const len = Math.hypot(qx - px, qy - py) || 1, ox = (qy - py) / len * 2.5, oy = -(qx - px) / len * 2.5;
      x = px + (qx - px) * f + ox;
      y = py + (qy - py) * f + oy;
    } else {
      const a = (P.id[i] % 16) * (Math.PI / 8);
      x = px + Math.cos(a) * pr * 0.6;
      y = py + Math.sin(a) * pr * 0.6;
    }
    g.fillStyle = KIND_COLOURS[P.kind[i]] || "#000";
    g.strokeStyle = crossed[i] ? "#000000" : "#ffffff";
    g.lineWidth = crossed[i] ? 1.8 : 1.2;
    g.beginPath();
    g.arc(x, y, 4.5, 0, 2 * Math.PI);
    g.fill();
    g.stroke();
    dots.push([x, y, i]);
  }
}

// ---- The frame ----
const frame = $("frame"), fg = frame.getContext("2d");
frame.width = D.image.width;
frame.height = D.image.height;
let colours = null, tileOf = null, shown = -1, shownView = "";
const pixels = fg.createImageData(D.image.width, D.image.height);
function decode(url) {
  return new Promise((resolve, reject) => {
    const img = new Image();
    img.onload = () => {
      const c = document.createElement("canvas");
      c.width = img.naturalWidth;
      c.height = img.naturalHeight;
      const cg = c.getContext("2d");
      cg.drawImage(img, 0, 0);
      resolve(cg.getImageData(0, 0, c.width, c.height).data);
    };
    img.onerror = () => reject(new Error("an embedded image does not decode"));
    img.src = url;
  });
}
const ownerRgb = D.colours.map((h) => [1, 3, 5].map((k) => parseInt(h.slice(k, k + 2), 16)));
function drawFrame() {
  if (!colours || !tileOf) return;
  const done = upTo(tileEnds, t);
  const which = document.querySelector("input[name=view]:checked").value;
  if (done === shown && which === shownView) return;
  shown = done;
  shownView = which;
  const out = pixels.data;
  for (let p = 0, q = 0; q < out.length; ++p, q += 4) {
    const rank = (tileOf[q] << 16) | (tileOf[q + 1] << 8) | tileOf[q + 2];
    if (rank === 0 || rank > done) { out[q] = 34; out[q + 1] = 34; out[q + 2] = 34; }
    else if (which === "owners") { const c = ownerRgb[D.tiles.node[rank - 1]]; out[q] = c[0]; out[q + 1] = c[1]; out[q + 2] = c[2]; }
    else { out[q] = colours[q]; out[q + 1] = colours[q + 1]; out[q + 2] = colours[q + 2]; }
    out[q + 3] = 255;
  }
  fg.putImageData(pixels, 0, 0);
}

// ---- Controls ----
const slider = $("slider"), clock = $("clock");
function show() {
  drawMachine();
  drawFrame();
  const c = counters();
  const total = D.totals;
  clock.textContent = format(t) + " of " + format(END);
  $("counters").innerHTML =
      `<span>packets delivered <b>${c.packets}</b> / ${total.packets}</span>` +
      `<span>hops <b>${c.hops}</b> / ${total.hops}</span>` +
      `<span>page misses <b>${c.misses}</b> / ${total.misses}</span>` +
      `<span>pixels <b>${c.pixels}</b> / ${total.pixels}</span>`;
  if (!dragging) slider.value = String(Math.round((1000 * t) / Math.max(1, END)));
}
function seek(ticks) {
  t = Math.min(END, Math.max(0, ticks));
  if (t >= END) stop();
  show();
}
function stop() { playing = false; $("play").textContent = "play"; }
function frameLoop(now) {
  if (!playing) return;
  if (lastFrame !== null) t += ((now - lastFrame) / 1000) * (END / 30) * speed;  // 30 s at speed 1
  lastFrame = now;
  seek(t);
  if (playing) requestAnimationFrame(frameLoop);
}
$("play").onclick = () => {
  if (playing) { stop(); return; }
  if (t >= END) t = 0;
  playing = true;
  lastFrame = null;
  $("play").textContent = "pause";
  requestAnimationFrame(frameLoop);
};
function next() { stop(); seek(events[Math.min(events.length - 1, upTo(events, t))]); }
function previous() {
  stop();
  const atOrBefore = upTo(events, t) - 1;
  const k = events[atOrBefore] === t ? atOrBefore - 1 : atOrBefore;
  seek(k >= 0 ? events[k] : 0);
}
$("step").onclick = next;
$("back").onclick = previous;
$("end").onclick = () => seek(END);
// Speed 1 plays the run in 30 s; the slowest ones show single hops, which
// in virtual time take a fraction of a millisecond of a run of minutes.
for (const s of [1e-6, 1e-5, 1e-4, 1e-3, 0.01, 0.1, 0.25, 0.5, 1, 2, 4]) {
  const o = document.createElement("option");
  o.value = String(s);
  o.textContent = brief((END / 30) * s) + " of the run a second";
  if (s === 1) o.selected = true;
  $("speed").appendChild(o);
}
$("speed").onchange = (e) => { speed = Number(e.target.value); };
let dragging = false;
slider.oninput = () => { dragging = true; seek((Number(slider.value) / 1000) * END); dragging = false; };
for (const r of document.querySelectorAll("input[name=view]")) r.onchange = () => drawFrame();

// ---- Details of a node or a packet ----
function esc(s) { return String(s).replace(/[&<>"]/g, (c) => ({"&": "&amp;", "<": "&lt;", ">": "&gt;", "\"": "&quot;"}[c])); }
function packetDetails(i) {
  let rows = `<tr><th>node</th>${RANK ? "<th>rank</th>" : ""}<th>arrives</th><th>leaves</th></tr>`;
  for (let h = 0; h <= P.hops[i]; ++h)
    rows += `<tr><td>${node(i, h)}</td>${RANK ? `<td>${RANK[node(i, h)]}</td>` : ""}` +
            `<td>${format(h === 0 ? injected(i) : arrives(i, h - 1))}</td>` +
            `<td>${format(h === P.hops[i] ? delivered(i) : departs(i, h))}</td></tr>`;
  $("details").innerHTML = `<h3>${esc(D.kinds[P.kind[i]])} packet ${P.id[i]}: ${P.bytes[i]} bytes, ` +
      `${P.hops[i]} hop${P.hops[i] === 1 ? "" : "s"}</h3><p>route ${Array.from({length: P.hops[i] + 1}, (_, h) => node(i, h)).join(" \u2192 ")}` +
      ` (injected at the first node, delivered at the last)` +
      (crossed[i] ? `; it crossed between MPI ranks` : ``) + `</p><table>${rows}</table>`;
}
function nodeDetails(n) {
  const buckets = 48, hits = new Float64Array(buckets), miss = new Float64Array(buckets);
  const at = (ticks) => Math.min(buckets - 1, Math.floor((ticks / Math.max(1, END)) * buckets));
  D.hits.node.forEach((m, k) => { if (m === n) hits[at(D.hits.time[k])] += D.hits.hits[k]; });
  D.fetches.node.forEach((m, k) => { if (m === n) miss[at(D.fetches.start[k])] += 1; });
  const served = new Map();
  let servedCount = 0;
  D.serves.node.forEach((m, k) => {
    if (m !== n) return;
    ++servedCount;
    served.set(D.serves.page[k], (served.get(D.serves.page[k]) || 0) + 1);
  });
  const top = [...served.entries()].sort((a, b) => b[1] - a[1] || a[0] - b[0]).slice(0, 12);
  const totalHits = hits.reduce((a, b) => a + b, 0), totalMisses = miss.reduce((a, b) => a + b, 0);
  $("details").innerHTML = `<h3>node ${n}${RANK ? ` (MPI rank ${RANK[n]})` : ``}</h3><p>page calls answered by its own pages or its cache: ${totalHits}; ` +
      `misses (page requests sent): ${totalMisses}` +
      (D.window < END ? ` (recorded up to ${format(D.window)})` : ``) +
      `; over the run, in ${buckets} slices of ${format(END / buckets)}:</p>` +
      `<canvas id="cache-chart" width="640" height="140"></canvas>` +
      `<p>pages served: ${servedCount} requests for ${served.size} pages` +
      (top.length ? `; the most asked for:</p><table><tr><th>page</th><th>served</th></tr>` +
          top.map(([p, c]) => `<tr><td>${p}</td><td>${c}</td></tr>`).join("") + `</table>` : `.</p>`);
  const c = $("cache-chart"), cg = c.getContext("2d");
  const top2 = Math.max(1, ...hits), topMiss = Math.max(1, ...miss), bw = c.width / buckets;
  cg.fillStyle = "#fff";
  cg.fillRect(0, 0, c.width, c.height);
  for (let k = 0; k < buckets; ++k) {
    const hh = (hits[k] / top2) * 60, mh = (miss[k] / topMiss) * 60;
    cg.fillStyle = STATE.tracing;
    cg.fillRect(k * bw + 1, 64 - hh, bw - 2, hh);
    cg.fillStyle = STATE.waiting;
    cg.fillRect(k * bw + 1, 72, bw - 2, mh);
  }
  cg.fillStyle = "#333";
  cg.font = "11px sans-serif";
  cg.fillText(`hits (up to ${top2} a slice)`, 4, 12);
  cg.fillText(`misses (up to ${topMiss} a slice)`, 4, 136);
  cg.fillStyle = "rgba(0,0,0,0.4)";
  cg.fillRect((t / Math.max(1, END)) * c.width, 0, 1, c.height);
}
overlay.onclick = (e) => {
  const box = overlay.getBoundingClientRect(), ratio = window.devicePixelRatio || 1;
  const x = ((e.clientX - box.left) * ratio) / scale, y = ((e.clientY - box.top) * ratio) / scale;
  let best = null, bestD = 7;
  for (const [dx, dy, i] of dots) { const d = Math.hypot(dx - x, dy - y); if (d < bestD) { best = i; bestD = d; } }
  if (best !== null) { packetDetails(best); return; }
  for (let n = 0; n < N; ++n) {
    const [nx, ny, r] = D.places[n];
    if (Math.hypot(nx - x, ny - y) <= r * 1.5) { nodeDetails(n); return; }
  }
};

// ---- Words ----
const recorded = count, all = D.totals.packets;
$("about").textContent = `${D.topology}, ${N} nodes, ${W} pixel computer${W === 1 ? "" : "s"} each; ` +
    (D.timing === "virtual" ? "virtual time: the modelled machine's timing, the same on every replay of this command"
                            : "real time: this computer's wall clock, as the run went") +
    `; ${format(END)} recorded, ${recorded} packets hop by hop.` +
    (RANK ? ` Run over ${RANKS} MPI ranks, each on its own clock put onto rank 0's; ` +
            `${crossedCount} of the packets recorded crossed between ranks.` : ``);
if (D.unrecorded.packets > 0) {
  $("bound").hidden = false;
  $("bound").textContent = `Only the first ${D.maxPackets} of ${all} packets were recorded hop by hop ` +
      `(--replay-packets); the other ${D.unrecorded.packets} packets (${D.unrecorded.hops} hops) were only counted, ` +
      `and join the counters at the end.`;
}
if (D.unrecorded.fetches + D.unrecorded.serves > 0) {
  $("bound").hidden = false;
  $("bound").textContent += ` Waits for pages and pages served are recorded while that budget lasted, up to ` +
      `${format(D.window)}: ${D.fetches.start.length} waits and ${D.serves.start.length} serves; ` +
      `the other ${D.unrecorded.fetches} waits and ${D.unrecorded.serves} serves were only counted.`;
}
let legend = "<b>packets</b>";
D.kinds.forEach((name, k) => {
  if (name) legend += `<span class="sw" style="background:${KIND_COLOURS[k]}"></span>${esc(name)}`;
});
legend += "<br/><b>pixel computers</b>";
for (const s of ["tracing", "waiting", "idle"])
  legend += `<span class="sw" style="background:${STATE[s]}"></span>${s === "waiting" ? "waiting for a page" : s}`;
legend += `<span class="sw" style="background:${STATE.serving}"></span>page server serving (outer ring)`;
legend += "<br/><b>links</b>: orange, thicker as more packets have crossed them";
if (RANK) legend += "; dashed between nodes of different MPI ranks. A packet ringed in black crossed between ranks";
$("legend").innerHTML = legend;

fit();
window.addEventListener("resize", () => { fit(); show(); });
const ready = Promise.all([decode(D.image.colours), decode(D.image.tiles)]).then(([c, m]) => {
  colours = c;
  tileOf = m;
  shown = -1;
  show();
});
show();
window.vmprayReplay = {
  ready,
  end: seconds(END),
  time: () => seconds(t),
  seek: (s) => seek(s / TICK),
  step: next,
  stepToEnd: () => { seek(END); return counters(); },
  counters: () => counters(),
  packets: recorded,
  ranks: RANKS,
  crossedRanks: crossedCount,
};
})();
