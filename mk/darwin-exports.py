#!/usr/bin/env python3
"""Removes from the export trie of each slice of a Mach-O dylib every name but the fmi2* and fmi3*
functions (and fmi2-shell's sampling entry gearRattleDoStepSampled): zig's linker exports `__mh_dylib_header` and `___dso_handle` (the Mach-O header)
from every dylib it links, which Apple's ld keeps private. mk/darwin-link.py has already
hidden every other symbol before the link.

The trie is rebuilt from the kept entries (their flags and addresses as they were) and
written where the old one was, its size in LC_DYLD_INFO(_ONLY) or LC_DYLD_EXPORTS_TRIE
updated. This breaks the arm64 slice's code signature: `llvm-strip`, which runs next
(mk/portable.mk), lays out the link-edit data again and re-signs it.

Usage: darwin-exports.py IN OUT
"""

import os
import re
import shutil
import struct
import sys

FAT_MAGIC, MH_MAGIC_64 = 0xCAFEBABE, 0xFEEDFACF
LC_DYLD_INFO, LC_DYLD_INFO_ONLY, LC_DYLD_EXPORTS_TRIE = 0x22, 0x80000022, 0x80000033
KEEP = re.compile(r"_(fmi[23]\w+|gearRattleDoStepSampled)")


def read_uleb(data, at):
    value = shift = 0
    while True:
        byte = data[at]
        at += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if byte < 0x80:
            return value, at


def uleb(value):
    out = bytearray()
    while True:
        byte, value = value & 0x7F, value >> 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def entries(trie, at=0, prefix=""):
    """(name, terminal bytes: flags and address as encoded) of every exported name."""
    size, at = read_uleb(trie, at)
    if size:
        yield prefix, bytes(trie[at : at + size])
    at += size
    count, at = trie[at], at + 1
    for _ in range(count):
        end = trie.index(0, at)
        label, at = trie[at:end].decode(), end + 1
        child, at = read_uleb(trie, at)
        yield from entries(trie, child, prefix + label)


class Node:
    def __init__(self):
        self.terminal = b""
        self.edges = []  # (label, Node)
        self.offset = 0

    def insert(self, name, terminal):
        if not name:
            self.terminal = terminal
            return
        for i, (label, child) in enumerate(self.edges):
            common = os.path.commonprefix([label, name])
            if common == label:
                return child.insert(name[len(label) :], terminal)
            if common:  # split the edge where the names part
                middle = Node()
                middle.edges.append((label[len(common) :], child))
                self.edges[i] = (common, middle)
                return middle.insert(name[len(common) :], terminal)
        leaf = Node()
        leaf.terminal = terminal
        self.edges.append((name, leaf))

    def nodes(self):
        yield self
        for _, child in self.edges:
            yield from child.nodes()

    def encode(self):
        out = bytearray(uleb(len(self.terminal)) + self.terminal + bytes([len(self.edges)]))
        for label, child in self.edges:
            out += label.encode() + b"\0" + uleb(child.offset)
        return bytes(out)


def build(kept):
    """The trie of the (name, terminal) pairs, as ld64 lays it out: nodes in preorder, their
    offsets recomputed until the ULEB128 sizes of the edges settle."""
    root = Node()
    for name, terminal in kept:
        root.insert(name, terminal)
    nodes = list(root.nodes())
    while True:
        offset, moved = 0, False
        for node in nodes:
            moved |= node.offset != offset
            node.offset = offset
            offset += len(node.encode())
        if not moved:
            return b"".join(node.encode() for node in nodes)


def rewrite(data, start):
    """Rebuilds the export trie of the Mach-O image at data[start:] in place; the names
    it dropped."""
    if struct.unpack_from("<I", data, start)[0] != MH_MAGIC_64:
        sys.exit("darwin-exports.py: not a 64-bit Mach-O image")
    ncmds, at = struct.unpack_from("<I", data, start + 16)[0], start + 32
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<II", data, at)
        field = {LC_DYLD_INFO: 40, LC_DYLD_INFO_ONLY: 40, LC_DYLD_EXPORTS_TRIE: 8}.get(cmd)
        if field:
            offset, length = struct.unpack_from("<II", data, at + field)
            if length:
                old = data[start + offset : start + offset + length]
                found = list(entries(old))
                kept = [e for e in found if KEEP.fullmatch(e[0])]
                new = build(kept)
                assert sorted(entries(new)) == sorted(kept), "rebuilt trie differs"
                data[start + offset : start + offset + length] = new.ljust(length, b"\0")
                struct.pack_into("<I", data, at + field + 4, len(new))
                return [name for name, _ in found if not KEEP.fullmatch(name)]
        at += size
    sys.exit("darwin-exports.py: no export trie found")


def main(src, dst):
    data = bytearray(open(src, "rb").read())
    if struct.unpack_from(">I", data)[0] == FAT_MAGIC:
        starts = [
            struct.unpack_from(">I", data, 8 + 20 * i + 8)[0]
            for i in range(struct.unpack_from(">I", data, 4)[0])
        ]
    else:
        starts = [0]
    for start in starts:
        dropped = rewrite(data, start)
        print(f"darwin-exports.py: slice at {start}: dropped {' '.join(dropped) or 'nothing'}")
    with open(dst, "wb") as f:
        f.write(data)
    shutil.copymode(src, dst)


if __name__ == "__main__":
    main(*sys.argv[1:])
