"""The bundled dusk facade (issue 29, the README's first image): the corner of a glazed
two-storey building at dusk, seen from the street, for `glassdb blender render` with two light
groups and insulated units (their ghosts). scripts/blender/make_dusk_fixture.sh renders it
into fixtures/dusk/.

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P scripts/blender/make_dusk_facade_scene.py -- --out dusk.blend \
        [--size 960x540] [--samples 64] [--preview preview.exr]

The building stands in x <= 0, y <= 0 (metres, Z up). Two glazed facades meet at its corner:

- `Glass_tinted` (glass id 14 of fixtures/dusk/catalog.toml, Arctic Blue 6 | 12.7 air |
  clear 6, a body-tinted unit): the facade in the plane y = 0, normal +y;
- `Glass_clear` (id 11, clear 6 | 12.7 air | clear 6, as in the bundled catalogue): the facade
  in the plane x = 0, normal +x.

Each glass face is the unit's surface #1, its normal outdoors (docs/scene.md, "Units"):
the two units have different pane depths, so each facade is its own plane. Mullions stand in
front of the glass, a spandrel band and a parapet are opaque.

Two Cycles light groups (`view_layer.lightgroups`):

- `sun`: a low sun (5 degrees above the horizon, lighting the clear facade at a glance) and
  the dusk sky (the world);
- `warm`: every tungsten source: the lamps of the two lit floors inside (ceiling area lamps,
  pendant globes the camera sees), the light columns outside, 0.5 m in front of each
  facade (their double reflections are the units' ghosts), a street lamp and the lit windows
  of the buildings across the streets. Their colour is CIE illuminant A's white in linear
  Rec.709 (no white balance: a camera balanced to daylight sees tungsten orange), so the
  group matches a registry built with `--light warm=A --white-balance D65`.

Cycles, `--samples` (default 64) with a fixed seed (0), no adaptive sampling and no denoising
(Debian's Blender 3.4 is built without OpenImageDenoise; `glassdb blender render` turns
denoising off anyway). `--preview FILE.exr` also renders the saved scene's beauty (glass as
Blender's placeholder material) with its light-group layers, to look at the composition.

Licence: same as the project, MIT OR Apache-2.0.
"""

import math
import os
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fixture_scene  # noqa: E402

OPTS = fixture_scene.parse_options(
    sys.argv, "make_dusk_facade_scene.py", __doc__,
    {"out": None, "size": "960x540", "samples": "64", "preview": None},
    paths=("out", "preview"), values=("size", "samples"))
if not OPTS["out"]:
    sys.exit("make_dusk_facade_scene.py: --out FILE.blend is required")
WIDTH, _, HEIGHT = OPTS["size"].partition("x")

# CIE illuminant A's white (XYZ 1.09850, 1, 0.35585) in linear Rec.709 (the sRGB matrix of
# IEC 61966-2-1), scaled to a maximum of 1: what a daylight-balanced render shows a tungsten
# lamp as.
_A_XYZ = (1.09850, 1.0, 0.35585)
_M = ((3.2404542, -1.5371385, -0.4985314),
      (-0.9692660, 1.8760108, 0.0415560),
      (0.0556434, -0.2040259, 1.0572252))
_A_RGB = [sum(m * c for m, c in zip(row, _A_XYZ)) for row in _M]
TUNGSTEN = tuple(c / max(_A_RGB) for c in _A_RGB)

FLOOR_Z = (0.0, 3.8)        # the two storeys' floor levels
GLASS_Z = ((0.05, 3.2), (3.8, 6.9))   # each storey's glazing, bottom to top
SPANDREL_Z = (3.2, 3.8)
PARAPET_Z = (6.9, 7.5)
LENGTH = 14.0               # each facade runs 14 m from the corner
BAY = 1.5                   # mullion spacing
MULLION = (0.04, 0.10)      # half width, depth in front of the glass
CEILING_GAP = 0.3           # slab thickness under each storey's top glazing edge

scene = None
EMITTERS = ("Bulb", "Column", "Window_lit")


def material(name, rgb, roughness=0.8, emission=None, pass_index=0):
    mat = bpy.data.materials.new(name)
    fixture_scene.set_use_nodes(mat)
    mat.pass_index = pass_index
    nt = mat.node_tree
    if emission is not None:
        emit = nt.nodes.new("ShaderNodeEmission")
        emit.inputs["Color"].default_value = tuple(rgb) + (1.0,)
        emit.inputs["Strength"].default_value = emission
        nt.links.new(emit.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
        # Small emitters are seen, not sampled as lights: Blender 3.4 picks one light per
        # sample uniformly (no light tree before 3.5), and hundreds of tiny emissive
        # triangles would starve the lamps that light the rooms.
        if hasattr(mat.cycles, "sample_as_light"):
            mat.cycles.sample_as_light = False
        elif hasattr(mat.cycles, "emission_sampling"):
            mat.cycles.emission_sampling = "NONE"
        return mat
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = tuple(rgb) + (1.0,)
    bsdf.inputs["Roughness"].default_value = roughness
    return mat


def glass(name, pass_index):
    """A placeholder thin pane (10 % mirror, 75 % clear) for the preview; `glassdb blender
    render` replaces it by the registry's glass."""
    mat = material(name, (1.0, 1.0, 1.0), 0.0, pass_index=pass_index)
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    glossy = nt.nodes.new("ShaderNodeBsdfGlossy")
    glossy.inputs["Roughness"].default_value = 0.0
    glossy.inputs["Color"].default_value = (0.1, 0.1, 0.1, 1.0)
    clear = nt.nodes.new("ShaderNodeBsdfTransparent")
    clear.inputs["Color"].default_value = (0.75, 0.75, 0.75, 1.0)
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(glossy.outputs[0], add.inputs[0])
    nt.links.new(clear.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return mat


def seen_only(ob):
    """An emitter that is seen (by the camera, in reflections and through glass) but lights
    nothing: diffuse rays would find it only by chance (fireflies at these samples)."""
    ob.visible_diffuse = False
    ob.visible_volume_scatter = False


def mesh(name, verts, faces, mat, group=None):
    data = bpy.data.meshes.new(name)
    data.from_pydata(verts, [], faces)
    data.update()
    data.materials.append(mat)
    ob = bpy.data.objects.new(name, data)
    if group is not None:
        ob.lightgroup = group
    if mat.name in EMITTERS:
        seen_only(ob)
    scene.collection.objects.link(ob)
    return ob


def box(name, lo, hi, mat, group=None):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return mesh(name, v, f, mat, group)


def quad(name, corners, mat, group=None):
    return mesh(name, list(corners), [(0, 1, 2, 3)], mat, group)


def along(facade, s, depth):
    """The point `s` metres along `facade` ("A": the plane y = 0, running to -x; "B": the
    plane x = 0, running to -y) and `depth` metres in front of it (negative: inside)."""
    return (-s, depth) if facade == "A" else (depth, -s)


def facade_box(name, facade, s0, s1, d0, d1, z0, z1, mat, group=None):
    """A box spanning [s0, s1] along a facade, [d0, d1] in front of it, [z0, z1] in height."""
    (xa, ya), (xb, yb) = along(facade, s0, d0), along(facade, s1, d1)
    return box(name, (min(xa, xb), min(ya, yb), z0), (max(xa, xb), max(ya, yb), z1), mat, group)


def glazing(facade, mat):
    """One glass face per storey in the facade's plane, wound so that its normal points out."""
    for k, (z0, z1) in enumerate(GLASS_Z):
        if facade == "A":   # normal +y
            corners = [(-LENGTH, 0.0, z0), (-LENGTH, 0.0, z1), (0.0, 0.0, z1), (0.0, 0.0, z0)]
        else:               # normal +x
            corners = [(0.0, 0.0, z0), (0.0, 0.0, z1), (0.0, -LENGTH, z1), (0.0, -LENGTH, z0)]
        quad("Glazing_%s%d" % (facade, k), corners, mat)


def build():
    mats = {
        "Ground": material("Ground", (0.10, 0.10, 0.11), 0.7),
        "Kerb": material("Kerb", (0.35, 0.34, 0.32), 0.8),
        "Frame": material("Frame", (0.05, 0.05, 0.055), 0.35),
        "Panel": material("Panel", (0.16, 0.17, 0.18), 0.5),
        "Concrete": material("Concrete", (0.42, 0.40, 0.37), 0.9),
        "Oak": material("Oak", (0.45, 0.28, 0.14), 0.6),
        "Plaster": material("Plaster", (0.75, 0.73, 0.70), 0.9),
        "Teal": material("Teal", (0.05, 0.35, 0.38), 0.7),
        "Red": material("Red", (0.55, 0.08, 0.06), 0.6),
        "Leaf": material("Leaf", (0.08, 0.30, 0.07), 0.8),
        "Opposite": material("Opposite", (0.20, 0.19, 0.18), 0.9),
        "Bulb": material("Bulb", TUNGSTEN, emission=40.0),
        "Column": material("Column", TUNGSTEN, emission=25.0),
        "Window_lit": material("Window_lit", TUNGSTEN, emission=1.5),
        "Glass_tinted": glass("Glass_tinted", 14),
        "Glass_clear": glass("Glass_clear", 11),
    }

    # The street: asphalt, and a pavement along both facades.
    quad("Ground", [(-40, -40, 0), (40, -40, 0), (40, 40, 0), (-40, 40, 0)], mats["Ground"])
    box("Pavement_A", (-LENGTH - 2, 0.0, 0.0), (4.0, 4.0, 0.12), mats["Kerb"])
    box("Pavement_B", (0.0, -LENGTH - 2, 0.0), (4.0, 0.0, 0.12), mats["Kerb"])

    for facade, glass_mat in (("A", mats["Glass_tinted"]), ("B", mats["Glass_clear"])):
        glazing(facade, glass_mat)
        # Mullions in front of the glass, at every bay and at the corner.
        n_bays = int(LENGTH / BAY)
        for i in range(n_bays + 1):
            s = i * BAY
            facade_box("Mullion_%s%d" % (facade, i), facade, s - MULLION[0], s + MULLION[0],
                       0.0, MULLION[1], 0.0, PARAPET_Z[1], mats["Frame"])
        # Spandrel, parapet, and the slabs behind them.
        facade_box("Spandrel_%s" % facade, facade, 0.0, LENGTH, -0.35, 0.02, SPANDREL_Z[0],
                   SPANDREL_Z[1], mats["Panel"])
        facade_box("Parapet_%s" % facade, facade, 0.0, LENGTH, -0.35, 0.02, PARAPET_Z[0],
                   PARAPET_Z[1], mats["Panel"])
        facade_box("Sill_%s" % facade, facade, 0.0, LENGTH, -0.35, 0.04, 0.0, GLASS_Z[0][0],
                   mats["Panel"])
        # Light columns 0.5 m in front of the glass: what the units show twice.
        for k, s in enumerate((1.1, 3.35, 6.35)):
            facade_box("Column_%s%d" % (facade, k), facade, s - 0.04, s + 0.04, 0.46, 0.54,
                       0.12, 1.05, mats["Column"], group="warm")
            facade_box("Column_base_%s%d" % (facade, k), facade, s - 0.06, s + 0.06, 0.44, 0.56,
                       0.12, 0.2, mats["Frame"])

    # Inside: two storeys, floors, ceilings, back walls, columns and furniture.
    inner = -LENGTH
    for k, (z_floor, (g0, g1)) in enumerate(zip(FLOOR_Z, GLASS_Z)):
        quad("Floor_%d" % k, [(inner, inner, z_floor + 0.01), (-0.05, inner, z_floor + 0.01),
                              (-0.05, -0.05, z_floor + 0.01), (inner, -0.05, z_floor + 0.01)],
             mats["Oak"] if k == 0 else mats["Concrete"])
        quad("Ceiling_%d" % k, [(inner, inner, g1), (inner, -0.05, g1), (-0.05, -0.05, g1),
                                (-0.05, inner, g1)], mats["Plaster"])
        # The back walls of each storey, 7 m in, the whole length of each facade, and the
        # walls that close each wing at its far end: every ray through the glass meets a room.
        box("Back_A%d" % k, (-LENGTH, -7.2, z_floor), (-0.05, -7.0, g1), mats["Plaster"])
        box("Back_B%d" % k, (-7.2, -LENGTH, z_floor), (-7.0, -0.05, g1), mats["Teal" if k else "Plaster"])
        box("End_A%d" % k, (-LENGTH - 0.2, -7.2, z_floor), (-LENGTH, 0.0, g1), mats["Plaster"])
        box("End_B%d" % k, (-7.2, -LENGTH - 0.2, z_floor), (0.0, -LENGTH, g1), mats["Plaster"])
        for i, (x, y) in enumerate(((-3.0, -3.0), (-3.0, -6.0), (-6.0, -3.0), (-9.0, -3.0), (-3.0, -9.0))):
            box("Column_in_%d%d" % (k, i), (x - 0.2, y - 0.2, z_floor), (x + 0.2, y + 0.2, g1), mats["Concrete"])
        # The room's light: one large area lamp under each ceiling (Blender 3.4 samples one
        # light per bounce with no light tree: few large lamps keep the passes smooth at
        # these samples), and pendant globes the camera sees.
        lamp = bpy.data.lights.new("Ceiling_%d" % k, "AREA")
        lamp.shape = "RECTANGLE"
        lamp.size, lamp.size_y = 6.0, 6.0
        lamp.energy = 350.0
        lamp.color = TUNGSTEN
        ob = bpy.data.objects.new(lamp.name, lamp)
        ob.location = (-3.6, -3.6, g1 - 0.02)
        ob.lightgroup = "warm"
        scene.collection.objects.link(ob)
        for i, (x, y) in enumerate(((-1.5, -1.5), (-4.5, -1.5), (-1.5, -4.5), (-4.5, -4.5))):
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.09, location=(x, y, g1 - 0.7),
                                                 segments=16, ring_count=8)
            globe = bpy.context.active_object
            globe.name = "Globe_%d%d" % (k, i)
            globe.data.materials.append(mats["Bulb"])
            globe.lightgroup = "warm"
            seen_only(globe)
            box("Cord_%d%d" % (k, i), (x - 0.005, y - 0.005, g1 - 0.61), (x + 0.005, y + 0.005, g1), mats["Frame"])
    # Ground floor: a long oak counter, tables, a red sofa, plants; upstairs desks and shelves.
    box("Counter", (-6.5, -2.6, 0.0), (-1.8, -2.0, 1.05), mats["Oak"])
    for i, (x, y) in enumerate(((-1.6, -5.0), (-4.0, -5.2), (-5.2, -1.2))):
        box("Table_%d" % i, (x - 0.5, y - 0.5, 0.72), (x + 0.5, y + 0.5, 0.76), mats["Oak"])
        box("Table_leg_%d" % i, (x - 0.04, y - 0.04, 0.0), (x + 0.04, y + 0.04, 0.72), mats["Frame"])
    box("Sofa", (-2.8, -6.8, 0.0), (-1.0, -6.0, 0.8), mats["Red"])
    for i, (x, y) in enumerate(((-0.8, -0.8), (-6.6, -0.7), (-0.7, -6.4))):
        box("Pot_%d" % i, (x - 0.2, y - 0.2, 0.0), (x + 0.2, y + 0.2, 0.45), mats["Concrete"])
        box("Plant_%d" % i, (x - 0.3, y - 0.3, 0.45), (x + 0.3, y + 0.3, 1.5), mats["Leaf"])
    for i in range(4):
        box("Desk_%d" % i, (-1.2 - 2.6 * i, -3.0, 4.52), (-2.8 - 2.6 * i, -2.2, 4.56), mats["Oak"])
        box("Shelf_%d" % i, (-6.95, -1.0 - 1.4 * i, 3.8), (-6.6, -2.1 - 1.4 * i, 5.8),
            mats["Red"] if i % 2 else mats["Oak"])

    # Across both streets: buildings with a few lit windows (in the reflections).
    box("Opposite_A", (-30.0, 16.0, 0.0), (6.0, 22.0, 12.0), mats["Opposite"])
    box("Opposite_B", (16.0, -30.0, 0.0), (22.0, 6.0, 9.0), mats["Opposite"])
    lit = 0
    for i in range(6):
        for j in range(3):
            if (i * 3 + j) % 4 == 1:
                continue
            x0, z0 = -24.0 + 4.5 * i, 1.5 + 3.5 * j
            quad("Lit_A%d" % lit, [(x0, 15.98, z0), (x0 + 1.8, 15.98, z0), (x0 + 1.8, 15.98, z0 + 1.6),
                                   (x0, 15.98, z0 + 1.6)], mats["Window_lit"], group="warm")
            y0 = -24.0 + 4.5 * i
            quad("Lit_B%d" % lit, [(15.98, y0, z0), (15.98, y0, z0 + 1.6), (15.98, y0 + 1.8, z0 + 1.6),
                                   (15.98, y0 + 1.8, z0)], mats["Window_lit"], group="warm")
            lit += 1

    # A street lamp on the pavement, out of the frame (its light and its reflection in it).
    box("Lamp_post", (5.95, 2.45, 0.0), (6.05, 2.55, 4.2), mats["Frame"])
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.18, location=(6.0, 2.5, 4.35), segments=16, ring_count=8)
    head = bpy.context.active_object
    head.name = "Lamp_head"
    head.data.materials.append(mats["Bulb"])
    head.lightgroup = "warm"
    seen_only(head)
    lamp = bpy.data.lights.new("Street_lamp", "POINT")
    lamp.energy = 300.0
    lamp.shadow_soft_size = 0.18
    lamp.color = TUNGSTEN
    ob = bpy.data.objects.new("Street_lamp", lamp)
    ob.location = (6.0, 2.5, 4.35)
    ob.lightgroup = "warm"
    scene.collection.objects.link(ob)


def sun_and_sky():
    """The `sun` group: a low sun from the right-hand street (its glint falls outside the
    clear facade) and a dusk sky, orange at the horizon, deep blue above."""
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy = 1.2
    sun.angle = math.radians(1.0)
    sun.color = (1.0, 0.62, 0.38)
    ob = bpy.data.objects.new("Sun", sun)
    to_sun = Vector((0.8, -0.6, math.tan(math.radians(5.0)))).normalized()
    ob.rotation_euler = to_sun.to_track_quat("Z", "Y").to_euler()
    ob.lightgroup = "sun"
    scene.collection.objects.link(ob)

    world = bpy.data.worlds.new("Dusk")
    fixture_scene.set_use_nodes(world)
    nt = world.node_tree
    bg = nt.nodes["Background"]
    coord = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    nt.links.new(coord.outputs["Generated"], sep.inputs[0])
    nt.links.new(sep.outputs["Z"], ramp.inputs["Fac"])
    # Generated coordinates of the world are the view direction: its z is the sine of the
    # elevation (the ramp clamps what is below the horizon to the horizon's colour).
    els = ramp.color_ramp.elements
    els[0].position, els[0].color = 0.0, (0.30, 0.13, 0.05, 1.0)
    els[1].position, els[1].color = 1.0, (0.008, 0.016, 0.05, 1.0)
    for pos, rgb in ((0.05, (0.16, 0.09, 0.07)), (0.15, (0.06, 0.06, 0.10)),
                     (0.4, (0.025, 0.04, 0.09))):
        e = els.new(pos)
        e.color = rgb + (1.0,)
    nt.links.new(ramp.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = 1.0
    world.lightgroup = "sun"
    scene.world = world


def camera():
    data = bpy.data.cameras.new("Camera")
    data.lens = 26.0
    data.sensor_width = 36.0
    data.sensor_fit = "HORIZONTAL"
    ob = bpy.data.objects.new("Camera", data)
    scene.collection.objects.link(ob)
    ob.location = (3.9, 5.0, 1.6)
    target = Vector((-1.9, -1.5, 3.2))
    ob.rotation_euler = (target - ob.location).to_track_quat("-Z", "Y").to_euler()
    scene.camera = ob


def main():
    global scene
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    build()
    sun_and_sky()
    camera()
    vl = scene.view_layers[0]
    for group in ("sun", "warm"):
        vl.lightgroups.add(name=group)
    r = fixture_scene.fixed_cycles(scene)
    r.resolution_x, r.resolution_y = int(WIDTH), int(HEIGHT)
    scene.frame_start = scene.frame_end = 1
    scene.cycles.samples = int(OPTS["samples"])
    scene.cycles.max_bounces = 6
    scene.cycles.glossy_bounces = 4
    scene.cycles.transparent_max_bounces = 8
    scene.cycles.sample_clamp_indirect = 3.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    bpy.context.view_layer.update()
    bpy.ops.wm.save_as_mainfile(filepath=OPTS["out"])
    print("wrote", OPTS["out"])
    if OPTS["preview"]:
        fixture_scene.set_exr_format(r.image_settings, multilayer=True, half=True)
        fixture_scene.render_still(scene, os.path.dirname(OPTS["preview"]),
                                   os.path.basename(OPTS["preview"]))
        print("wrote", OPTS["preview"])


main()
