"""The `relit` scene (make_glassdb_scene.py) with the scene's own Cycles light groups (issue 29,
docs/blender.md "Light groups"): the sun, a second, lower sun and the world in group `sun`, a
warm point lamp and a small area lamp inside the room in group `warm`.

    blender -b relit.blend --python-exit-code 1 \
        -P scripts/blender/make_light_groups_scene.py -- --out groups.blend [--property]

With `--property` the warm lamp carries the custom property `glassdb_light = "A"` (the group's
spectrum without `--light`). `--ungrouped` leaves the area lamp in no group (a scene glassdb
must refuse). The scene is saved as `--out`.

Licence: same as the project, MIT OR Apache-2.0.
"""

import math
import os
import sys

import bpy


def lamp(scene, name, kind, energy, colour, location, group):
    """A lamp object of `kind` at `location` in light group `group`, linked to the scene."""
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    data.color = colour
    ob = bpy.data.objects.new(name, data)
    ob.location = location
    ob.lightgroup = group
    scene.collection.objects.link(ob)
    return ob


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    out = argv[argv.index("--out") + 1] if "--out" in argv else sys.exit("--out FILE is needed")
    scene = bpy.context.scene
    vl = bpy.context.view_layer
    for name in ("sun", "warm"):
        if name not in vl.lightgroups:
            vl.lightgroups.add(name=name)
    scene.objects["Sun"].lightgroup = "sun"
    scene.world.lightgroup = "sun"
    # A second sun, lower and from the other side of the facade's normal.
    low = lamp(scene, "Sun_low", "SUN", 1.5, (1.0, 0.85, 0.7), (0.0, 0.0, 0.0), "sun")
    low.data.angle = math.radians(1.0)
    low.rotation_euler = (math.radians(70.0), 0.0, math.radians(160.0))
    # The warm interior: a bulb under the ceiling and a small area lamp over the table.
    bulb = lamp(scene, "Bulb", "POINT", 150.0, (1.0, 0.75, 0.5), (0.5, 1.0, 2.5), "warm")
    bulb.data.shadow_soft_size = 0.125
    if "--property" in argv:
        bulb["glassdb_light"] = "A"
    desk = lamp(scene, "Desk", "AREA", 40.0, (1.0, 0.8, 0.6), (-0.5, 0.125, 2.0),
                "" if "--ungrouped" in argv else "warm")
    desk.data.size = 0.5
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out))


main()
