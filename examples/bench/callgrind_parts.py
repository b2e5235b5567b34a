#!/usr/bin/env python3
"""Where the machine's own instructions go, per page miss.

Takes two callgrind outputs of the same frame, the machine's and the plain
renderer's, subtracts the plain one function by function, sorts what is
left into parts of the machine by function name, and divides by the run's
page misses. Instruction counts, so other load on the machine does not
move them; a part's figure moves when inlining moves code across names.

usage: examples/bench/callgrind_parts.py MACHINE.out PLAIN.out MISSES

    valgrind --tool=callgrind --callgrind-out-file=m.out \\
        build/release/app/vmpray rings4 --width 192 --height 192 --threads 1 -q -o m.png --stats m.json
    valgrind --tool=callgrind --callgrind-out-file=p.out \\
        build/release/app/vmpray rings4 --width 192 --height 192 --single --threads 1 -q -o p.png
    examples/bench/callgrind_parts.py m.out p.out "$(jq .machine.svm.misses m.json)"
"""
import re
import subprocess
import sys

PARTS = [
    ("ALT and wake bells", r"csp::Alt|Bell::|BellMark"),
    ("routers", r"nodes::Router|HopSummary|topology::"),
    ("channels", r"ChannelState|ChannelBase|RecordQueue|Spinlock"),
    ("scheduler and switches", r"boost::fibers|FifoScheduler|Tracker|detail::park|detail::arm|detail::complete|"
     r"fcontext|algorithm_with_properties|tls_get_addr|detail::sleep|issue_deferred|try_claim|process_of|"
     r"current_process"),
    ("allocation", r"malloc|free|operator new|operator delete|_int_"),
    ("page table and cache", r"SvmSource|NodeMemory|NodeSvm"),
    ("page server, messages, pixel computer", r"PageServer|Outbox|messages|encode_|decode_|WireWriter|WireReader|"
     r"make_page|make_packet|page_reply|PageFetch|_Function_handler|PixelComputer|Farmer|Collector|WorkPlan|"
     r"pixel_order"),
    ("memcpy", r"memcpy|memmove|memset"),
    ("the tracer, slower inside the machine", r"tracer::"),
]


def self_costs(path):
    """Instructions by function (recursion levels merged)."""
    out = subprocess.run(["callgrind_annotate", "--threshold=100", path], capture_output=True, text=True,
                         check=True).stdout
    costs = {}
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+) \([ \d.]+%\)\s+(.*)", line)
        if not m or "PROGRAM TOTALS" in line:
            continue
        name = re.sub(r"'\d+", "", m[2])
        costs[name] = costs.get(name, 0) + int(m[1].replace(",", ""))
    return costs


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: callgrind_parts.py MACHINE.out PLAIN.out MISSES")
    machine, plain, misses = self_costs(sys.argv[1]), self_costs(sys.argv[2]), float(sys.argv[3])
    parts = {name: 0 for name, _ in PARTS}
    parts["the rest"] = 0
    for fn in set(machine) | set(plain):
        extra = machine.get(fn, 0) - plain.get(fn, 0)
        part = next((name for name, pattern in PARTS if re.search(pattern, fn)), "the rest")
        parts[part] += extra
    print(f"{'all the machine adds':40s} {(sum(machine.values()) - sum(plain.values())) / misses:8.0f}")
    for name, extra in parts.items():
        print(f"{name:40s} {extra / misses:8.0f}")


if __name__ == "__main__":
    main()
