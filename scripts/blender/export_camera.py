#!/usr/bin/env python3
"""Write the scene camera of a .blend file as a glassdb camera JSON (docs/scene.md).

    blender -b scene.blend --python-exit-code 1 -P scripts/blender/export_camera.py -- \
        --out camera.json [--frames 1-24] [--axes obj|blender]

Without --frames, every frame of the scene's range (Output › Frame Range). One frame gives one
camera; several give `{"frames": {"1": {…}, …}}`, which
`glassdb mask scene.obj --camera camera.json -o mask.####.png` renders frame by frame.

Every field comes from Blender: `matrix_world` (Object › Transform, evaluated at each frame,
so keyframes, parents and constraints are included), Focal Length, Sensor Fit / Width /
Height, Shift X / Y (Camera › Lens and Sensor), Resolution X / Y × % and Aspect X / Y
(Output › Format).

`--axes obj` (default) expresses the camera in the coordinates of an OBJ exported with
Blender's default axes (Forward −Z, Up Y: Blender's (x, y, z) is the file's (x, z, −y)), so it
matches `glassdb mask`'s scene; `--axes blender` keeps Blender's Z-up world (for an OBJ
exported with Forward Y, Up Z).

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import os
import sys

import bpy
from bpy_extras.io_utils import axis_conversion

# The camera JSON is written by glassdb's Blender integration (one definition of the fields).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "integrations", "blender"))
from glassdb_blender import camera_json  # noqa: E402


def parse_args(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    out, frames, axes = None, None, "obj"
    while args:
        flag = args.pop(0)
        if not args:
            sys.exit(f"{flag} needs a value")
        value = args.pop(0)
        if flag == "--out":
            out = value
        elif flag == "--frames":
            first, _, last = value.partition("-")
            frames = range(int(first), int(last or first) + 1)
        elif flag == "--axes" and value in ("obj", "blender"):
            axes = value
        else:
            sys.exit(f"unknown option {flag} {value}")
    if out is None:
        sys.exit("usage: blender -b scene.blend -P export_camera.py -- --out camera.json "
                 "[--frames A-B] [--axes obj|blender]")
    return out, frames, axes


def main():
    out, frames, axes = parse_args(sys.argv)
    scene = bpy.context.scene
    if scene.camera is None:
        sys.exit("the scene has no camera")
    if axes == "obj":
        to_file = axis_conversion(
            from_forward="Y", from_up="Z", to_forward="-Z", to_up="Y"
        ).to_4x4()
    else:
        to_file = axis_conversion().to_4x4()  # identity
    if frames is None:
        frames = range(scene.frame_start, scene.frame_end + 1)
    cameras = {}
    for f in frames:
        scene.frame_set(f)
        cameras[str(f)] = camera_json(scene, to_file)
    doc = next(iter(cameras.values())) if len(cameras) == 1 else {"frames": cameras}
    with open(out, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    print(f"wrote {len(cameras)} camera(s) to {out}")


main()
