"""A mask from the render itself, for docs/blender.md ("Masks: rasterised, or from the render"):
one Cycles render of a frame with Cryptomatte Material (6 levels) and the shader AOVs
`facing` = |N·I| and `plane` (a glass material's plane index) on the glass materials, as
`compose --mask-cryptomatte` reads them (docs/mask.md).

    blender -b scene.blend --factory-startup -noaudio --python-exit-code 1 \
        -P scripts/blender/render_mask_aovs.py -- --out mask_aovs.0001.exr --frame 1 \
        --plane Glass_clear=0 --plane Tinted_bronze=1 [--samples 64] [--seed 0]

Licence: same as the project, MIT OR Apache-2.0.
"""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fixture_scene  # noqa: E402


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    opts, planes = {}, {}
    while argv:
        flag, value = argv.pop(0), argv.pop(0)
        if flag == "--plane":
            name, _, k = value.partition("=")
            planes[name] = float(k)
        else:
            opts[flag] = value
    scene = bpy.context.scene
    for name, k in planes.items():
        nt = bpy.data.materials[name].node_tree
        fixture_scene.facing_aov(nt)
        plane = fixture_scene.aov_output(nt, "plane", (-200, -600))
        plane.inputs["Value"].default_value = k
    vl = scene.view_layers[0]
    vl.use_pass_cryptomatte_material = True
    vl.pass_cryptomatte_depth = 6
    for name in ("facing", "plane"):
        aov = vl.aovs.add()
        aov.name = name
        aov.type = "VALUE"
    scene.cycles.samples = int(opts.get("--samples", 64))
    scene.cycles.seed = int(opts.get("--seed", 0))
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 2
    fixture_scene.set_exr_format(scene.render.image_settings, multilayer=True, half=False)
    scene.frame_set(int(opts.get("--frame", 1)))
    scene.render.use_file_extension = False
    scene.render.filepath = opts["--out"]
    bpy.ops.render.render(write_still=True)


main()
