#!/usr/bin/env bash
# Fails if a function of the binary calls a SIMD intrinsic (`core::core_arch::…`) out of line.
#
#   scripts/check_kernel_calls.sh [BINARY]      (default: target/release/goldray)
#
# The kernels of `simd::dispatch` are compiled with AVX2 (or AVX-512) enabled, and every lane
# operation in them is an intrinsic that must be inlined. Code compiled without those features
# cannot inline them and calls each one instead: a closure inside a kernel (closures do not
# inherit the enclosing function's target features), an `array::map` over lanes, a generic
# function that is not `#[inline(always)]`. Nothing fails and the pictures stay the same; the
# kernel just runs several times slower. The only legitimate callers are the standard
# library's and blake3's CPU feature detection, which run once.
set -euo pipefail
binary=${1:-target/release/goldray}
command -v objdump >/dev/null || { echo "objdump (binutils) is needed" >&2; exit 2; }
offenders=$(objdump -d -C --no-show-raw-insn "$binary" | awk '
    /^[0-9a-f]+ </ { name = $0; sub(/^[0-9a-f]+ </, "", name); sub(/>:$/, "", name); next }
    /call.*<core::core_arch::/ { calls[name]++ }
    END { for (n in calls) print calls[n] "\t" n }' |
    grep -v -E $'\t(std_detect::|blake3::platform::)' || true)
if [ -n "$offenders" ]; then
    echo "functions of $binary that call SIMD intrinsics out of line (calls, function):" >&2
    echo "$offenders" | sort -rn >&2
    exit 1
fi
echo "no SIMD intrinsic is called out of line in $binary"
