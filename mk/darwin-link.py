#!/usr/bin/env python3
"""Linker for the apple-darwin targets of `cargo zigbuild` (mk/portable.mk): hides every
symbol but the fmi2* and fmi3* functions (and fmi2-shell's sampling entry
gearRattleDoStepSampled), then hands the link to cargo-zigbuild's `zig cc` wrapper.

Why: rustc passes the Apple linker an exported-symbols list (every #[no_mangle] function,
fmi-sys's `callback_log` included), but zig's Mach-O linker ignores -exported_symbols_list
and exports every global symbol of its inputs (about 2 500 here, the Rust standard library's
among them). It does honour private-extern symbols (N_PEXT, what visibility("hidden") makes),
so this script copies each object and archive of the link, marks every symbol it defines that
is not on rustc's list narrowed to fmi2* and fmi3* as private extern, and links the copies. The narrowed
list is passed on too, for a linker that reads it. tests/portable/check.sh checks the dylib's
export trie.

The linker that rustc would have used is cargo-zigbuild's wrapper for the link's -arch, which
cargo-zigbuild names in CARGO_TARGET_<TRIPLE>_LINKER (mk/portable.mk sets this script as the
linker on cargo's command line, which takes precedence).
"""

import os
import re
import struct
import sys

N_STAB, N_PEXT, N_TYPE, N_EXT = 0xE0, 0x10, 0x0E, 0x01
LC_SYMTAB = 0x2
MH_MAGIC_64 = 0xFEEDFACF


def fail(message):
    sys.exit(f"mk/darwin-link.py: {message}")


def hide_object(data, start, keep):
    """Marks the defined external symbols of the Mach-O object at data[start:] that are not
    in `keep` as private extern, in place. Returns how many it hid."""
    if struct.unpack_from("<I", data, start)[0] != MH_MAGIC_64:
        return 0
    ncmds = struct.unpack_from("<I", data, start + 16)[0]
    at, hidden = start + 32, 0
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<II", data, at)
        if cmd == LC_SYMTAB:
            symoff, nsyms, stroff = struct.unpack_from("<III", data, at + 8)
            for i in range(nsyms):
                entry = start + symoff + 16 * i
                strx, n_type = struct.unpack_from("<IB", data, entry)
                defined = n_type & N_TYPE != 0  # N_UNDF is 0
                if n_type & N_STAB or not n_type & N_EXT or not defined or n_type & N_PEXT:
                    continue
                name_at = start + stroff + strx
                name = bytes(data[name_at : data.index(0, name_at)])
                if name not in keep:
                    data[entry + 4] = n_type | N_PEXT
                    hidden += 1
        at += size
    return hidden


def hide_archive(data, keep):
    """hide_object for every member of an ar archive (BSD `#1/len` names or GNU names)."""
    at, hidden = 8, 0
    while at + 60 <= len(data):
        name = bytes(data[at : at + 16]).decode("ascii", "replace").strip()
        size = int(bytes(data[at + 48 : at + 58]).decode("ascii").strip())
        body = at + 60
        if name.startswith("#1/"):
            body += int(name[3:])
        hidden += hide_object(data, body, keep)
        at += 60 + size + (size & 1)
    return hidden


def main(args):
    if any(a.startswith("@") for a in args):
        fail("rustc passed a response file; refusing to link with unchecked exports")
    lists = [i for i, a in enumerate(args) if a == "-Wl,-exported_symbols_list"]
    if len(lists) != 1 or len(args) <= lists[0] + 1:
        fail("rustc's -exported_symbols_list is not among the arguments (is this a cdylib link?)")
    list_path = args[lists[0] + 1].removeprefix("-Wl,")
    with open(list_path) as f:
        keep = [n.strip() for n in f
                if re.fullmatch(r"_(fmi[23]\w+|gearRattleDoStepSampled)", n.strip())]
    if not keep:
        fail(f"no fmi2* or fmi3* symbol in {list_path}")
    work = os.path.dirname(list_path)  # rustc's temporary directory for this link
    narrowed = os.path.join(work, "list.fmi2")
    with open(narrowed, "w") as f:
        f.write("\n".join(keep) + "\n")
    args[lists[0] + 1] = "-Wl," + narrowed

    keep = {n.encode() for n in keep}
    hidden = 0
    for i, arg in enumerate(args):
        if not re.search(r"\.(o|a|rlib)$", arg) or not os.path.isfile(arg):
            continue
        data = bytearray(open(arg, "rb").read())
        hidden += hide_archive(data, keep) if data.startswith(b"!<arch>\n") else hide_object(data, 0, keep)
        copy = os.path.join(work, f"hidden{i}-{os.path.basename(arg)}")
        with open(copy, "wb") as f:
            f.write(data)
        args[i] = copy
    if hidden == 0:
        fail("no symbol hidden: no Mach-O object among the arguments?")

    arch = args[args.index("-arch") + 1] if "-arch" in args else None
    triple = {"x86_64": "X86_64", "arm64": "AARCH64"}.get(arch)
    linker = os.environ.get(f"CARGO_TARGET_{triple}_APPLE_DARWIN_LINKER", "")
    if not linker or linker.endswith("darwin-link.py"):
        fail(f"no cargo-zigbuild linker for -arch {arch}: build with `cargo zigbuild` (make fmu)")
    os.execv(linker, [linker] + args)


main(sys.argv[1:])
