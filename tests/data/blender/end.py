# The end of the Blender test scenes: the world lit by the environment, then what `mode` asks.
world = bpy.data.worlds.new("World")
scene.world = world
world.use_nodes = True
texture = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
texture.image = bpy.data.images.load(environment)
world.node_tree.links.new(texture.outputs["Color"], world.node_tree.nodes["Background"].inputs["Color"])
layer = scene.view_layers[0]
layer.cycles.denoising_store_passes = False
settings = scene.render.image_settings
scene.render.filepath = out
if mode == "blend":
    bpy.ops.wm.save_as_mainfile(filepath=out)
elif mode == "plain":
    scene.cycles.samples = 16
    layer.use_pass_normal = layer.use_pass_position = layer.use_pass_z = True
    layer.use_pass_cryptomatte_object = layer.use_pass_cryptomatte_material = layer.use_pass_cryptomatte_asset = True
    settings.file_format = 'OPEN_EXR_MULTILAYER'
    settings.color_depth = '32'
    bpy.ops.render.render(write_still=True)
elif mode == "beauty":
    scene.cycles.samples = beauty_samples
    scene.cycles.max_bounces = 0
    settings.file_format = 'OPEN_EXR'
    settings.color_depth = '32'
    start = time.perf_counter()
    bpy.ops.render.render()
    print(f"render seconds: {time.perf_counter() - start:.3f}")
    bpy.data.images["Render Result"].save_render(out, scene=scene)
elif mode.startswith("catcher:"):
    bpy.data.objects[mode.split(":", 1)[1]].is_shadow_catcher = True
    layer.cycles.use_pass_shadow_catcher = True
    scene.cycles.samples = beauty_samples
    scene.cycles.max_bounces = 0
    settings.file_format = 'OPEN_EXR_MULTILAYER'
    settings.color_depth = '32'
    bpy.ops.render.render(write_still=True)
