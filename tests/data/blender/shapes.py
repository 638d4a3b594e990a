grey = material("Grey", (0.5, 0.5, 0.5), 0.0, 0.6)
def finish(name, mat):
    o = bpy.context.object
    o.name = name
    o.data.materials.append(mat)
    return o
bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 0, 0)); finish("Ground", grey)
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, location=(-1.3, 0.3, 0.7), segments=64, ring_count=32)
bpy.ops.object.shade_smooth(); finish("Ball", gold)
# An open box: a cube without its top face, given walls by a solidify modifier.
bpy.ops.mesh.primitive_cube_add(size=1.4, location=(0.9, 0.4, 0.7))
box = finish("Box", red)
box.rotation_euler = (0, 0, 0.4)
bm = bmesh.new(); bm.from_mesh(box.data)
bm.faces.ensure_lookup_table()
top = [f for f in bm.faces if f.normal.z > 0.9]
bmesh.ops.delete(bm, geom=top, context='FACES')
bm.to_mesh(box.data); bm.free()
solid = box.modifiers.new("walls", 'SOLIDIFY'); solid.thickness = 0.08
bpy.ops.mesh.primitive_torus_add(major_radius=0.45, minor_radius=0.15, location=(-0.1, -1.2, 0.15))
bpy.ops.object.shade_smooth(); finish("Ring", red)
camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(camera)
scene.camera = camera
camera.location = (0.3, -6.5, 4.2)
camera.rotation_euler = (0.98, 0, 0.04)
