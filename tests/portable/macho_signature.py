#!/usr/bin/env python3
"""Checks the code signature of each slice of a Mach-O file (thin or universal), as macOS
does before it maps the code: the SHA-256 of every page up to the signature must equal the
hash the CodeDirectory holds for it. macOS on Apple silicon refuses to load arm64 code that
is unsigned or whose pages no longer match (an edit after the link, a strip that does not
re-sign); an ad hoc signature (no certificate) is enough.

Usage: macho_signature.py DYLIB   prints one line per slice; exit status 1 on any mismatch,
or when an arm64 slice carries no signature.
"""

import hashlib
import struct
import sys

FAT_MAGIC, MH_MAGIC_64 = 0xCAFEBABE, 0xFEEDFACF
CPU_ARM64, LC_CODE_SIGNATURE = 0x0100000C, 0x1D
CSMAGIC_CODEDIRECTORY, CS_HASHTYPE_SHA256 = 0xFADE0C02, 2
CPU_NAMES = {0x01000007: "x86_64", CPU_ARM64: "arm64"}


def slices(data):
    """(cputype, bytes of the slice) for each architecture of the file."""
    if struct.unpack_from(">I", data)[0] == FAT_MAGIC:
        for i in range(struct.unpack_from(">I", data, 4)[0]):
            cpu, _, offset, size, _ = struct.unpack_from(">5I", data, 8 + 20 * i)
            yield cpu, data[offset : offset + size]
    elif struct.unpack_from("<I", data)[0] == MH_MAGIC_64:
        yield struct.unpack_from("<I", data, 4)[0], data
    else:
        raise ValueError("not a 64-bit Mach-O file")


def signature(mach):
    """The (offset, size) of the LC_CODE_SIGNATURE data, or None."""
    ncmds, at = struct.unpack_from("<I", mach, 16)[0], 32
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<II", mach, at)
        if cmd == LC_CODE_SIGNATURE:
            return struct.unpack_from("<II", mach, at + 8)
        at += size
    return None


def check(mach):
    """Problems with the signature of one slice (empty when it holds), and a summary."""
    found = signature(mach)
    if found is None:
        return ["no code signature"], "unsigned"
    offset, size = found
    blob = mach[offset : offset + size]
    count = struct.unpack_from(">I", blob, 8)[0]
    for i in range(count):
        _, at = struct.unpack_from(">II", blob, 12 + 8 * i)
        if struct.unpack_from(">I", blob, at)[0] != CSMAGIC_CODEDIRECTORY:
            continue
        cd = blob[at:]
        hash_at, _, _, pages, limit, hash_size, hash_type, _, page_log = struct.unpack_from(
            ">IIIIIBBBB", cd, 16
        )
        problems = []
        if hash_type != CS_HASHTYPE_SHA256:
            problems.append(f"hash type {hash_type}, not SHA-256")
        if limit != offset:
            problems.append(f"signs {limit} bytes, but the signature starts at {offset}")
        page = 1 << page_log
        bad = [
            k
            for k in range(pages)
            if hashlib.sha256(mach[k * page : min((k + 1) * page, limit)]).digest()
            != cd[hash_at + k * hash_size : hash_at + (k + 1) * hash_size]
        ]
        if bad:
            problems.append(f"{len(bad)} of {pages} pages do not match their hash (first: {bad[0]})")
        return problems, f"{pages} pages of {page} bytes signed up to byte {limit}"
    return ["no CodeDirectory in the signature"], "unreadable signature"


def main(path):
    failed = False
    for cpu, mach in slices(open(path, "rb").read()):
        problems, summary = check(mach)
        if cpu != CPU_ARM64 and problems == ["no code signature"]:
            problems = []  # x86_64 code may run unsigned
        name = CPU_NAMES.get(cpu, hex(cpu))
        print(f"{name}: {summary}" + "".join(f"; FAILED: {p}" for p in problems))
        failed |= bool(problems)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
