#!/usr/bin/env python3
"""Bake time, memory and file size with and without visibility (docs/verification.md#visibility).

Writes a 100,000-triangle asset (four UV spheres of about 25,000 triangles on a ground plane) to
a temporary folder, then runs `lookdev bake` at 1920x1080 with --visibility off, 16 and 32,
each under /usr/bin/time -v, and prints wall time, peak memory and the g-buffer's size.

    cargo build --release && python3 benches/bake_visibility.py [--lookdev target/release/lookdev]
"""

import argparse
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile


def sphere(centre, radius, segments, rings):
    positions, normals, indices = [], [], []
    for ring in range(rings + 1):
        theta = math.pi * ring / rings
        for segment in range(segments + 1):
            phi = 2 * math.pi * segment / segments
            n = (math.sin(theta) * math.sin(phi), math.cos(theta), math.sin(theta) * math.cos(phi))
            positions.append(tuple(c + radius * k for c, k in zip(centre, n)))
            normals.append(n)
    row = segments + 1
    for ring in range(rings):
        for segment in range(segments):
            a, b = ring * row + segment, (ring + 1) * row + segment
            indices += [a, b, b + 1, a, b + 1, a + 1]
    return positions, normals, indices


def ground(half):
    positions = [(-half, 0, -half), (-half, 0, half), (half, 0, half), (half, 0, -half)]
    return positions, [(0, 1, 0)] * 4, [0, 1, 2, 0, 2, 3]


def write_glb(path, meshes):
    binary = bytearray()
    views, accessors, gltf_meshes, nodes = [], [], [], []

    def view(data, target):
        while len(binary) % 4:
            binary.append(0)
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data), "target": target})
        binary.extend(data)
        return len(views) - 1

    for name, (positions, normals, indices) in meshes:
        p = view(b"".join(struct.pack("<3f", *v) for v in positions), 34962)
        lo = [min(v[k] for v in positions) for k in range(3)]
        hi = [max(v[k] for v in positions) for k in range(3)]
        accessors.append({"bufferView": p, "componentType": 5126, "count": len(positions), "type": "VEC3", "min": lo, "max": hi})
        n = view(b"".join(struct.pack("<3f", *v) for v in normals), 34962)
        accessors.append({"bufferView": n, "componentType": 5126, "count": len(normals), "type": "VEC3"})
        i = view(struct.pack(f"<{len(indices)}I", *indices), 34963)
        accessors.append({"bufferView": i, "componentType": 5125, "count": len(indices), "type": "SCALAR"})
        base = len(accessors) - 3
        gltf_meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": base, "NORMAL": base + 1}, "indices": base + 2}]})
        nodes.append({"name": name, "mesh": len(gltf_meshes) - 1})
    while len(binary) % 4:
        binary.append(0)
    document = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": gltf_meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(binary)}],
    }
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(binary)))
        f.write(struct.pack("<I4s", len(text), b"JSON") + text)
        f.write(struct.pack("<I4s", len(binary), b"BIN\0") + bytes(binary))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lookdev", default="target/release/lookdev")
    parser.add_argument("--size", nargs=2, type=int, default=[1920, 1080])
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        model = os.path.join(folder, "spheres.glb")
        meshes = [(f"sphere{k}", sphere((2.2 * k - 3.3, 1.0, 0.0), 1.0, 158, 79)) for k in range(4)]
        meshes.append(("ground", ground(8.0)))
        write_glb(model, meshes)
        triangles = sum(len(m[2]) // 3 for _, m in meshes)
        print(f"asset: {triangles} triangles; bake at {args.size[0]}x{args.size[1]}, 16 samples")
        print(f"{'visibility':>10} {'wall':>9} {'peak RSS':>10} {'g-buffer':>10}")
        for visibility in ["off", "16", "32"]:
            out = os.path.join(folder, f"g-{visibility}.exr")
            command = ["/usr/bin/time", "-v", args.lookdev, "bake", model, "--out", out, "--quiet",
                       "--auto-camera", "--pitch", "25", "--size", *map(str, args.size), "--visibility", visibility]
            result = subprocess.run(command, capture_output=True, text=True)
            if result.returncode != 0:
                sys.exit(result.stderr)
            wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", result.stderr)
            seconds = int(wall.group(1) or 0) * 3600 + int(wall.group(2)) * 60 + float(wall.group(3))
            rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", result.stderr).group(1)) / 1024
            size = os.path.getsize(out) / 2**20
            print(f"{visibility:>10} {seconds:>8.2f}s {rss:>7.0f} MiB {size:>6.1f} MiB")


if __name__ == "__main__":
    main()
