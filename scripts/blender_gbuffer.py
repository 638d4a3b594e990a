"""Writes a lookdev-ready g-buffer from a Blender scene.

    blender -b shot.blend --python-exit-code 2 --python scripts/blender_gbuffer.py -- --out shot.exr
        [--size W H] [--samples N] [--view-layer NAME] [--camera NAME]
        [--matte-material NAME]... [--matte-attribute NAME]...

It renders the scene's active camera with Cycles into one multilayer OpenEXR holding what
lookdev reads (docs/formats.md#production-renders):

- the Normal and Position passes (world space, Z up), and Depth;
- Cryptomatte object, material and asset layers (ids, coverage, names and mattes);
- the camera, in the render's metadata note, so that lookdev needs no --camera-position;
- custom mattes on request, as shader AOVs named mask_<name>: 1 on the surfaces of each
  --matte-material, and the value of each --matte-attribute (a named attribute of the
  geometry, such as a painted vertex group or a colour attribute's first channel).

A g-buffer needs no light transport: the render takes no bounces, no denoising and few
samples (16, enough to antialias coverage). The .blend file is not changed; nothing is saved.
"""

import argparse
import sys

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

    scene.render.use_stamp_note = True
    scene.render.stamp_note_text = camera_note(scene.camera)
    scene.render.use_compositing = False
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.filepath = args.out
    bpy.ops.render.render(write_still=True)


main()
