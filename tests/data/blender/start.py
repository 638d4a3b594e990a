# The start of the Blender test scenes (tests/common/blender.rs), and of benches/compare_cycles.py's:
# the arguments, an empty Cycles scene at 160x120 on the CPU, and the materials. A scene's own
# script follows, then end.py.
import bpy, bmesh, sys, time
mode, out, environment = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.engine = 'CYCLES'
scene.cycles.device = 'CPU'
scene.cycles.use_denoising = False
scene.cycles.use_adaptive_sampling = False
scene.render.resolution_x, scene.render.resolution_y = 160, 120
scene.render.resolution_percentage = 100
# Samples of the beauty and catcher renders.
beauty_samples = 256
def material(name, color, metallic, roughness):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.distribution = 'GGX'
    p.inputs["Base Color"].default_value = (*color, 1)
    p.inputs["Metallic"].default_value = metallic
    p.inputs["Roughness"].default_value = roughness
    p.inputs["Specular"].default_value = 0.5
    return m
red = material("Red Paint", (0.8, 0.1, 0.05), 0.0, 0.4)
gold = material("Gold", (1.0, 0.766, 0.336), 1.0, 0.3)
