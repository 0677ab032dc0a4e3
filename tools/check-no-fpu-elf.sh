#!/bin/sh
# Proves that a flight binary built for a core without an FPU (the mps2-an385's
# Cortex-M3) holds no instruction of the floating-point unit: disassembles every code
# section of the ELF and fails on any VFP/NEON mnemonic (v*) or any other access to
# coprocessors 10 and 11 (mrc, mcr, ldc, stc, cdp on p10/p11: the FPU's). Literal
# pools are data (the ELF's mapping symbols), not decoded. The same scan must find such
# instructions in a Cortex-M4F flight binary, or its verdict would mean nothing.
# Usage: tools/check-no-fpu-elf.sh NO_FPU_ELF FPU_ELF (docs/fixed-point.md).
set -eu
no_fpu_elf=$1
fpu_elf=$2

objdump=$(sh "$(cd "$(dirname "$0")" && pwd)/find-objdump.sh")

# FPU instructions of an ELF, one line each (address and instruction).
fpu_lines() {
    "$objdump" -d --no-show-raw-insn "$1" | awk '
        /^[ \t]*[0-9a-f]+:[ \t]/ {
            m = $2
            if (m ~ /^v/ || ($0 ~ /[ \t,]p1[01],/ && m ~ /^(mrc|mcr|mrrc|mcrr|ldc|stc|cdp)/)) print
        }
    '
}

# Instructions of an ELF.
count() {
    "$objdump" -d --no-show-raw-insn "$1" | grep -cE '^[[:space:]]*[0-9a-f]+:[[:space:]]+[a-z]'
}

canary=$(fpu_lines "$fpu_elf" | wc -l)
if [ "$canary" -eq 0 ]; then
    echo "check-no-fpu-elf: the scan finds no FPU instruction in $fpu_elf: it cannot be trusted" >&2
    exit 1
fi
n=$(count "$no_fpu_elf")
if [ "$n" -eq 0 ]; then
    echo "check-no-fpu-elf: no code in $no_fpu_elf" >&2
    exit 1
fi
bad=$(fpu_lines "$no_fpu_elf")
if [ -n "$bad" ]; then
    echo "check-no-fpu-elf: $no_fpu_elf holds FPU instructions:" >&2
    printf '%s\n' "$bad" | head -20 >&2
    exit 1
fi
echo "check-no-fpu-elf: $no_fpu_elf: $n instructions, none of the FPU ($canary in $fpu_elf)"
