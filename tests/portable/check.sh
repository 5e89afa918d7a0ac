#!/usr/bin/env bash
# The FMU's binaries as packaged, checked on Linux (run by `make test-portable`, part of
# `make test`), with Debian's llvm tools:
#   linux64   needs no glibc symbol version newer than 2.17 (so it loads on RHEL 7 and later);
#   darwin64  a universal binary of an x86_64 and an arm64 slice, each loading on macOS 11 and later,
#             linking libSystem alone, its arm64 code signature matching its pages
#             (macho_signature.py). Built and checked here, never run: there is no macOS here;
#   all       export exactly the FMI 2.0 functions (tests/fmi2_functions.txt), and the FMI 3.0
#             ones (tests/fmi3_functions.txt) for the models tests/exports.sh names;
#             win64's export table is checked by tests/windows/run.sh), carry no debug
#             information, and each binary (each darwin slice) is under 1 MB.
# The pytest suite and tests/windows/run.sh run the linux64 binary of the same FMU.
# Every problem fails the test with a message; nothing is skipped.
#
# Usage: tests/portable/check.sh [FMU]   (default target/fmu/GearRattle.fmu; the binaries are
# named after the FMU's file, binaries/linux64/GearboxRattle.so in GearboxRattle.fmu)
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/../.." && pwd)
FMU=$(realpath -m "${1:-$ROOT/target/fmu/GearRattle.fmu}")
MODEL=$(basename "$FMU" .fmu)
WORK=$ROOT/target/portable-test/$MODEL
MAX_GLIBC=2.17
MAX_MACOS=11.0
# A stripped binary is about 1 MB, an unstripped one (target/fmu/debug) 4-5 MB.
MAX_BYTES=$((3 * 1024 * 1024 / 2))

failures=0
fail() {
    echo "test-portable FAILED: $*" >&2
    failures=$((failures + 1))
}
step() { echo "test-portable: $*"; }

for tool in llvm-objdump llvm-nm python3; do
    command -v "$tool" >/dev/null || { fail "$tool not found ('make test-portable' installs llvm)"; exit 1; }
done
[ -f "$FMU" ] || { fail "$FMU does not exist: build it with 'make fmu'"; exit 1; }
rm -rf "$WORK" && mkdir -p "$WORK"
python3 -m zipfile -e "$FMU" "$WORK/fmu" || { fail "$FMU is not a readable zip file"; exit 1; }
SO=$WORK/fmu/binaries/linux64/$MODEL.so
DYLIB=$WORK/fmu/binaries/darwin64/$MODEL.dylib
DLL=$WORK/fmu/binaries/win64/$MODEL.dll
for bin in "$SO" "$DYLIB" "$DLL"; do
    [ -f "$bin" ] || { fail "$FMU has no ${bin#"$WORK/fmu/"}"; exit 1; }
done
# shellcheck source=tests/exports.sh
. "$ROOT/tests/exports.sh"
expected=$(expected_exports "$MODEL")
PREFIXES=$(export_prefixes "$MODEL")

# $1: what, $2: the names found; compares them with the functions expected.
exports_are_fmi2() {
    if [ "$2" = "$expected" ]; then
        step "$1 exports exactly the $(wc -l <<<"$expected") $PREFIXES functions"
    else
        fail "$1 does not export exactly the $PREFIXES functions (diff expected actual):"
        diff <(echo "$expected") <(echo "$2") | head -n 20 >&2 || true
    fi
}

# $1: what, $2: size in bytes.
size_ok() {
    if [ -n "$2" ] && [ "$2" -lt "$MAX_BYTES" ]; then
        step "$1: $2 bytes (limit $MAX_BYTES)"
    else
        fail "$1 is '$2' bytes, not under $MAX_BYTES: is it stripped?"
    fi
}

# ---- linux64 ----
glibc=$(llvm-objdump -T "$SO" | grep -o 'GLIBC_[0-9][0-9.]*' | sed 's/GLIBC_//' | sort -uV)
newest=$(tail -n 1 <<<"$glibc")
[ -n "$newest" ] || fail "no GLIBC_ symbol version found in linux64 (is it a glibc build?)"
if [ "$(printf '%s\n' "$newest" "$MAX_GLIBC" | sort -V | tail -n 1)" = "$MAX_GLIBC" ]; then
    step "linux64 needs glibc $newest at most (symbol versions: $(echo $glibc); limit $MAX_GLIBC)"
else
    fail "linux64 needs GLIBC_$newest, newer than $MAX_GLIBC:" \
        "$(llvm-objdump -T "$SO" | grep "GLIBC_$newest" | awk '{print $NF}' | sort -u | tr '\n' ' ')"
fi
exports_are_fmi2 linux64 "$(llvm-nm -D --defined-only --format=just-symbols "$SO" | sort)"
sections=$(llvm-objdump -h "$SO" | awk '{print $2}' | grep -E '^\.(debug_|symtab$)' || true)
[ -z "$sections" ] || fail "linux64 carries debug information or a symbol table: $(echo $sections)"
size_ok linux64 "$(stat -c %s "$SO")"

# ---- darwin64 ----
archs=$(llvm-objdump --macho --universal-headers "$DYLIB" | sed -n 's/^ *cputype CPU_TYPE_//p' | sort | tr '\n' ' ')
[ "$archs" = "ARM64 X86_64 " ] || fail "darwin64 is not a universal binary of arm64 and x86_64 (slices: $archs)"
for arch in x86_64 arm64; do
    what="darwin64 ($arch)"
    exports_are_fmi2 "$what" "$(llvm-objdump --macho --exports-trie --arch=$arch "$DYLIB" |
        awk '/^0x/ {print $2}' | sed 's/^_//' | sort)"
    libs=$(llvm-objdump --macho --dylibs-used --arch=$arch "$DYLIB" | sed -n 's/^[[:space:]]*\([^ ]*\) (compat.*/\1/p')
    # The first entry is the dylib's own install name (LC_ID_DYLIB): no path of the build machine.
    id=$(head -n 1 <<<"$libs")
    [[ $id == @rpath/* ]] || fail "$what: its install name is '$id', not @rpath/..."
    linked=$(tail -n +2 <<<"$libs")
    if [ "$linked" = /usr/lib/libSystem.B.dylib ]; then
        step "$what links libSystem alone"
    else
        fail "$what links more than libSystem: $(echo $linked)"
    fi
    minos=$(llvm-objdump --macho --private-headers --arch=$arch "$DYLIB" | awk '$1 == "minos" {print $2}')
    if [ -n "$minos" ] && [ "$(printf '%s\n' "$minos" "$MAX_MACOS" | sort -V | tail -n 1)" = "$MAX_MACOS" ]; then
        step "$what needs macOS $minos or later (limit $MAX_MACOS)"
    else
        fail "$what needs macOS '$minos', newer than $MAX_MACOS (MACOSX_DEPLOYMENT_TARGET, mk/portable.mk)"
    fi
    stabs=$(llvm-nm -a --arch=$arch "$DYLIB" 2>/dev/null | awk '$2 == "-"' | wc -l)
    dwarf=$(llvm-objdump --macho --section-headers --arch=$arch "$DYLIB" | grep -c '__debug_\|__DWARF' || true)
    [ "$stabs" -eq 0 ] && [ "$dwarf" -eq 0 ] ||
        fail "$what carries debug information ($stabs debug-map symbols, $dwarf DWARF sections)"
    size_ok "$what" "$(llvm-objdump --macho --universal-headers "$DYLIB" |
        awk -v a="$arch" '$1 == "architecture" {cur = $2} $1 == "size" && cur == a {print $2}')"
done
if signature=$(python3 "$ROOT/tests/portable/macho_signature.py" "$DYLIB"); then
    step "darwin64 code signature: $(echo $signature)"
else
    fail "darwin64's code signature does not match its code: $(echo $signature)"
fi

# ---- win64 (exports, imports and a run under Wine: tests/windows/run.sh) ----
sections=$(llvm-objdump -h "$DLL" | awk '{print $2}' | grep -E '^\.debug_' || true)
[ -z "$sections" ] || fail "win64 carries debug information: $(echo $sections)"
symbols=$(llvm-nm "$DLL" 2>&1 | grep -vc 'no symbols' || true)
[ "$symbols" -eq 0 ] || fail "win64 carries a symbol table ($symbols symbols)"
size_ok win64 "$(stat -c %s "$DLL")"

if [ "$failures" -gt 0 ]; then
    echo "test-portable: $failures check(s) failed" >&2
    exit 1
fi
step "OK: $MODEL's linux64, darwin64 and win64 binaries are portable, stripped and export only $PREFIXES"
