#!/bin/sh
# Prints the path of an llvm-objdump that reads Arm ELF files: the one on PATH, else
# rustup's llvm-tools component (added when missing). Fails with a message if none.
# Used by tools/check-no-float.sh and tools/check-no-fpu-elf.sh.
set -eu
if command -v llvm-objdump >/dev/null 2>&1; then
    command -v llvm-objdump
    exit 0
fi
sysroot=$(rustc --print sysroot)
host=$(rustc -vV | sed -n 's/^host: //p')
cand="$sysroot/lib/rustlib/$host/bin/llvm-objdump"
if [ ! -x "$cand" ] && command -v rustup >/dev/null 2>&1; then
    rustup component add llvm-tools >/dev/null 2>&1 || true
fi
if [ -x "$cand" ]; then
    echo "$cand"
    exit 0
fi
echo "no llvm-objdump (install LLVM, or rustup component add llvm-tools)" >&2
exit 1
