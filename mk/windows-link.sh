#!/bin/sh
# Linker for the x86_64-pc-windows-gnu target (set in .cargo/config.toml): MinGW-w64's gcc,
# after narrowing rustc's export list to the fmi2* and fmi3* functions (and fmi2-shell's
# sampling entry gearRattleDoStepSampled, outside FMI).
#
# Why: for a cdylib, rustc writes a .def file naming every #[no_mangle] symbol of every crate,
# fmi-sys's `callback_log` included, and passes it to GNU ld as `-Wl,<tmpdir>/list.def`.
# On Linux, build.rs's version script (`local: callback_log; *`) hides the extra symbol; GNU
# ld's PE back end has no such thing for .def exports: a second .def only adds to the list
# (def files are merged), and --exclude-symbols / --exclude-all-symbols apply to automatic
# exports only. So the one place to drop a name is the list itself: this script writes a
# copy with only the fmi2* and fmi3* entries and links with that copy instead (rustc's file is left
# as it is). tests/windows/run.sh checks the resulting export table.
set -eu

shared=no
found=no
first=yes
for arg in "$@"; do
    if [ "$first" = yes ]; then
        set --
        first=no
    fi
    case $arg in
    -shared) shared=yes ;;
    -Wl,*.def | *.def)
        def=${arg#-Wl,}
        if [ "$(head -n 1 "$def")" = EXPORTS ]; then
            kept=${def%.def}.fmi2.def
            echo EXPORTS >"$kept"
            # An empty list would make ld export every global symbol: refuse instead.
            if ! grep -E '^[[:space:]]*"?(fmi[23]|gearRattleDoStepSampled)' "$def" >>"$kept"; then
                echo "mk/windows-link.sh: no fmi2* or fmi3* symbol in $def" >&2
                exit 1
            fi
            case $arg in -Wl,*) arg=-Wl,$kept ;; *) arg=$kept ;; esac
            found=yes
        fi
        ;;
    esac
    set -- "$@" "$arg"
done

if [ "$shared" = yes ] && [ "$found" = no ]; then
    echo "mk/windows-link.sh: linking a DLL but rustc's export list (a .def file) is not among" >&2
    echo "the arguments (a response file?): refusing to link a DLL with unchecked exports" >&2
    exit 1
fi
exec x86_64-w64-mingw32-gcc "$@"
