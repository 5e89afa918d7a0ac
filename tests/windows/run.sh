#!/usr/bin/env bash
# The win64 binary of the FMU, checked on Linux (run by `make test-windows`, part of `make test`):
#   1. the FMU carries binaries/win64/MODEL.dll beside binaries/linux64/MODEL.so, MODEL the
#      FMU's file name (GearRattle, GearboxRattle);
#   2. the DLL's export table is exactly the FMI 2.0 Co-Simulation and Model Exchange
#      functions, and its import
#      table names only DLLs that a plain Windows 10 has;
#   3. fmu_run.c, built with MinGW-w64 and run under Wine, steps the DLL through scene S1
#      (GearRattle: sine mode, the paper's defaults; GearboxRattle: its defaults, the engine at
#      idle, gear 1 read) to 0.2 s in 1 ms communication steps; the same C file built with gcc
#      steps the linux64 .so the same way; xi must agree within 1e-6 G and the impact counters
#      exactly.
# Every problem fails the test with a message; nothing is skipped.
#
# Usage: tests/windows/run.sh [FMU]   (default target/fmu/GearRattle.fmu)
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/../.." && pwd)
HERE=$ROOT/tests/windows
FMU=$(realpath -m "${1:-$ROOT/target/fmu/GearRattle.fmu}")
MODEL=$(basename "$FMU" .fmu)
WORK=$ROOT/target/windows-test
T_END=0.2
DT=0.001

fail() {
    echo "test-windows FAILED: $*" >&2
    exit 1
}
step() { echo "test-windows: $*"; }

# ---- tools ----
WINE=$(command -v wine64 || true)
[ -n "$WINE" ] || WINE=/usr/lib/wine/wine64 # Debian's wine64 package puts it there
[ -x "$WINE" ] || fail "wine64 not found (Debian: apt-get install wine64; 'make test-windows' installs it)"
WINESERVER=$(dirname "$WINE")/wineserver
for tool in gcc x86_64-w64-mingw32-gcc x86_64-w64-mingw32-objdump python3 timeout; do
    command -v "$tool" >/dev/null || fail "$tool not found ('make test-windows' installs what it needs)"
done
[ -f "$FMU" ] || fail "$FMU does not exist: build it with 'make fmu'"

# ---- 1. the FMU's content ----
rm -rf "$WORK/run"
mkdir -p "$WORK/run"
python3 -m zipfile -e "$FMU" "$WORK/run/fmu" || fail "$FMU is not a readable zip file"
DLL=$WORK/run/fmu/binaries/win64/$MODEL.dll
SO=$WORK/run/fmu/binaries/linux64/$MODEL.so
[ -f "$DLL" ] || fail "$FMU has no binaries/win64/$MODEL.dll"
[ -f "$SO" ] || fail "$FMU has no binaries/linux64/$MODEL.so"
if find "$WORK/run/fmu" -iname "bcryptprimitives*" | grep -q .; then
    fail "$FMU carries a bcryptprimitives.dll: the ProcessPrng stand-in is for the Wine test only"
fi
GUID=$(grep -o ' guid="[^"]*"' "$WORK/run/fmu/modelDescription.xml" | cut -d'"' -f2)
[ -n "$GUID" ] || fail "no guid in the FMU's modelDescription.xml"
step "FMU carries linux64 and win64 binaries (GUID $GUID)"

# ---- 2. export and import tables of the DLL ----
x86_64-w64-mingw32-objdump -p "$DLL" >"$WORK/run/objdump.txt" || fail "objdump -p $DLL failed"
FMI2=$(grep -v "^#" "$ROOT/tests/fmi2_functions.txt")
expected=$(tr -s ' \n' '\n\n' <<<"$FMI2" | sort)
exported=$(sed -n '/^\[Ordinal\/Name Pointer\] Table/,/^$/p' "$WORK/run/objdump.txt" |
    sed -n 's/^[[:space:]]*\[ *[0-9]*\] //p' | sort)
entries=$(sed -n '/^Export Address Table -- Ordinal Base/,/^$/p' "$WORK/run/objdump.txt" |
    grep -c 'Export RVA' || true)
echo "$exported" >"$WORK/run/exports.txt"
if [ "$exported" != "$expected" ]; then
    echo "exported by name, versus the FMI 2.0 functions (diff expected actual):" >&2
    diff <(echo "$expected") <(echo "$exported") >&2 || true
    fail "the DLL's export table is not exactly the fmi2* functions (see mk/windows-link.sh)"
fi
[ "$entries" -eq "$(wc -l <<<"$expected")" ] ||
    fail "the export address table has $entries entries for $(wc -l <<<"$expected") names (exports by ordinal only?)"
step "exports: exactly the $entries fmi2* functions of FMI 2.0 (Co-Simulation and Model Exchange)"

# DLLs of every Windows 10 installation that Rust's standard library (windows-gnu, MinGW's
# msvcrt) may import; anything else (libgcc_s_seh-1.dll, libwinpthread-1.dll, vcruntime140.dll,
# ...) would have to ship beside the DLL, which an FMU cannot rely on.
WINDOWS10="kernel32.dll ntdll.dll msvcrt.dll advapi32.dll userenv.dll ws2_32.dll bcrypt.dll
bcryptprimitives.dll api-ms-win-core-synch-l1-2-0.dll"
imports=$(sed -n 's/^[[:space:]]*DLL Name: //p' "$WORK/run/objdump.txt" | tr 'A-Z' 'a-z' | sort -u)
[ -n "$imports" ] || fail "no import table found in objdump's output"
for dll in $imports; do
    grep -qw -- "$dll" <<<"$WINDOWS10" ||
        fail "the DLL imports $dll, which is not in the list of Windows 10 system DLLs of tests/windows/run.sh"
done
step "imports: $(echo $imports) (all part of Windows 10)"

# ---- 3. the same run, linux64 natively and win64 under Wine ----
CFLAGS="-O2 -std=c11 -Wall -Wextra -Werror"
gcc $CFLAGS -o "$WORK/run/fmu_run" "$HERE/fmu_run.c" -ldl
x86_64-w64-mingw32-gcc $CFLAGS -o "$WORK/run/fmu_run.exe" "$HERE/fmu_run.c"
# For Wine only (see processprng.c): found beside fmu_run.exe when the DLL is loaded.
x86_64-w64-mingw32-gcc $CFLAGS -shared -o "$WORK/run/bcryptprimitives.dll" "$HERE/processprng.c" -ladvapi32

# The value references fmu_run reads and sets (G, xi, excitation, impacts_Fplus, impacts_Fminus).
case $MODEL in
GearRattle) VRS="7 34 100 102 103" ;;
GearboxRattle) VRS="1105 1120 2 1102 1103" ;; # gear[1]'s
*) fail "no value references for $MODEL in tests/windows/run.sh" ;;
esac
linux=$("$WORK/run/fmu_run" "$SO" "$GUID" $T_END $DT $VRS) || fail "the linux64 run failed"
echo "  linux64: $linux"

export WINEPREFIX=$WORK/wine-prefix WINEDEBUG=-all,err+module WINEDLLOVERRIDES="mscoree,mshtml,winemenubuilder.exe="
trap '"$WINESERVER" -k 2>/dev/null || true' EXIT # the wineserver this script started
if [ ! -f "$WINEPREFIX/system.reg" ]; then
    step "creating the Wine prefix $WINEPREFIX (first run only)"
    timeout 90 "$WINE" wineboot --init >"$WORK/wineboot.log" 2>&1 ||
        { cat "$WORK/wineboot.log" >&2; fail "wineboot failed or timed out"; }
fi
winpath="Z:${DLL//\//\\}"
windows=$(cd "$WORK/run" && timeout 90 "$WINE" ./fmu_run.exe "$winpath" "$GUID" $T_END $DT $VRS | tr -d '\r') ||
    fail "the win64 run under Wine failed (messages above)"
echo "  win64:   $windows"

field() { sed -n "s/.*\\b$1=\\([^ ]*\\).*/\\1/p" <<<"$2"; }
for name in impacts_Fplus impacts_Fminus steps; do
    [ "$(field $name "$linux")" = "$(field $name "$windows")" ] ||
        fail "$name differs: linux64 $(field $name "$linux"), win64 $(field $name "$windows")"
done
[ "$(field steps "$linux")" -eq 200 ] || fail "expected 200 steps"
[ $(($(field impacts_Fplus "$linux") + $(field impacts_Fminus "$linux"))) -gt 0 ] ||
    fail "no impact in 0.2 s of S1: the comparison would prove nothing"
awk -v a="$(field xi "$linux")" -v b="$(field xi "$windows")" -v g="$(field G "$linux")" 'BEGIN {
    d = a - b; if (d < 0) d = -d
    printf "  |xi(linux64) - xi(win64)| = %.3g m (limit 1e-6 G = %.3g m)\n", d, 1e-6 * g
    exit !(g > 0 && d <= 1e-6 * g)
}' || fail "xi differs by more than 1e-6 G between linux64 and win64"
step "OK: $MODEL's win64 under Wine agrees with linux64 ($T_END s, dt $DT s)"
