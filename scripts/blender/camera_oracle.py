#!/usr/bin/env python3
"""Blender's own camera projection, for checking glassdb's camera JSON (docs/scene.md).

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P scripts/blender/camera_oracle.py -- --out fixtures/blender/cameras_b34.json

Sets up cameras procedurally (no .blend file): positions, rotations and object scales, Focal
Length, Sensor Fit / Width / Height, Shift X / Y, the render resolution and pixel Aspect X / Y.
For each it writes the glassdb camera JSON (the `matrix_world` form with the Blender lens
fields), Blender's view plane at unit depth (from `Object.calc_matrix_camera`, the projection
matrix Blender renders with) and the image position, in glassdb's pixels (x right, y down, from
the top-left corner), of a few world points by `bpy_extras.object_utils.world_to_camera_view`.
crates/scene/tests/blender_camera.rs compares glassdb's camera with these numbers.

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import sys

import bpy
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Euler, Vector

# (resolution, aspect x, aspect y, lens mm, sensor w, sensor h, fit, shift x, shift y,
#  location, rotation (deg, XYZ), object scale)
CASES = [
    ((320, 240), 1, 1, 50, 36, 24, "AUTO", 0, 0, (7.36, -6.93, 4.96), (63.6, 0, 46.7), (1, 1, 1)),
    ((320, 240), 1, 1, 50, 36, 24, "HORIZONTAL", 0, 0, (0, 0, 0), (90, 0, 0), (1, 1, 1)),
    ((320, 240), 1, 1, 50, 36, 24, "VERTICAL", 0, 0, (1, 2, 3), (80, 10, -30), (1, 1, 1)),
    ((240, 320), 1, 1, 50, 36, 24, "AUTO", 0, 0, (-2, 5, 1.5), (95, 0, 180), (1, 1, 1)),
    ((240, 320), 1, 1, 28, 30, 20, "VERTICAL", 0.1, -0.2, (0, -8, 2), (88, 0, 0), (2, 2, 2)),
    ((320, 240), 1, 1, 35, 36, 24, "AUTO", 0.25, -0.1, (3, -4, 1.7), (90, 0, 30), (1, 1, 1)),
    ((200, 100), 2, 1, 50, 36, 24, "AUTO", 0, 0, (0, -6, 1), (90, 0, 0), (1, 3, 0.5)),
    ((100, 150), 1, 2, 50, 36, 24, "AUTO", 0, 0, (0, -6, 1), (90, 0, 0), (1, 1, 1)),
    ((100, 100), 1, 2, 50, 36, 24, "AUTO", 0.1, 0.2, (0, -6, 1), (85, 5, 10), (1, 1, 1)),
    ((1920, 1080), 1, 1, 24, 36, 24, "AUTO", 0, 0.15, (2, -9, 1.6), (90, 0, 12), (1, 1, 1)),
    ((1080, 1920), 3, 2, 85, 23.5, 15.6, "HORIZONTAL", -0.3, 0.05, (-1, -7, 2), (92, 3, -8), (0.2, 0.2, 0.2)),
    ((64, 48), 1, 1, 18, 36, 24, "VERTICAL", 0.5, 0.5, (4, 4, 4), (55, 0, 135), (1, 1, 1)),
]

POINTS = [
    (0.0, 0.0, 0.0),
    (1.0, 0.5, 0.2),
    (-0.7, 1.3, 1.1),
    (0.3, -1.2, 0.8),
    (2.0, 2.0, 0.0),
]


def out_path(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) != 2 or args[0] != "--out":
        sys.exit("usage: blender -b -P camera_oracle.py -- --out FILE.json")
    return args[1]


def main():
    path = out_path(sys.argv)
    scene = bpy.context.scene
    cam_ob = scene.camera
    cam = cam_ob.data
    r = scene.render
    r.resolution_percentage = 100
    cases = []
    for (res, ax, ay, lens, sw, sh, fit, sx, sy, loc, rot, scale) in CASES:
        r.resolution_x, r.resolution_y = res
        r.pixel_aspect_x, r.pixel_aspect_y = ax, ay
        cam.type = "PERSP"
        cam.lens, cam.sensor_width, cam.sensor_height, cam.sensor_fit = lens, sw, sh, fit
        cam.shift_x, cam.shift_y = sx, sy
        cam_ob.location = loc
        cam_ob.rotation_euler = Euler([math.radians(a) for a in rot], "XYZ")
        cam_ob.scale = scale
        bpy.context.view_layer.update()
        depsgraph = bpy.context.evaluated_depsgraph_get()
        p = cam_ob.calc_matrix_camera(depsgraph, x=res[0], y=res[1], scale_x=ax, scale_y=ay)
        # perspective_m4: P[0][0] = 2n/(r−l), P[0][2] = (r+l)/(r−l); at unit depth l/n, r/n.
        view = [
            (p[0][2] - 1) / p[0][0],
            (p[0][2] + 1) / p[0][0],
            (p[1][2] - 1) / p[1][1],
            (p[1][2] + 1) / p[1][1],
        ]
        points = []
        for q in POINTS:
            ndc = world_to_camera_view(scene, cam_ob, Vector(q))
            points.append({
                "world": list(q),
                "depth": ndc.z,
                "pixel": [ndc.x * res[0], (1.0 - ndc.y) * res[1]],
            })
        camera = {
            "matrix_world": [list(row) for row in cam_ob.matrix_world],
            "focal_length_mm": lens,
            "sensor_width_mm": sw,
            "sensor_height_mm": sh,
            "sensor_fit": fit.lower(),
            "shift_x": sx,
            "shift_y": sy,
            "pixel_aspect": ax / ay,
            "width": res[0],
            "height": res[1],
        }
        cases.append({"camera": camera, "view_plane": view, "points": points})
    doc = {
        "blender": bpy.app.version_string,
        "made_by": "scripts/blender/camera_oracle.py",
        "cases": cases,
    }
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(f"wrote {len(cases)} cameras to {path}")


main()
