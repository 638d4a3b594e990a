#!/usr/bin/env python3
"""lookdev against Cycles' direct light with shadows, on a Blender scene (docs/verification.md#visibility).

    cargo build --release && python3 benches/compare_cycles.py [--gltf ASSET.glb] [--size 320 240]
        [--spp 64] [--cycles-spp 64] [--reference-spp 2048] [--supersample 2] [--visibility auto]
        [--repeats 3]
        [--env FILE.exr] [--rotation DEG] [--lookdev PATH] [--blender PATH] [--keep DIR]

The scene is the one tests/blender_shadows.rs renders (a ground, a gold ball, an open red box and
a red ring, tests/data/blender/shapes.py), or with --gltf an asset standing on a grey ground,
every one of its materials replaced by one red paint (the comparison is of light, not of glTF
materials). Blender builds it, `scripts/blender_gbuffer.py` writes its g-buffer and occluders,
and `lookdev render` relights it with the materials the scene gives its objects.

It prints two tables:

- **Accuracy**: lookdev's render at --reference-spp against Cycles' (no bounces, the same
  samples), per object inside it (pixels whose 3x3 neighbourhood the object wholly covers, by
  the g-buffer's Cryptomatte), at the edges (every other covered pixel) and over every covered
  pixel: the bias of the mean luminance and the mean relative error of the pixels' luminance.
  The edges are split into those the objects cover wholly between them and those over the
  background.
  Rows for the g-buffer without its shadows (--no-visibility), with them, and supersampled.
- **Speed at equal quality**: each renderer's relative MSE against its own --reference-spp render,
  over the wholly covered pixels, and its time: Cycles' render alone (bpy.ops.render.render,
  timed in Blender, scene synchronisation included) and its process; lookdev's process with the
  visibility cached (the look-dev loop), and the first render's trace apart. Efficiency is
  1 / (time x relative MSE); the ratio is how many times faster lookdev reaches the same error.
"""

import argparse
import json
import os
import re
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, str(Path(__file__).resolve().parent))
import exr_read  # noqa: E402
from compare_mitsuba import efficiency, read_rgb, rel_mse  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
SCENES = REPO / "tests" / "data" / "blender"

# An asset on a ground: the glTF joined into one object, "Asset", in red paint, standing on a grey
# ground, seen from the front and a little above.
ASSET_SCENE = """
import mathutils
grey = material("Grey", (0.5, 0.5, 0.5), 0.0, 0.6)
bpy.ops.preferences.addon_enable(module="io_scene_gltf2")
bpy.ops.import_scene.gltf(filepath=GLTF)
meshes = [o for o in scene.objects if o.type == 'MESH']
bpy.ops.object.select_all(action='DESELECT')
for o in meshes:
    o.select_set(True)
bpy.context.view_layer.objects.active = meshes[0]
if len(meshes) > 1:
    bpy.ops.object.join()
asset = bpy.context.view_layer.objects.active
asset.name = "Asset"
asset.data.materials.clear()
asset.data.materials.append(red)
corners = [asset.matrix_world @ mathutils.Vector(c) for c in asset.bound_box]
low = mathutils.Vector([min(c[i] for c in corners) for i in range(3)])
high = mathutils.Vector([max(c[i] for c in corners) for i in range(3)])
centre, size = (low + high) / 2, max(high - low)
bpy.ops.mesh.primitive_plane_add(size=8 * size, location=(centre.x, centre.y, low.z))
bpy.context.object.name = "Ground"
bpy.context.object.data.materials.append(grey)
camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(camera)
scene.camera = camera
camera.location = centre + mathutils.Vector((0.35, -2.2, 0.9)) * size
camera.rotation_euler = (centre - camera.location).to_track_quat('-Z', 'Y').to_euler()
"""

# After the scene's own script: in `blend` mode, each object's material as lookdev sets it.
MATERIALS = """
if mode == "blend":
    import json
    materials = {}
    for o in scene.objects:
        if o.type == 'MESH' and o.material_slots and o.material_slots[0].material:
            p = o.material_slots[0].material.node_tree.nodes["Principled BSDF"].inputs
            materials[o.name] = {
                "base_color": list(p["Base Color"].default_value)[:3],
                "metallic": p["Metallic"].default_value,
                "roughness": p["Roughness"].default_value,
                "specular": p["Specular"].default_value,
            }
    with open(out + ".materials.json", "w") as f:
        json.dump(materials, f)
"""

CRYPTO_LAYER = "ViewLayer.CryptoObject"


# --- measuring -------------------------------------------------------------------------------


def cryptomatte(planes, attributes, layer, pixels):
    """Per object name, per pixel, its coverage in a Cryptomatte layer (from the specification:
    rank pairs whose id is the name's hash, stored as float bits with the exponent kept in
    1..254). `planes` holds the channels as floats, `attributes` the header's text values."""
    key = next(k[: -len("/name")] for k, v in attributes.items() if k.endswith("/name") and v == layer)
    manifest = json.loads(attributes[f"{key}/manifest"])
    objects = {}
    for name, digest in manifest.items():
        hashed = int(digest, 16)
        exponent = min(max((hashed >> 23) & 0xFF, 1), 254)
        wanted = (hashed & 0x807FFFFF) | (exponent << 23)
        coverage = [0.0] * pixels
        rank = 0
        while f"{layer}{rank:02d}.r" in planes:
            channel = [planes[f"{layer}{rank:02d}.{c}"] for c in "rgba"]
            for ids, amounts in ((channel[0], channel[1]), (channel[2], channel[3])):
                for p in range(pixels):
                    if float_bits(ids[p]) == wanted:
                        coverage[p] += amounts[p]
            rank += 1
        objects[name] = coverage
    return objects


def float_bits(value):
    return struct.unpack("<I", struct.pack("<f", value))[0]


def inside(coverage, width, height):
    """The pixels whose 3x3 neighbourhood `coverage` covers wholly (none on the frame's border)."""
    whole = [c >= 1.0 for c in coverage]
    return [
        y * width + x
        for y in range(1, height - 1)
        for x in range(1, width - 1)
        if all(whole[(y + dy) * width + x + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1))
    ]


def luminance(rgb, p):
    return 0.2126 * rgb[3 * p] + 0.7152 * rgb[3 * p + 1] + 0.0722 * rgb[3 * p + 2]


def bias_and_error(ours, theirs, pixels):
    """The bias of the mean luminance of `ours` over `pixels` against `theirs`, and the mean
    relative error of the pixels' luminance (flat RGB images)."""
    if not pixels:
        raise ValueError("no pixels to compare")
    mean = lambda image: sum(luminance(image, p) for p in pixels) / len(pixels)  # noqa: E731
    relative = sum(abs(luminance(ours, p) - luminance(theirs, p)) / max(luminance(theirs, p), 1e-3) for p in pixels)
    return mean(ours) / mean(theirs) - 1.0, relative / len(pixels)


def read_mattes(gbuffer):
    """Each object's coverage in the script's g-buffer, by its Cryptomatte."""
    data = Path(gbuffer).read_bytes()
    attributes, _ = exr_read._header(data, gbuffer)
    text = {k: v.decode("utf-8", "replace") for k, (kind, v) in attributes.items() if kind == "string"}
    width, height, planes = exr_read.read(gbuffer)
    return width, height, cryptomatte(planes, text, CRYPTO_LAYER, width * height)


# --- running ---------------------------------------------------------------------------------


def run(command, **kwargs):
    """Runs a command; returns its wall time and stdout. Fails with its output on an error."""
    start = time.perf_counter()
    done = subprocess.run([str(c) for c in command], capture_output=True, text=True, **kwargs)
    seconds = time.perf_counter() - start
    if done.returncode != 0 or "Error:" in done.stdout:
        raise SystemExit(f"{' '.join(map(str, command))} failed:\n{done.stdout[-3000:]}{done.stderr[-3000:]}")
    return seconds, done.stdout


class Blender:
    """The scene's script at a resolution, and the renders Blender makes of it."""

    def __init__(self, opts, work):
        self.opts, self.work = opts, work
        self.options, self.env = [], None
        body = (SCENES / "shapes.py").read_text()
        if opts.gltf:
            body = f"GLTF = {str(opts.gltf.resolve())!r}\n{ASSET_SCENE}"
            self.options, self.env = ["--python-use-system-env"], lend_numpy(work)
        self.body = f"scene.render.resolution_x, scene.render.resolution_y = {opts.size[0]}, {opts.size[1]}\n{body}"

    def script(self, samples, seed):
        path = self.work / f"scene-{samples}-{seed}.py"
        start, end = (SCENES / "start.py").read_text(), (SCENES / "end.py").read_text()
        settings = f"beauty_samples = {samples}\nscene.cycles.seed = {seed}\n"
        path.write_text(f"{start}{settings}{self.body}{MATERIALS}{end}")
        return path

    def scene(self, mode, out, samples=16, seed=0):
        command = [self.opts.blender, "-b", *self.options, "--python-exit-code", "2"]
        command += ["--python", self.script(samples, seed), "--", mode, out, self.opts.env]
        return run(command, env=self.env)

    def beauty(self, out, samples, seed):
        """Cycles' direct light: (the render's own seconds, the process's)."""
        seconds, stdout = self.scene("beauty", out, samples, seed)
        return float(re.search(r"render seconds: ([\d.]+)", stdout).group(1)), seconds

    def gbuffer(self, blend, out, supersample):
        script = REPO / "scripts" / "blender_gbuffer.py"
        command = [self.opts.blender, "-b", blend, "--python-exit-code", "2", "--python", script, "--"]
        command += ["--out", out, "--supersample", str(supersample), "--visibility", str(self.opts.visibility)]
        return run(command)[0]


def lend_numpy(work):
    """An environment that lends Blender this Python's NumPy, which Blender's glTF importer needs
    and Debian's Blender lacks (the two Pythons must share their minor version)."""
    try:
        import numpy
    except ImportError:
        raise SystemExit("compare_cycles: --gltf needs NumPy in this Python, to lend to Blender's glTF importer")
    site = Path(numpy.__file__).resolve().parent.parent
    lent = work / "numpy-for-blender"
    lent.mkdir(exist_ok=True)
    for name in ("numpy", "numpy.libs"):
        if (site / name).exists() and not (lent / name).exists():
            (lent / name).symlink_to(site / name)
    return dict(os.environ, PYTHONPATH=str(lent))


def write_look(path, materials):
    lines = []
    for name, params in materials.items():
        lines += [f"[[object]]\nname = {json.dumps(name)}\n[[object.layer]]\n[object.layer.set]"]
        lines += [f"{key} = {json.dumps(value)}" for key, value in params.items()]
    path.write_text("\n".join(lines) + "\n")


def lookdev(opts, work, gbuffer, out, spp, seed, extra=()):
    """`lookdev render` of a g-buffer with the scene's look; its wall time."""
    # The HDRIs' lossy compression leaves a few slightly negative texels, which lookdev
    # refuses unless told to make them 0 (as its built-in copies of them are).
    command = [opts.lookdev, "render", "--gbuffer", gbuffer, "--look", work / "look.toml", "--env", opts.env, "--env-clamp"]
    command += ["--rotation", str(opts.rotation), "--spp", str(spp), "--seed", str(seed), "--quiet", "--out", out]
    env = dict(os.environ, XDG_CACHE_HOME=str(work / "cache"))
    return run(command + list(extra), env=env)[0]


def median_of(repeats, measure):
    return statistics.median(measure() for _ in range(repeats))


# --- the comparison --------------------------------------------------------------------------


def accuracy(work, width, height, mattes, variants):
    """Rows of (variant, region, pixels, bias, mean relative error) against Cycles' reference."""
    _, _, cycles = read_rgb(work / "cycles-ref.exr")
    objects = {name: inside(coverage, width, height) for name, coverage in mattes.items()}
    interior = set(p for pixels in objects.values() for p in pixels)
    covered = [p for p in range(width * height) if any(c[p] > 0 for c in mattes.values())]
    regions = [(name, pixels) for name, pixels in objects.items() if pixels]
    edges = [p for p in covered if p not in interior]
    between = [p for p in edges if sum(c[p] for c in mattes.values()) >= 0.999]
    over_background = sorted(set(edges) - set(between))
    regions += [("edges", edges), ("edges between objects", between), ("edges over the background", over_background)]
    regions += [("every covered pixel", covered)]
    rows = []
    for variant, file in variants:
        _, _, ours = read_rgb(work / file)
        for region, pixels in regions:
            rows.append((variant, region, len(pixels), *bias_and_error(ours, cycles, pixels)))
    return rows


def print_table(header, rows):
    table = [header] + [[str(cell) for cell in row] for row in rows]
    widths = [max(len(row[i]) for row in table) for i in range(len(header))]
    for row in table:
        print("  ".join(cell.ljust(widths[i]) for i, cell in enumerate(row)).rstrip())


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--gltf", type=Path, help="an asset to stand on a ground instead of the test scene")
    parser.add_argument("--size", nargs=2, type=int, default=[320, 240], metavar=("W", "H"))
    parser.add_argument("--spp", type=int, default=64, help="lookdev's samples for the speed comparison")
    parser.add_argument("--cycles-spp", type=int, default=64, help="Cycles' samples for the speed comparison")
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--supersample", type=int, default=2, help="also a g-buffer this many times finer (1: not)")
    parser.add_argument("--visibility", default="auto", help="the script's --visibility: directions a side, or auto")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--env", type=Path, default=REPO / "src" / "environment" / "studio.exr")
    # Blender's equirectangular centre is +X; lookdev's is -Z.
    parser.add_argument("--rotation", type=float, default=-90.0)
    parser.add_argument("--lookdev", type=Path, default=REPO / "target" / "release" / "lookdev")
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--keep", type=Path, help="keep the renders in this folder")
    opts = parser.parse_args()
    opts.env, opts.lookdev = opts.env.resolve(), opts.lookdev.resolve()
    with tempfile.TemporaryDirectory() as temporary:
        work = opts.keep.resolve() if opts.keep else Path(temporary)
        work.mkdir(parents=True, exist_ok=True)
        compare(opts, work)
    return 0


def compare(opts, work):
    blender = Blender(opts, work)
    blender.scene("blend", work / "scene.blend")
    write_look(work / "look.toml", json.loads((work / "scene.blend.materials.json").read_text()))
    gbuffers = [("gbuffer.exr", 1)] + ([("gbuffer-fine.exr", opts.supersample)] if opts.supersample > 1 else [])
    for file, factor in gbuffers:
        seconds = blender.gbuffer(work / "scene.blend", work / file, factor)
        print(f"blender_gbuffer.py --supersample {factor}: {seconds:.1f} s")
    width, height, mattes = read_mattes(work / "gbuffer.exr")

    # The references take other seeds than the timed renders, whose samples they would include.
    cycles_ref, _ = blender.beauty(work / "cycles-ref.exr", opts.reference_spp, 1000)
    print(f"Cycles, {opts.reference_spp} samples: {cycles_ref:.1f} s")
    trace = lookdev(opts, work, work / "gbuffer.exr", work / "first.exr", 1, 1)
    print(f"lookdev's first render, tracing the visibility: {trace:.1f} s")
    variants = [("no shadows", "lookdev-ref-unshadowed.exr", work / "gbuffer.exr", ["--no-visibility"])]
    variants += [("shadows", "lookdev-ref.exr", work / "gbuffer.exr", [])]
    if opts.supersample > 1:
        variants += [(f"shadows, {opts.supersample}x g-buffer", "lookdev-ref-fine.exr", work / "gbuffer-fine.exr", [])]
    for _, file, gbuffer, extra in variants:
        lookdev(opts, work, gbuffer, work / file, opts.reference_spp, 1000, extra)

    rows = accuracy(work, width, height, mattes, [(v, f) for v, f, _, _ in variants])
    print(f"\nAccuracy at {opts.reference_spp} samples, {width}x{height}, --visibility {opts.visibility}, against Cycles:")
    rows = [(v, r, n, f"{b * 100:+.2f}%", f"{e * 100:.1f}%") for v, r, n, b, e in rows]
    print_table(["g-buffer", "pixels", "count", "bias", "mean relative error"], rows)

    covered = [sum(c[p] for c in mattes.values()) >= 0.999 for p in range(width * height)]
    cycles_times = [blender.beauty(work / "cycles.exr", opts.cycles_spp, 1) for _ in range(opts.repeats)]
    cycles_error = rel_mse(read_rgb(work / "cycles.exr")[2], read_rgb(work / "cycles-ref.exr")[2], covered)
    ours = median_of(opts.repeats, lambda: lookdev(opts, work, work / "gbuffer.exr", work / "lookdev.exr", opts.spp, 1))
    ours_error = rel_mse(read_rgb(work / "lookdev.exr")[2], read_rgb(work / "lookdev-ref.exr")[2], covered)
    timings = [
        (f"Cycles, render alone, {opts.cycles_spp} spp", statistics.median(t[0] for t in cycles_times), cycles_error),
        (f"Cycles, process, {opts.cycles_spp} spp", statistics.median(t[1] for t in cycles_times), cycles_error),
        (f"lookdev, process, {opts.spp} spp, visibility cached", ours, ours_error),
    ]
    print(f"\nSpeed at equal quality (median of {opts.repeats}; relative MSE over {sum(covered)} pixels):")
    rows = [(label, f"{t:.2f}", f"{e:.3g}", f"{efficiency(t, e):.3g}") for label, t, e in timings]
    print_table(["renderer", "time (s)", "relative MSE", "efficiency"], rows)
    ratios = [efficiency(ours, ours_error) / efficiency(t, e) for _, t, e in timings[:2]]
    print(f"lookdev / Cycles efficiency: {ratios[0]:.1f}x (render alone), {ratios[1]:.1f}x (process)")


if __name__ == "__main__":
    sys.exit(main())
