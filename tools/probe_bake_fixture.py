#!/usr/bin/env python3
"""Writes crates/hikari-probes/tests/fixtures/formula_bake.hkprobe: a bake file built from the
format table in hikari-probes' crate docs with Python's struct and zlib.crc32 only, so the Rust
reader and writer are checked against an encoder that shares no code with them.

Contents (the Rust test rebuilds the same values from these formulas):
  scene key bytes 0..31; 256 rays; spacing 12.5 m; layers 1.5, 10, 30 m; complete.
  One grid tile, coordinates (2, -1), origin x0 = 400, z0 = -200,
    ground[c] = 0.25 c - 3, for probe p: sky[k] = 0.001 p + 0.5 k,
    bounced[k][ch] = -0.002 p + 0.25 k + 0.125 ch, interior = p % 3 == 0.
  One tetrahedral mesh, id 7: the unit tetrahedron's corners plus (1, 1, 1), tetrahedra
    [0,1,2,3] and [1,2,3,4] sharing face (1,2,3); probe values by the tile's formulas with
    p = 1000 + index; interior = index % 3 == 0.
"""
import pathlib
import struct
import zlib

HULL = 0xFFFFFFFF


def probe_sh(p):
    out = b"".join(struct.pack("<f", 0.001 * p + 0.5 * k) for k in range(9))
    out += b"".join(
        struct.pack("<f", -0.002 * p + 0.25 * k + 0.125 * ch) for k in range(9) for ch in range(3)
    )
    return out


def tile_section():
    out = struct.pack("<ii", 2, -1) + struct.pack("<ff", 400.0, -200.0)
    out += b"".join(struct.pack("<f", 0.25 * c - 3.0) for c in range(256))
    out += b"".join(probe_sh(p) for p in range(768))
    out += bytes(1 if p % 3 == 0 else 0 for p in range(768))
    return out


def mesh_section():
    positions = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)]
    tets = [(0, 1, 2, 3), (1, 2, 3, 4)]
    # Tet 0's face opposite vertex 0 is (1,2,3), shared with tet 1, whose face opposite its
    # 4th vertex (probe 4) is the same one.
    adjacency = [(1, HULL, HULL, HULL), (HULL, HULL, HULL, 0)]
    out = struct.pack("<II", 7, len(tets))
    out += b"".join(struct.pack("<3f", *p) for p in positions)
    out += b"".join(probe_sh(1000 + i) for i in range(len(positions)))
    out += b"".join(struct.pack("<4I", *t) for t in tets)
    out += b"".join(struct.pack("<4I", *a) for a in adjacency)
    out += bytes(1 if i % 3 == 0 else 0 for i in range(len(positions)))
    return out, len(positions)


def main():
    tile = tile_section()
    mesh, mesh_probes = mesh_section()
    sections = [(1, 768, tile), (2, mesh_probes, mesh)]
    header_len, entry_len = 80, 24
    offset = header_len + entry_len * len(sections)
    table = b""
    for kind, count, payload in sections:
        table += struct.pack("<IIQQ", kind, count, offset, len(payload))
        offset += len(payload)
    total = offset + 4
    header = b"HIKPROBE" + struct.pack("<IIQ", 1, 1, total) + bytes(range(32))
    header += struct.pack("<If3fI", 256, 12.5, 1.5, 10.0, 30.0, len(sections))
    assert len(header) == header_len
    body = header + table + b"".join(s[2] for s in sections)
    data = body + struct.pack("<I", zlib.crc32(body))
    assert len(data) == total
    out = pathlib.Path(__file__).resolve().parent.parent / "crates/hikari-probes/tests/fixtures/formula_bake.hkprobe"
    out.write_bytes(data)
    print(f"wrote {out} ({len(data)} bytes)")


if __name__ == "__main__":
    main()
