#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets, fuzz/corpus/<target>/ (docs/reliability.md):
the tests' fixtures, copied, and small valid inputs built here with the standard library only.
Run from anywhere; rewrites the generated files, keeps nothing else. The settings corpus also
gets each preset's full TOML, written by `cargo run -p hikari-fuzz --example preset_seeds`
(run separately, see docs/reliability.md), since only the Rust side knows the presets' values.
"""
import base64
import json
import pathlib
import shutil
import struct
import zlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
CORPUS = ROOT / "fuzz/corpus"


def put(target, name, data):
    d = CORPUS / target
    d.mkdir(parents=True, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    (d / name).write_bytes(data)


# --- PNG ---------------------------------------------------------------------------------------

def png(width, height, rows, color_type=6, bit_depth=8, palette=None, filter_type=1):
    """A PNG of `rows` (each a bytes object of one row's samples), every row with `filter_type`
    (0 none, 1 Sub), so gradients compress to almost nothing."""
    bpp = max(1, {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[color_type] * bit_depth // 8)
    raw = b""
    for row in rows:
        if filter_type == 1:
            row = bytes((row[i] - (row[i - bpp] if i >= bpp else 0)) & 0xFF for i in range(len(row)))
        raw += bytes([filter_type]) + row

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    out = b"\x89PNG\r\n\x1a\n"
    out += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0))
    if palette:
        out += chunk(b"PLTE", palette)
    out += chunk(b"IDAT", zlib.compress(raw, 9))
    return out + chunk(b"IEND", b"")


def lut_strip_png(width, image_rows, grade=lambda c: c):
    """An image `width` wide (a multiple of 32, at most 2048) and `image_rows` high with the
    LUT strip of `grade` (a function of 8-bit r, g, b) below it, laid out as lut_strip.rs says."""
    tiles_per_row = min(width // 32, 64)
    band = 32 * -(-64 // tiles_per_row)
    px = [[(40, 80, 120, 255)] * width for _ in range(image_rows)]
    px += [[(0, 0, 0, 255)] * width for _ in range(band)]
    for b in range(32):
        for copy in range(2):
            tile = b if copy == 0 else 63 - b
            tx, ty = tile % tiles_per_row, tile // tiles_per_row
            for g in range(32):
                for r in range(32):
                    c = grade(tuple(round(v * 255 / 31) for v in (r, g, b)))
                    px[image_rows + ty * 32 + g][tx * 32 + r] = (*c, 255)
    rows = [bytes(v for p in row for v in p) for row in px]
    return png(width, image_rows + band, rows)


def pngs():
    put("lut_strip_png", "identity_strip_2048.png", lut_strip_png(2048, 2))
    put("lut_strip_png", "warm_strip_1024.png",
        lut_strip_png(1024, 1, lambda c: (min(255, c[0] + 20), c[1], max(0, c[2] - 20))))
    put("lut_strip_png", "rgb_1x1.png", png(1, 1, [b"\x10\x20\x30"], color_type=2, filter_type=0))
    put("lut_strip_png", "grey16_3x2.png",
        png(3, 2, [b"\x00\x01\x80\x00\xff\xff"] * 2, color_type=0, bit_depth=16, filter_type=0))
    put("lut_strip_png", "palette_4x1.png",
        png(4, 1, [b"\x00\x01\x02\x03"], color_type=3, palette=b"\xff\x00\x00\x00\xff\x00\x00\x00\xff\xff\xff\xff", filter_type=0))
    put("lut_strip_png", "grey_alpha_2x2.png", png(2, 2, [b"\x10\xff\x20\x80"] * 2, color_type=4, filter_type=0))


# --- glTF --------------------------------------------------------------------------------------

def data_uri(blob, mime="application/octet-stream"):
    return f"data:{mime};base64," + base64.b64encode(blob).decode()


def cube_geometry():
    """A unit cube: 24 vertices (positions, normals, uvs) and 36 u16 indices."""
    pos, nrm, uv, idx = [], [], [], []
    faces = [((1, 0, 0), (0, 1, 0)), ((-1, 0, 0), (0, 1, 0)), ((0, 1, 0), (0, 0, 1)),
             ((0, -1, 0), (0, 0, 1)), ((0, 0, 1), (0, 1, 0)), ((0, 0, -1), (0, 1, 0))]
    for n, u in faces:
        v = (n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0])
        base = len(pos)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            pos.append(tuple(0.5 * (n[k] + su * u[k] + sv * v[k]) for k in range(3)))
            nrm.append(n)
            uv.append(((su + 1) / 2, (sv + 1) / 2))
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, uv, idx


def cube_doc(texture_png):
    """A textured cube with a camera, a punctual light, a node hierarchy and the extensions and
    extras hikari reads; returns (document, binary buffer)."""
    pos, nrm, uv, idx = cube_geometry()
    blob = b"".join(struct.pack("<3f", *p) for p in pos)
    blob += b"".join(struct.pack("<3f", *n) for n in nrm)
    blob += b"".join(struct.pack("<2f", *t) for t in uv)
    blob += b"".join(struct.pack("<H", i) for i in idx)
    n = len(pos)
    views = [
        {"buffer": 0, "byteOffset": 0, "byteLength": 12 * n, "target": 34962},
        {"buffer": 0, "byteOffset": 12 * n, "byteLength": 12 * n, "target": 34962},
        {"buffer": 0, "byteOffset": 24 * n, "byteLength": 8 * n, "target": 34962},
        {"buffer": 0, "byteOffset": 32 * n, "byteLength": 2 * len(idx), "target": 34963},
    ]
    doc = {
        "asset": {"version": "2.0", "generator": "tools/fuzz_seeds.py"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength",
                           "KHR_texture_transform", "KHR_materials_specular"],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": len(idx), "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob)}],
        "images": [{"uri": data_uri(texture_png, "image/png")}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 33071}],
        "textures": [{"source": 0, "sampler": 0}],
        "materials": [
            {"name": "painted", "pbrMetallicRoughness": {
                "baseColorFactor": [0.8, 0.7, 0.6, 1.0],
                "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                    "offset": [0.5, 0.0], "scale": [2.0, 2.0], "rotation": 0.3}}},
                "metallicFactor": 0.0, "roughnessFactor": 0.7},
             "extensions": {"KHR_materials_specular": {"specularFactor": 0.5}},
             "extras": {"hikari": {"gi_albedo": [0.5, 0.5, 0.5], "interior": 0.25}}},
            {"name": "lamp", "emissiveFactor": [1.0, 0.9, 0.8],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 40.0}},
             "alphaMode": "MASK", "alphaCutoff": 0.4, "doubleSided": True,
             "extras": {"hikari": {"area_light": True}}},
        ],
        "meshes": [
            {"name": "cube", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                             "indices": 3, "material": 0}]},
            {"name": "lamp", "primitives": [{"attributes": {"POSITION": 0}, "indices": 3, "material": 1}]},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100.0, "aspectRatio": 1.5}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "color": [1.0, 0.9, 0.8], "intensity": 50.0, "range": 20.0,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}, "extras": {"hikari": {"radius": 0.1}}},
            {"type": "point", "intensity": 10.0}, {"type": "directional", "intensity": 3.0}]}},
        "nodes": [
            {"name": "root", "children": [1, 2, 3, 4], "scale": [2.0, 2.0, 2.0]},
            {"name": "box", "mesh": 0, "translation": [0.0, 0.5, 0.0], "rotation": [0.0, 0.383, 0.0, 0.924]},
            {"name": "lamp", "mesh": 1, "matrix": [0.1, 0, 0, 0, 0, 0.1, 0, 0, 0, 0, 0.1, 0, 1, 2, 0, 1]},
            {"name": "eye", "camera": 0, "translation": [0.0, 1.0, 5.0]},
            {"name": "light", "extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 3, 0],
             "extras": {"hikari": {"particles": {"half_extents": [1.0, 0.5, 1.5], "count": 8}}}},
        ],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    return doc, blob, views


def glb(doc, blob):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    blob += b"\0" * (-len(blob) % 4)
    body = struct.pack("<I4s", len(js), b"JSON") + js
    if blob:
        body += struct.pack("<I4s", len(blob), b"BIN\0") + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def gltfs():
    fixtures = ROOT / "crates/hikari-scene/tests/fixtures/malformed"
    for f in sorted(fixtures.iterdir()):
        if f.suffix in (".gltf", ".glb"):
            put("gltf", f.name, f.read_bytes())
            if f.suffix == ".glb":
                put("glb", f.name, f.read_bytes())
    tex = png(2, 2, [b"\xff\x00\x00\xff\x00\xff\x00\xff", b"\x00\x00\xff\xff\xff\xff\xff\xff"], filter_type=0)
    doc, blob, views = cube_doc(tex)
    doc["buffers"][0]["uri"] = data_uri(blob)
    text = json.dumps(doc, indent=1)
    put("gltf", "cube_data_uri.gltf", text)
    put("gltf_extras", "cube_data_uri.gltf", text)

    # The same cube as a .glb, its image in a buffer view.
    doc, blob, views = cube_doc(tex)
    del doc["images"][0]["uri"]
    pad = -len(blob) % 4
    views.append({"buffer": 0, "byteOffset": len(blob) + pad, "byteLength": len(tex)})
    doc["images"][0].update({"bufferView": 4, "mimeType": "image/png"})
    blob = blob + b"\0" * pad + tex
    doc["buffers"][0]["byteLength"] = len(blob)
    data = glb(doc, blob)
    put("gltf", "cube.glb", data)
    put("glb", "cube.glb", data)

    # A quantized triangle (KHR_mesh_quantization: normalized i16 positions, u8 indices) with a
    # sparse accessor moving one vertex.
    blob = struct.pack("<9h", 0, 0, 0, 32767, 0, 0, 0, 32767, 0) + b"\0\0"
    blob += struct.pack("<3B", 0, 1, 2) + b"\0"
    blob += struct.pack("<B", 2) + b"\0\0\0" + struct.pack("<3f", 0.0, 0.5, 0.5)
    tri = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"],
        "buffers": [{"byteLength": len(blob), "uri": data_uri(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 18},
                        {"buffer": 0, "byteOffset": 20, "byteLength": 3},
                        {"buffer": 0, "byteOffset": 24, "byteLength": 1},
                        {"buffer": 0, "byteOffset": 28, "byteLength": 12}],
        "accessors": [
            {"bufferView": 0, "componentType": 5122, "normalized": True, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5121, "count": 3, "type": "SCALAR"},
            {"componentType": 5126, "count": 3, "type": "VEC3",
             "sparse": {"count": 1, "indices": {"bufferView": 2, "componentType": 5121},
                        "values": {"bufferView": 3}}},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 2}, "indices": 1}]}],
        "nodes": [{"mesh": 0}, {"mesh": 0, "translation": [2, 0, 0]}],
        "scenes": [{"nodes": [0, 1]}],
    }
    put("gltf", "quantized_sparse.gltf", json.dumps(tri))
    put("glb", "quantized_sparse.glb", glb({**tri, "buffers": [{"byteLength": len(blob)}]}, blob))

    # Probe volumes and reflection probes marked in node extras (hikari-bake).
    marked = {
        "asset": {"version": "2.0"},
        "nodes": [
            {"name": "hall", "children": [1, 2], "translation": [10, 0, 0]},
            {"name": "volume", "scale": [4, 2, 4], "extras": {"hikari": {"probe_volume": {"spacing": 1.5}}}},
            {"name": "probe", "translation": [0, 1, 0],
             "extras": {"hikari": {"reflection_probe": {"capture": [0, 0.5, 0], "blend": 0.5}}}},
            {"name": "plain", "extras": {"hikari": {"probe_volume": True, "reflection_probe": True}}},
        ],
        "scenes": [{"nodes": [0, 3]}],
        "scene": 0,
    }
    put("gltf_extras", "marked_nodes.gltf", json.dumps(marked, indent=1))
    put("gltf_extras", "marked_nodes.glb", glb(marked, b""))
    put("gltf", "marked_nodes.gltf", json.dumps(marked))


# --- settings, .cube, bake ---------------------------------------------------------------------

def settings():
    put("settings_toml", "config.example.toml", (ROOT / "docs/config.example.toml").read_bytes())
    for p in ("low", "medium", "high", "ultra"):
        put("settings_toml", f"preset_{p}_line.toml", f'preset = "{p}"\n')
    put("settings_toml", "overrides.toml",
        'scene = "village"\nwidth = 640\n[sun_shadows]\ncascades = 3\n\0ultra\n'
        "sun_shadows.cascades=2\nexposure.ev100 = 12.5\ntaa.enabled=false\n")


def cubes():
    for f in sorted((ROOT / "crates/hikari-render/tests/fixtures").glob("*.cube")):
        put("cube", f.name, f.read_bytes())
    lines = ['TITLE "identity 2"', "# a comment", "LUT_3D_SIZE 2", "DOMAIN_MIN 0 0 0", "DOMAIN_MAX 1 1 1", ""]
    lines += [f"{r} {g} {b}" for b in (0, 1) for g in (0, 1) for r in (0, 1)]
    put("cube", "identity_2.cube", "\n".join(lines) + "\n")
    lines = ["LUT_3D_SIZE 3", "DOMAIN_MIN -0.5 0 0", "DOMAIN_MAX 2 1 1.5"]
    lines += [f"{r / 2:.6f} {g / 2:.6f} {1 - b / 2:.6f}" for b in range(3) for g in range(3) for r in range(3)]
    put("cube", "size_3_domain.cube", "\r\n".join(lines))


def bakes():
    """Small bakes, by the format table in hikari-probes' docs: no sections, and one small
    tetrahedral mesh (the full fixture's 112 kB grid tile would slow every execution)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("pbf", ROOT / "tools/probe_bake_fixture.py")
    pbf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(pbf)
    mesh, mesh_probes = pbf.mesh_section()
    for name, sections, flags in (("empty.hkprobe", [], 1), ("mesh_only.hkprobe", [(2, mesh_probes, mesh)], 1),
                                  ("mesh_checkpoint.hkprobe", [(2, mesh_probes, mesh)], 0)):
        offset = 80 + 24 * len(sections)
        table = b""
        for kind, count, payload in sections:
            table += struct.pack("<IIQQ", kind, count, offset, len(payload))
            offset += len(payload)
        header = b"HIKPROBE" + struct.pack("<IIQ", 1, flags, offset + 4) + bytes(range(32))
        header += struct.pack("<If3fI", 256, 12.5, 1.5, 10.0, 30.0, len(sections))
        body = header + table + b"".join(s[2] for s in sections)
        put("probe_bake", name, body + struct.pack("<I", zlib.crc32(body)))


def main():
    for target in ("gltf", "glb", "gltf_extras", "settings_toml", "cube", "lut_strip_png", "probe_bake"):
        d = CORPUS / target
        if d.exists():
            for f in d.iterdir():
                if not f.name.startswith("preset_") or f.name.endswith("_line.toml"):
                    f.unlink()
    gltfs()
    settings()
    cubes()
    pngs()
    bakes()
    total = sum(f.stat().st_size for f in CORPUS.rglob("*") if f.is_file())
    print(f"wrote {CORPUS} ({total} bytes)")


if __name__ == "__main__":
    main()
