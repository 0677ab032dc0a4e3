#!/bin/sh
# Proves that the real-Earth fixed-point backend's per-pixel function uses no floating
# point on a core without an FPU: builds tools/no-float (EARTH_FIXED.motion behind the C
# symbol earth_fixed_motion, core-math with only `earth-fixed`) for thumbv7m-none-eabi,
# disassembles that symbol and fails on any VFP instruction and on any call (bl, blx,
# or a branch to a relocated symbol): the function must be a leaf, so no soft-float,
# libm or other helper can hide behind a call. The same checker must flag the probe's
# float_canary (soft-float calls), or its verdict would mean nothing.
# Prints the function's static instruction count. docs/fixed-point.md.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
cd "$here/.."
target=thumbv7m-none-eabi
out=target/no-float
cargo build --quiet --release --manifest-path tools/no-float/Cargo.toml \
    --target "$target" --target-dir "$out"
lib="$out/$target/release/libno_float_probe.a"

objdump=$(sh "$here/find-objdump.sh")

# The disassembly of one symbol, with relocations (the archive is not linked, so calls
# show their target only as a relocation).
disasm() {
    "$objdump" -dr --no-show-raw-insn --disassemble-symbols="$1" "$lib" 2>/dev/null
}

# Offending lines of a disassembly on stdin: VFP/NEON instructions (mnemonics v*),
# calls, and relocations of branches (a tail call to another function).
offending() {
    awk '
        /R_ARM_THM_(CALL|JUMP24|JUMP19|JUMP11|JUMP8)/ { print "call: " $NF; next }
        /^[ \t]*[0-9a-f]+:[ \t]/ {
            m = $2
            if (m ~ /^v/ || m ~ /^blx?(\.[nw])?$/) print "insn: " $0
        }
    '
}

# Instructions of a disassembly on stdin.
count() {
    grep -cE '^[[:space:]]*[0-9a-f]+:[[:space:]]+[a-z]'
}

canary=$(disasm float_canary)
if [ -z "$(printf '%s\n' "$canary" | offending)" ]; then
    echo "check-no-float: the checker does not flag float_canary: it cannot be trusted" >&2
    exit 1
fi

motion=$(disasm earth_fixed_motion)
n=$(printf '%s\n' "$motion" | count)
if [ "$n" -eq 0 ]; then
    echo "check-no-float: earth_fixed_motion not found in $lib" >&2
    exit 1
fi
bad=$(printf '%s\n' "$motion" | offending)
if [ -n "$bad" ]; then
    echo "check-no-float: earth_fixed_motion ($target) is not integer-only:" >&2
    printf '%s\n' "$bad" >&2
    exit 1
fi
echo "check-no-float: earth_fixed_motion on $target: $n instructions, no VFP instruction, no call"
