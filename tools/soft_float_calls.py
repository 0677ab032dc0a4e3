#!/usr/bin/env python3
"""Calls of the soft-float routines in one profiled bench region, by call site.

`cargo xtask bench --board mps2-an385 --profile LABEL` leaves the region's executed
addresses and counts in target/thumbv7m-none-eabi/release/bench-pcs.txt; its profile
attributes each address to its inline stack, so the instructions inside
compiler_builtins lose their caller. The executed count of a `bl` to a routine is the
number of calls from that site: this joins the two (llvm-objdump, llvm-symbolizer) and
prints the calls per routine, per site and per function on the sites' inline stacks.

usage: python3 tools/soft_float_calls.py ELF PCS [ROWS]
"""
import collections
import re
import subprocess
import sys

ROUTINE = re.compile(r"__aeabi_[a-z0-9]+$|sqrtf?$")


def main():
    elf, pcs = sys.argv[1], sys.argv[2]
    rows = int(sys.argv[3]) if len(sys.argv) > 3 else 40
    counts = {}
    for line in open(pcs):
        addr, n = line.split()
        counts[int(addr, 16)] = int(n)
    dis = subprocess.run(
        ["llvm-objdump", "-d", "--no-show-raw-insn", elf],
        capture_output=True, text=True, check=True,
    ).stdout
    sites = []
    for line in dis.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(?:bl|b\.w|b)\s+.*<([^>+]+)>", line)
        if m and ROUTINE.search(m.group(2)):
            addr = int(m.group(1), 16)
            if addr in counts:
                sites.append((addr, m.group(2), counts[addr]))
    out = subprocess.run(
        ["llvm-symbolizer", "--obj=" + elf, "-f", "-i", "-C"],
        input="\n".join(hex(a) for a, _, _ in sites) + "\n",
        capture_output=True, text=True, check=True,
    ).stdout
    blocks = out.strip("\n").split("\n\n")
    per_routine = collections.Counter()
    per_site = collections.Counter()
    per_function = collections.Counter()
    for (_, routine, n), block in zip(sites, blocks):
        lines = block.split("\n")
        frames = [(lines[i], lines[i + 1].split("/")[-1]) for i in range(0, len(lines) - 1, 2)]
        per_routine[routine] += n
        per_site[(routine, f"{frames[0][0][:70]} @ {frames[0][1]}")] += n
        for name in {f[0] for f in frames}:
            per_function[name] += n
    print("calls per routine")
    for routine, n in per_routine.most_common():
        print(f"{n:7d} {routine}")
    print("\ncalls per site")
    for (routine, site), n in per_site.most_common(rows):
        print(f"{n:7d} {routine:16s} {site}")
    print("\ncalls per function on the sites' inline stacks")
    for name, n in per_function.most_common(rows):
        print(f"{n:7d} {name[:140]}")


if __name__ == "__main__":
    main()
