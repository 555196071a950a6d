"""Renders fixtures/blender/cryptomatte_fixup/fixup.exr with Blender 3.4 (Cycles, 8×4, one
sample, Normal and Position passes): two planes whose materials are named so that the MurmurHash3_32 of the names has an
exponent of all ones (`Glass_42`, 7f982061) and of all zeros (`Glass_339`, 000e7c10), the two
cases of Cryptomatte's exponent fix-up. Blender writes the raw hash in the manifest and the
fixed-up bits (7f182061, 008e7c10) in the pixels.

    blender -b --factory-startup -noaudio --python scripts/blender/make_cryptomatte_fixup.py -- OUT.exr
"""

import sys

import bpy

NAMES = ["Glass_42", "Glass_339"]

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.samples = 1
scene.cycles.use_denoising = False
for layer in scene.view_layers:
    layer.cycles.denoising_store_passes = False
scene.render.resolution_x = 8
scene.render.resolution_y = 4
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(camera)
camera.location = (0, 0, 5)
scene.camera = camera
for k, name in enumerate(NAMES):
    bpy.ops.mesh.primitive_plane_add(size=2, location=(-1 + 2 * k, 0, 0))
    bpy.context.active_object.data.materials.append(bpy.data.materials.new(name))
layer = scene.view_layers[0]
layer.use_pass_cryptomatte_material = True
# cos θ for glassdb's reader: world-space Normal and Position.
layer.use_pass_normal = True
layer.use_pass_position = True
scene.render.image_settings.file_format = "OPEN_EXR_MULTILAYER"
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
