"""Writes a lookdev-ready g-buffer from a Blender scene.

    blender -b shot.blend --python-exit-code 2 --python scripts/blender_gbuffer.py -- --out shot.exr
        [--size W H] [--samples N] [--view-layer NAME] [--camera NAME]
        [--matte-material NAME]... [--matte-attribute NAME]... [--visibility SIDE|auto|off] [--supersample N]

It renders the scene's active camera with Cycles into one multilayer OpenEXR holding what
lookdev reads (docs/formats.md#production-renders):

- the Normal and Position passes (world space, Z up), and Depth;
- Cryptomatte object, material and asset layers (ids, coverage, names and mattes);
- the camera, in the render's metadata note, so that lookdev needs no --camera-position;
- the scene's shadow-casting triangles as they render (modifiers at render levels, instances
  made real), in lookdev's Y-up world, beside the EXR as NAME.occluders.glb and named in the
  note: lookdev traces each pixel's shadows and occlusion through them from the Position pass
  (docs/formats.md#occluders), over SIDE² directions (--visibility; by default lookdev's
  choice, 64² up to half a megapixel and 32² above);
- with --supersample N, N times the resolution on each side, recorded in the note: lookdev
  relights each pixel's surfaces apart and filters its renders down to the scene's resolution
  (docs/formats.md#supersampled-g-buffers);
- custom mattes on request, as shader AOVs named mask_<name>: 1 on the surfaces of each
  --matte-material, and the value of each --matte-attribute (a named attribute of the
  geometry, such as a painted vertex group or a colour attribute's first channel).

A g-buffer needs no light transport: the render takes no bounces, no denoising and few
samples (16, enough to antialias coverage). The .blend file is not changed; nothing is saved.
"""

import argparse
import array
import json
import os
import struct
import sys
import urllib.parse

import bpy
import mathutils


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="blender_gbuffer.py", description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True, help="the g-buffer to write (.exr)")
    parser.add_argument("--size", nargs=2, type=int, metavar=("W", "H"), help="resolution (default: the scene's)")
    parser.add_argument("--samples", type=int, default=16, help="samples per pixel (default 16)")
    parser.add_argument("--view-layer", help="the view layer to render (default: the first)")
    parser.add_argument("--camera", help="the camera object to render (default: the scene's)")
    parser.add_argument("--matte-material", action="append", default=[], help="a material to matte")
    parser.add_argument("--matte-attribute", action="append", default=[], help="a named attribute to matte")
    parser.add_argument(
        "--supersample",
        type=int,
        default=1,
        choices=range(1, 9),
        metavar="N",
        help="write N times the resolution on each side, for lookdev to relight each pixel's surfaces apart "
        "and filter down (1 to 8, default 1)",
    )
    parser.add_argument(
        "--visibility",
        default="auto",
        choices=["8", "16", "32", "64", "auto", "off"],
        help="directions a side lookdev traces shadows over; auto (the default) leaves the choice to lookdev: "
        "64 up to half a megapixel, 32 above; off writes no occluders",
    )
    return parser.parse_args(argv)


def fail(message):
    print(f"blender_gbuffer.py: error: {message}", file=sys.stderr)
    sys.exit(2)


def aov_output(tree, name):
    """A shader node writing into the AOV of this name (Blender 3 names it by its name, 4 by
    aov_name)."""
    output = tree.nodes.new("ShaderNodeOutputAOV")
    if hasattr(output, "aov_name"):
        output.aov_name = name
    else:
        output.name = name
    return output


def add_matte(view_layer, name):
    aov = view_layer.aovs.get(f"mask_{name}") or view_layer.aovs.add()
    aov.name = f"mask_{name}"
    aov.type = "VALUE"


def matte_material(material, name):
    """Writes 1 into the AOV mask_<name> wherever this material shades."""
    material.use_nodes = True
    output = aov_output(material.node_tree, f"mask_{name}")
    output.inputs["Value"].default_value = 1.0


def matte_attribute(material, name):
    """Writes the named attribute into the AOV mask_<name>."""
    material.use_nodes = True
    tree = material.node_tree
    attribute = tree.nodes.new("ShaderNodeAttribute")
    attribute.attribute_type = "GEOMETRY"
    attribute.attribute_name = name
    output = aov_output(tree, f"mask_{name}")
    tree.links.new(attribute.outputs["Fac"], output.inputs["Value"])


def camera_note(camera):
    """The camera as lookdev reads it from the render's metadata note: its position, the
    direction it looks in (its −Z), and its projection, in Blender's own (Z-up) world."""
    world = camera.matrix_world
    position = world.translation
    forward = (world.to_3x3() @ mathutils.Vector((0.0, 0.0, -1.0))).normalized()
    projection = "orthographic" if camera.data.type == "ORTHO" else "perspective"
    numbers = lambda v: ",".join(f"{c:.9g}" for c in v)
    return f"lookdev.camera position={numbers(position)} forward={numbers(forward)} projection={projection}"


# Kinds of object Cycles renders as triangles.
GEOMETRY = {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES", "POINTCLOUD", "VOLUME"}


def render_visibility(scene, view_layer):
    """Makes the scene evaluate as it renders: objects and collections shown as in the render,
    modifiers on and subdivided as in the render. Nothing is saved, so the .blend is unchanged."""
    for collection in bpy.data.collections:
        collection.hide_viewport = collection.hide_render

    def show(layer_collection):
        layer_collection.hide_viewport = False
        for child in layer_collection.children:
            show(child)

    show(view_layer.layer_collection)
    for obj in view_layer.objects:
        obj.hide_viewport = obj.hide_render
        obj.hide_set(False, view_layer=view_layer)
        for modifier in obj.modifiers:
            modifier.show_viewport = modifier.show_render
            if hasattr(modifier, "render_levels"):
                modifier.levels = modifier.render_levels


def shadow_casters(view_layer):
    """The triangles of every object instance that casts shadows: per instance, its vertices
    (float32 x, y, z in the object's space), its corner indices (uint32) and its world matrix."""
    depsgraph = view_layer.depsgraph
    depsgraph.update()
    casters = []
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type not in GEOMETRY or not obj.visible_shadow:
            continue
        try:
            mesh = obj.to_mesh()
        except RuntimeError:
            continue
        if mesh is None:
            continue
        mesh.calc_loop_triangles()
        vertices = array.array("f", [0.0]) * (len(mesh.vertices) * 3)
        mesh.vertices.foreach_get("co", vertices)
        corners = array.array("I", [0]) * (len(mesh.loop_triangles) * 3)
        mesh.loop_triangles.foreach_get("vertices", corners)
        obj.to_mesh_clear()
        if corners:
            casters.append((vertices, corners, instance.matrix_world.copy()))
    return casters


def write_glb(path, casters):
    """A binary glTF with a mesh and a node for each caster, under a root node that turns
    Blender's Z-up world to glTF's Y up, (x, y, z) -> (x, z, -y). Written beside, then renamed
    into place."""
    if sys.byteorder != "little":
        fail("writing occluders needs a little-endian machine")
    binary = bytearray()
    accessors, views, meshes, nodes = [], [], [], []

    def view(data, target):
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data), "target": target})
        binary.extend(data)
        return len(views) - 1

    for vertices, corners, world in casters:
        xs, ys, zs = vertices[0::3], vertices[1::3], vertices[2::3]
        accessors.append({
            "bufferView": view(vertices.tobytes(), 34962),
            "componentType": 5126,
            "count": len(vertices) // 3,
            "type": "VEC3",
            "min": [min(xs), min(ys), min(zs)],
            "max": [max(xs), max(ys), max(zs)],
        })
        accessors.append({
            "bufferView": view(corners.tobytes(), 34963),
            "componentType": 5125,
            "count": len(corners),
            "type": "SCALAR",
        })
        meshes.append({"primitives": [{"attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1}]})
        columns = [world[row][column] for column in range(4) for row in range(4)]
        nodes.append({"mesh": len(meshes) - 1, "matrix": columns})
    root = {"name": "Z up", "matrix": [1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1]}
    root["children"] = list(range(1, len(nodes) + 1))
    document = {
        "asset": {"version": "2.0", "generator": "lookdev blender_gbuffer.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [root] + nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(binary)}],
    }
    text = json.dumps(document, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary.extend(b"\0" * (-len(binary) % 4))
    length = 12 + 8 + len(text) + 8 + len(binary)
    temporary = path + ".part"
    with open(temporary, "wb") as out:
        out.write(struct.pack("<4sII", b"glTF", 2, length))
        out.write(struct.pack("<I4s", len(text), b"JSON") + text)
        out.write(struct.pack("<I4s", len(binary), b"BIN\0") + binary)
    os.replace(temporary, path)


def occluders_path(out):
    stem = out[: -len(".exr")] if out.lower().endswith(".exr") else out
    return stem + ".occluders.glb"


def main():
    args = arguments()
    scene = bpy.context.scene
    if args.camera:
        camera = bpy.data.objects.get(args.camera)
        if camera is None or camera.type != "CAMERA":
            fail(f"--camera {args.camera}: no camera object of that name")
        scene.camera = camera
    if scene.camera is None:
        fail("the scene has no camera; give one with --camera NAME")
    view_layer = scene.view_layers.get(args.view_layer) if args.view_layer else scene.view_layers[0]
    if view_layer is None:
        fail(f"--view-layer {args.view_layer}: no such view layer")
    for layer in scene.view_layers:
        layer.use = layer == view_layer

    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.samples = args.samples
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    cycles.max_bounces = 0
    view_layer.cycles.denoising_store_passes = False
    if args.size:
        scene.render.resolution_x, scene.render.resolution_y = args.size
        scene.render.resolution_percentage = 100
    if args.supersample > 1:
        # The output size as Blender makes it, then N times that, exactly.
        render = scene.render
        width = render.resolution_x * render.resolution_percentage // 100
        height = render.resolution_y * render.resolution_percentage // 100
        render.resolution_x, render.resolution_y = width * args.supersample, height * args.supersample
        render.resolution_percentage = 100

    view_layer.use_pass_normal = True
    view_layer.use_pass_position = True
    view_layer.use_pass_z = True
    view_layer.use_pass_cryptomatte_object = True
    view_layer.use_pass_cryptomatte_material = True
    view_layer.use_pass_cryptomatte_asset = True
    view_layer.pass_cryptomatte_depth = 6

    for name in args.matte_material:
        material = bpy.data.materials.get(name)
        if material is None:
            fail(f"--matte-material {name}: no such material")
        add_matte(view_layer, name)
        matte_material(material, name)
    for name in args.matte_attribute:
        add_matte(view_layer, name)
        for material in bpy.data.materials:
            matte_attribute(material, name)

    note = camera_note(scene.camera)
    if args.supersample > 1:
        note += f" supersample={args.supersample}"
    if args.visibility != "off":
        render_visibility(scene, view_layer)
        casters = shadow_casters(view_layer)
        if not casters:
            print("blender_gbuffer.py: no object casts shadows; no occluders are written")
        else:
            path = occluders_path(bpy.path.abspath(args.out))
            write_glb(path, casters)
            triangles = sum(len(corners) for _, corners, _ in casters) // 3
            print(f"blender_gbuffer.py: {triangles} shadow-casting triangles written to {path}")
            name = urllib.parse.quote(os.path.basename(path))
            note += f" occluders={name}"
            if args.visibility != "auto":
                note += f" visibility={args.visibility}"
    scene.render.use_stamp_note = True
    scene.render.stamp_note_text = note
    scene.render.use_compositing = False
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.filepath = args.out
    bpy.ops.render.render(write_still=True)


main()
