#!/usr/bin/env python3
"""What shadows cost on the Blender path at 1920x1080 (docs/verification.md#visibility).

Builds a Blender scene of about 100,000 triangles (four UV spheres of about 25,000 triangles on
a ground plane) in a temporary folder, then:

- runs scripts/blender_gbuffer.py with --visibility off and with the default (which also writes
  the occluders), timing each;
- runs `lookdev render --spp 1` on the g-buffer with an empty cache (the trace), again (the
  cache), and with --no-visibility, each under /usr/bin/time -v for wall time and peak memory.

    cargo build --release && python3 benches/blender_visibility.py [--lookdev target/release/lookdev]
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

SCENE = """
import bpy
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.resolution_x, scene.render.resolution_y = 1920, 1080
scene.render.resolution_percentage = 100
bpy.ops.mesh.primitive_plane_add(size=12)
for i, (x, y) in enumerate([(-1.5, -1.5), (1.5, -1.5), (-1.5, 1.5), (1.5, 1.5)]):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(x, y, 1.0), segments=128, ring_count=100)
    bpy.ops.object.shade_smooth()
camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(camera)
scene.camera = camera
camera.location = (0.0, -11.0, 6.5)
camera.rotation_euler = (1.05, 0.0, 0.0)
bpy.ops.wm.save_as_mainfile(filepath=OUT)
"""


def timed(command, **kwargs):
    start = time.monotonic()
    result = subprocess.run(command, capture_output=True, text=True, **kwargs)
    if result.returncode != 0:
        sys.exit(f"{' '.join(command)} failed:\n{result.stdout[-2000:]}{result.stderr[-2000:]}")
    return time.monotonic() - start, result


def measured(command, env):
    _, result = timed(["/usr/bin/time", "-v"] + command, env=env)
    wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", result.stderr)
    hours, minutes, seconds = wall.groups()
    seconds = int(hours or 0) * 3600 + int(minutes) * 60 + float(seconds)
    memory = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", result.stderr).group(1)) / 1024
    return seconds, memory


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--lookdev", default="target/release/lookdev")
    parser.add_argument("--blender", default="blender")
    args = parser.parse_args()
    lookdev = os.path.abspath(args.lookdev)
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts", "blender_gbuffer.py")
    with tempfile.TemporaryDirectory() as folder:
        blend = os.path.join(folder, "scene.blend")
        builder = os.path.join(folder, "scene.py")
        with open(builder, "w") as out:
            out.write(f"OUT = {blend!r}\n" + SCENE)
        timed([args.blender, "-b", "--python-exit-code", "2", "--python", builder])
        rows = []
        for visibility in ["off", "32"]:
            out = os.path.join(folder, f"gbuffer-{visibility}.exr")
            command = [args.blender, "-b", blend, "--python-exit-code", "2", "--python", script, "--"]
            seconds, _ = timed(command + ["--out", out, "--visibility", visibility])
            rows.append((f"blender_gbuffer.py --visibility {visibility}", seconds, None))
        occluders = os.path.join(folder, "gbuffer-32.occluders.glb")
        print(f"occluders: {os.path.getsize(occluders) / 1e6:.1f} MB")
        env = dict(os.environ, XDG_CACHE_HOME=os.path.join(folder, "cache"))
        render = [lookdev, "render", "--gbuffer", os.path.join(folder, "gbuffer-32.exr"), "--spp", "1", "--quiet"]
        render += ["--out", os.path.join(folder, "out.exr")]
        for label, extra in [("render, tracing", []), ("render, cached", []), ("render --no-visibility", ["--no-visibility"])]:
            seconds, memory = measured(render + extra, env)
            rows.append((f"lookdev {label}", seconds, memory))
    print(f"{'step':<44} {'wall s':>8} {'peak MiB':>9}")
    for label, seconds, memory in rows:
        print(f"{label:<44} {seconds:>8.1f} {'' if memory is None else f'{memory:.0f}':>9}")


main()
