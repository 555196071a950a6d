#!/usr/bin/env python3
"""Writes the example scene `fixtures/atrium/`: a small glazed courtyard (an "atrium").

Plain Python, no extra packages, so that the scene can be regenerated anywhere:

    python3 python_oracle/make_atrium.py [OUT_DIR]        # default: fixtures/atrium

Writes
- `atrium.obj` + `atrium.mtl`: the geometry, metres, y up, one `o` per object, one material per
  surface kind. Glass materials are named `Glass*` (`GlassClear`, `GlassTinted`), everything else
  is opaque. Every face is wound counter-clockwise seen from its front (outside); glass faces point
  towards the courtyard, where the camera stands.
- `camera.json`: the pinhole camera in the format `glassdb mask` reads.
- `lights.json`: the sun (a directional light) and the sky (`sky.pfm`, an equirectangular
  radiance map, +y up, Mitsuba's `envmap` convention), in linear radiance units where a white sky
  of radiance 1 is the PSNR peak.
- `sky.pfm`: the sky, 256×128 float RGB (Portable Float Map, little endian).

The scene (what the validation needs, issue 8):
- three glass planes in three orientations: the west facade (plane x = -4, normal +x, clear), the
  north facade (plane z = -6, normal +z, tinted) and a free-standing glass screen in the courtyard
  turned 30° (clear). (A tilted canopy at the north facade was tried and left out: its virtual
  scene cuts the north room open along the canopy plane, so the reflection pass sees a sunlit
  room where reality shows a roofed one; docs/validation.md explains this limit of the method.)
- occluders in front of glass: mullions, columns, a planter, a tree, a bench;
- geometry on both sides of every plane: closed rooms behind both facades, lit only through the
  glass by sun and sky (so the interior is lit through the glass), a sculpture behind the screen;
- a sky (environment map) that the glass reflects, and the sun.
"""

import json
import math
import os
import struct
import sys

# ----------------------------------------------------------------------------- geometry helpers


class Obj:
    """Collects objects (name, material, quads/triangles) and writes them as OBJ."""

    def __init__(self):
        self.vertices = []
        self.objects = []  # (name, material, [faces as lists of vertex indices, 0-based])

    def add_face(self, name, material, points):
        base = len(self.vertices)
        self.vertices.extend(points)
        face = list(range(base, base + len(points)))
        if self.objects and self.objects[-1][0] == name and self.objects[-1][1] == material:
            self.objects[-1][2].append(face)
        else:
            self.objects.append((name, material, [face]))

    def quad(self, name, material, p0, p1, p2, p3):
        """A planar quad, counter-clockwise seen from its front."""
        self.add_face(name, material, [p0, p1, p2, p3])

    def box(self, name, material, x0, x1, y0, y1, z0, z1, bottom=False):
        """An axis-aligned box with outward faces (no bottom face unless asked)."""
        q = self.quad
        q(name, material, (x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1))  # +x
        q(name, material, (x0, y0, z1), (x0, y1, z1), (x0, y1, z0), (x0, y0, z0))  # -x
        q(name, material, (x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0))  # +y
        if bottom:
            q(name, material, (x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1))  # -y
        q(name, material, (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))  # +z
        q(name, material, (x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0))  # -z

    def oriented_box(self, name, material, centre, half, yaw_deg, y0, y1):
        """A box turned about +y by `yaw_deg` (half = (half-length along u, half-depth along v))."""
        c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
        u = (c, 0.0, -s)
        v = (s, 0.0, c)
        hu, hv = half

        def pt(a, b, y):
            return (centre[0] + a * u[0] + b * v[0], y, centre[2] + a * u[2] + b * v[2])

        corners = [(-hu, -hv), (hu, -hv), (hu, hv), (-hu, hv)]
        # Sides: walk the footprint counter-clockwise seen from above (+y) so faces point outwards.
        ring = [pt(a, b, 0.0) for a, b in corners]
        # Orientation of the ring seen from above: make it counter-clockwise in (x, -z).
        area = 0.0
        for i in range(4):
            x0, _, z0 = ring[i]
            x1, _, z1 = ring[(i + 1) % 4]
            area += x0 * (-z1) - x1 * (-z0)
        order = corners if area > 0 else list(reversed(corners))
        for i in range(4):
            a0, b0 = order[i]
            a1, b1 = order[(i + 1) % 4]
            self.quad(name, material, pt(a0, b0, y0), pt(a1, b1, y0), pt(a1, b1, y1), pt(a0, b0, y1))
        self.add_face(name, material, [pt(a, b, y1) for a, b in order])

    def write(self, obj_path, mtl_name):
        lines = [
            "# glassdb example scene `atrium` (python_oracle/make_atrium.py); metres, y up",
            f"mtllib {mtl_name}",
        ]
        for x, y, z in self.vertices:
            lines.append(f"v {x:.6f} {y:.6f} {z:.6f}")
        for name, material, faces in self.objects:
            lines.append(f"o {name}")
            lines.append(f"usemtl {material}")
            for face in faces:
                lines.append("f " + " ".join(str(i + 1) for i in face))
        with open(obj_path, "w", encoding="utf-8") as f:
            f.write("\n".join(lines) + "\n")


# Diffuse albedos (linear RGB). Glass entries are described by `catalog.toml` (ids) and by the
# renderer's thin dielectric; their MTL colours are only a hint for OBJ viewers.
MATERIALS = {
    "Ground": (0.32, 0.30, 0.27),
    "Paving": (0.55, 0.52, 0.47),
    "Facade": (0.62, 0.60, 0.56),
    "Mullion": (0.08, 0.08, 0.09),
    "Roof": (0.40, 0.40, 0.40),
    "WallInside": (0.72, 0.70, 0.66),
    "FloorWood": (0.45, 0.28, 0.15),
    "Ceiling": (0.80, 0.80, 0.80),
    "PanelRed": (0.70, 0.12, 0.08),
    "PanelBlue": (0.10, 0.22, 0.60),
    "Sofa": (0.85, 0.45, 0.05),
    "Table": (0.30, 0.18, 0.10),
    "Column": (0.75, 0.74, 0.70),
    "Planter": (0.35, 0.22, 0.15),
    "Foliage": (0.10, 0.32, 0.08),
    "Trunk": (0.25, 0.16, 0.10),
    "Sculpture": (0.80, 0.20, 0.45),
    "Bench": (0.50, 0.35, 0.20),
    "Brick": (0.55, 0.25, 0.18),
    "GlassClear": (0.90, 0.95, 0.95),
    "GlassTinted": (0.55, 0.68, 0.62),
}

GLASS_MATERIALS = ("GlassClear", "GlassTinted")

CAMERA = {
    "origin": [-0.5, 1.6, 7.5],
    "target": [-1.5, 2.1, -5.0],
    "up": [0.0, 1.0, 0.0],
    "fov_x_deg": 80.0,
    "width": 320,
    "height": 240,
}

# Sun: direction *towards* the sun (unit), elevation about 34°, from the south-east so that it
# shines into both glazed rooms. Irradiance on a surface facing the sun, per channel.
SUN_TOWARDS = (0.62, 0.56, 0.55)
SUN_IRRADIANCE = (2.6, 2.45, 2.2)


def glazed_wall(obj, name, axis, plane, along0, along1, y0, y1, opening, mullion_step, glass):
    """A facade in the plane `axis = plane` (axis 'x' faces +x, axis 'z' faces +z) with one glazed
    opening `opening = (a0, a1, b0, b1)` (along, height), glass panes between mullions that stand
    in front of the glass (occluders on the camera side), and opaque wall around the opening."""

    def p(a, y, off=0.0):
        return (plane + off, y, a) if axis == "x" else (a, y, plane + off)

    def wall_rect(a0, a1, b0, b1):
        if a1 - a0 <= 1e-9 or b1 - b0 <= 1e-9:
            return
        if axis == "x":  # faces +x: counter-clockwise seen from +x means (z decreasing) order
            obj.quad(name + "Wall", "Facade", p(a1, b0), p(a0, b0), p(a0, b1), p(a1, b1))
        else:  # faces +z
            obj.quad(name + "Wall", "Facade", p(a0, b0), p(a1, b0), p(a1, b1), p(a0, b1))

    oa0, oa1, ob0, ob1 = opening
    wall_rect(along0, oa0, y0, y1)
    wall_rect(oa1, along1, y0, y1)
    wall_rect(oa0, oa1, y0, ob0)
    wall_rect(oa0, oa1, ob1, y1)
    # Glass panes tiling the opening; mullion boxes over the joints and the frame, in front.
    n = max(1, round((oa1 - oa0) / mullion_step))
    edges = [oa0 + (oa1 - oa0) * i / n for i in range(n + 1)]
    for i in range(n):
        a0, a1 = edges[i], edges[i + 1]
        if axis == "x":
            obj.quad(name + "Glass", glass, p(a1, ob0), p(a0, ob0), p(a0, ob1), p(a1, ob1))
        else:
            obj.quad(name + "Glass", glass, p(a0, ob0), p(a1, ob0), p(a1, ob1), p(a0, ob1))
    # Closed boxes that stand 5 mm in front of the glass: a face coplanar with the glass would
    # tie with it in any z-buffer or ray tracer (the mask and the renderer could then disagree).
    w, depth, gap = 0.07, 0.14, 0.005
    p0, p1 = plane + gap, plane + gap + depth
    for a in edges:
        if axis == "x":
            obj.box(name + "Mullion", "Mullion", p0, p1, ob0, ob1, a - w, a + w, bottom=True)
        else:
            obj.box(name + "Mullion", "Mullion", a - w, a + w, ob0, ob1, p0, p1, bottom=True)
    transom = ob0 + 0.62 * (ob1 - ob0)
    for yc in (transom, ob0, ob1):
        if axis == "x":
            obj.box(name + "Mullion", "Mullion", p0, p1, yc - w, yc + w, oa0, oa1, bottom=True)
        else:
            obj.box(name + "Mullion", "Mullion", oa0, oa1, yc - w, yc + w, p0, p1, bottom=True)


def room(obj, name, x0, x1, y0, y1, z0, z1, skip):
    """The inside of a closed room: floor, ceiling and the walls except `skip` (the glazed one),
    all facing inwards, plus the roof slab over it facing up."""
    q = obj.quad
    q(name + "Floor", "FloorWood", (x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0))
    q(name + "Ceiling", "Ceiling", (x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1))
    if skip != "x0":
        q(name + "Walls", "WallInside", (x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1))
    if skip != "x1":
        q(name + "Walls", "WallInside", (x1, y0, z1), (x1, y1, z1), (x1, y1, z0), (x1, y0, z0))
    if skip != "z0":
        q(name + "Walls", "WallInside", (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z0))
    if skip != "z1":
        q(name + "Walls", "WallInside", (x0, y0, z1), (x0, y1, z1), (x1, y1, z1), (x1, y0, z1))


def build():
    o = Obj()
    H = 4.0  # storey height (interior)
    # Courtyard ground (stops at the facades; the rooms have their own floors).
    o.quad("Ground", "Ground", (-4.0, 0.0, -6.0), (-4.0, 0.0, 8.0), (60.0, 0.0, 8.0), (60.0, 0.0, -6.0))
    o.quad("Ground", "Ground", (-60.0, 0.0, 8.0), (-60.0, 0.0, 60.0), (60.0, 0.0, 60.0), (60.0, 0.0, 8.0))
    o.quad("Ground", "Ground", (16.0, 0.0, -60.0), (16.0, 0.0, -6.0), (60.0, 0.0, -6.0), (60.0, 0.0, -60.0))
    o.quad("Paving", "Paving", (-4.0, 0.002, -6.0), (-4.0, 0.002, 4.0), (6.0, 0.002, 4.0), (6.0, 0.002, -6.0))

    # West building: room x in [-12, -4], z in [-18, 8]; facade plane x = -4 faces +x.
    room(o, "WestRoom", -12.0, -4.0, 0.0, H, -18.0, 8.0, skip="x1")
    glazed_wall(o, "West", "x", -4.0, -6.0, 8.0, 0.0, H, (-5.2, 6.8, 0.35, 3.45), 2.0, "GlassClear")
    # The west room's east wall behind the north room (x = -4, z in [-18, -16]); for z in
    # [-16, -6] the north room's west wall closes both rooms (all opaque surfaces are two-sided).
    o.quad("WestRoomWalls", "WallInside", (-4.0, 0.0, -16.0), (-4.0, H, -16.0), (-4.0, H, -18.0), (-4.0, 0.0, -18.0))
    o.box("WestRoof", "Roof", -12.3, -3.7, H, H + 0.35, -18.3, 8.3)
    o.quad("WestRoof", "Roof", (-4.0, H, -6.0), (-3.7, H, -6.0), (-3.7, H, 8.3), (-4.0, H, 8.3))  # soffit
    # Interior of the west room: coloured panels on the back wall, a sofa, tables, columns.
    for i, z in enumerate(range(-4, 8, 3)):
        mat = "PanelRed" if i % 2 == 0 else "PanelBlue"
        o.quad("WestPanels", mat, (-11.98, 0.6, z + 2.2), (-11.98, 2.8, z + 2.2), (-11.98, 2.8, z), (-11.98, 0.6, z))
    o.box("WestSofa", "Sofa", -10.5, -9.3, 0.0, 0.8, -2.0, 2.5)
    o.box("WestTable", "Table", -7.8, -6.6, 0.0, 0.75, -1.0, 1.2)
    o.box("WestTable", "Table", -8.4, -7.0, 0.0, 0.75, 3.5, 5.0)
    o.box("WestColumns", "Column", -8.2, -7.8, 0.0, H, -4.2, -3.8)
    o.box("WestColumns", "Column", -8.2, -7.8, 0.0, H, 5.8, 6.2)

    # North building: room x in [-4, 16], z in [-16, -6]; facade plane z = -6 faces +z.
    room(o, "NorthRoom", -4.0, 16.0, 0.0, H, -16.0, -6.0, skip="z1")
    glazed_wall(o, "North", "z", -6.0, -4.0, 16.0, 0.0, H, (-3.2, 13.4, 0.35, 3.45), 2.1, "GlassTinted")
    o.box("NorthRoof", "Roof", -3.7, 16.3, H, H + 0.35, -16.3, -5.7)
    o.quad("NorthRoof", "Roof", (-3.7, H, -6.0), (16.3, H, -6.0), (16.3, H, -5.7), (-3.7, H, -5.7))  # soffit
    for i, x in enumerate(range(-2, 14, 3)):
        mat = "PanelBlue" if i % 2 == 0 else "PanelRed"
        o.quad("NorthPanels", mat, (x, 0.6, -15.98), (x + 2.0, 0.6, -15.98), (x + 2.0, 2.8, -15.98), (x, 2.8, -15.98))
    o.box("NorthSofa", "Sofa", 1.0, 5.0, 0.0, 0.8, -14.8, -13.6)
    o.box("NorthTable", "Table", 7.0, 9.0, 0.0, 0.75, -11.0, -9.5)
    o.box("NorthColumns", "Column", 4.8, 5.2, 0.0, H, -10.2, -9.8)
    o.box("NorthColumns", "Column", 10.8, 11.2, 0.0, H, -10.2, -9.8)

    # Occluders in front of the glass: two columns before the west facade, a tree before the
    # north facade, a bench.
    o.box("Columns", "Column", -2.9, -2.4, 0.0, 4.2, -1.2, -0.7)
    o.box("Columns", "Column", -2.9, -2.4, 0.0, 4.2, 3.6, 4.1)
    o.box("TreeTrunk", "Trunk", -1.2, -0.9, 0.0, 2.2, -4.3, -4.0)
    o.box("TreeCrown", "Foliage", -2.2, 0.1, 2.2, 3.8, -5.3, -3.0, bottom=True)
    # Blocks across the courtyard (behind the camera): what the facades mostly reflect.
    o.box("EastBlock", "Facade", 14.0, 22.0, 0.0, 6.0, -6.0, 22.0)
    o.box("SouthBlock", "Brick", -4.0, 14.0, 0.0, 5.0, 14.0, 20.0)
    for i, x in enumerate(range(-2, 13, 3)):
        o.quad("SouthWindows", "Mullion", (x + 1.6, 1.2, 13.99), (x, 1.2, 13.99), (x, 3.4, 13.99), (x + 1.6, 3.4, 13.99))
    for z in range(-3, 21, 4):
        o.quad("EastWindows", "PanelBlue", (13.99, 1.0, z), (13.99, 1.0, z + 2.2), (13.99, 4.2, z + 2.2), (13.99, 4.2, z))
    o.box("Bench", "Bench", 0.5, 3.0, 0.0, 0.45, 3.0, 3.6)

    # Free-standing glass screen in the courtyard, turned 30° (normal towards the camera side),
    # with a planter in front (occluder) and a sculpture behind it.
    yaw = 30.0
    c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
    centre = (1.6, 0.0, -0.6)
    u = (c, 0.0, -s)  # along the screen
    half_len, y_lo, y_hi = 2.3, 0.25, 2.4

    def sp(a, y):
        return (centre[0] + a * u[0], y, centre[2] + a * u[2])

    # Counter-clockwise seen from the front (normal n = u × up... = (s, 0, c), towards +z+x).
    o.quad("ScreenGlass", "GlassClear", sp(-half_len, y_lo), sp(half_len, y_lo), sp(half_len, y_hi), sp(-half_len, y_hi))
    o.oriented_box("ScreenFrame", "Mullion", sp(-half_len - 0.06, 0.0), (0.06, 0.06), yaw, 0.0, y_hi + 0.06)
    o.oriented_box("ScreenFrame", "Mullion", sp(half_len + 0.06, 0.0), (0.06, 0.06), yaw, 0.0, y_hi + 0.06)
    o.oriented_box("ScreenFrame", "Mullion", sp(0.0, 0.0), (half_len, 0.06), yaw, 0.0, y_lo)
    n_screen = (s, 0.0, c)
    pc = (centre[0] + 0.9 * n_screen[0] + 0.8 * u[0], 0.0, centre[2] + 0.9 * n_screen[2] + 0.8 * u[2])
    o.oriented_box("Planter", "Planter", pc, (0.7, 0.35), yaw, 0.0, 0.9)
    o.oriented_box("PlanterFoliage", "Foliage", pc, (0.6, 0.28), yaw, 0.9, 1.5)
    bc = (centre[0] - 1.6 * n_screen[0] - 0.6 * u[0], 0.0, centre[2] - 1.6 * n_screen[2] - 0.6 * u[2])
    o.oriented_box("Sculpture", "Sculpture", bc, (0.45, 0.45), yaw + 20.0, 0.0, 1.9)

    return o


def write_mtl(path):
    lines = ["# glassdb example scene `atrium`: Kd = diffuse albedo (linear RGB)"]
    for name, (r, g, b) in MATERIALS.items():
        lines += [f"newmtl {name}", f"Kd {r:.4f} {g:.4f} {b:.4f}"]
        if name.startswith("Glass"):
            lines += ["d 0.2", "Ni 1.5"]
        lines.append("")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))


def sky_radiance(d):
    """Linear RGB radiance of the sky in direction d (unit, y up): a gradient from a bright hazy
    horizon to a deeper zenith, a glow around the sun, a few soft clouds (so that reflections in
    the glass show structure), and a dark ground below the horizon."""
    x, y, z = d
    if y < 0.0:
        return (0.10, 0.095, 0.085)
    zen = (0.20, 0.34, 0.62)
    hor = (0.62, 0.68, 0.74)
    w = (1.0 - y) ** 3
    col = [zen[i] * (1.0 - w) + hor[i] * w for i in range(3)]
    cosg = x * SUN_TOWARDS[0] + y * SUN_TOWARDS[1] + z * SUN_TOWARDS[2]
    glow = 0.35 * max(0.0, cosg) ** 24
    cloud = 0.0
    for (cx, cy, cz, r, a) in CLOUDS:
        dd = (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2
        cloud += a * math.exp(-dd / (r * r))
    cloud = min(cloud, 0.9)
    out = []
    for i in range(3):
        v = col[i] * (1.0 - cloud) + 0.92 * cloud + glow
        out.append(v)
    return tuple(out)


def _unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


# Soft clouds: (unit direction, angular radius (chord), opacity).
CLOUDS = [
    (*_unit((1.0, 0.35, 0.3)), 0.16, 0.8),
    (*_unit((0.7, 0.22, 1.0)), 0.20, 0.7),
    (*_unit((0.2, 0.30, 1.0)), 0.13, 0.85),
    (*_unit((1.0, 0.15, -0.4)), 0.18, 0.6),
    (*_unit((-0.3, 0.5, 1.0)), 0.15, 0.7),
    (*_unit((0.9, 0.6, 0.8)), 0.12, 0.6),
]


def write_sky_pfm(path, width=256, height=128):
    """Equirectangular map in Mitsuba's `envmap` convention: pixel (u, v) with u = (i+0.5)/W,
    v = (j+0.5)/H (row 0 at the top), direction = (sinθ·sinφ... ) as in Mitsuba:
    φ = 2π·u, θ = π·v, d = (sin φ·sin θ, cos θ, -cos φ·sin θ)."""
    rows = []
    for j in range(height):
        theta = math.pi * (j + 0.5) / height
        row = []
        for i in range(width):
            phi = 2.0 * math.pi * (i + 0.5) / width
            d = (math.sin(phi) * math.sin(theta), math.cos(theta), -math.cos(phi) * math.sin(theta))
            row.append(sky_radiance(d))
        rows.append(row)
    # PFM stores rows bottom to top.
    data = bytearray()
    for row in reversed(rows):
        for r, g, b in row:
            data += struct.pack("<fff", r, g, b)
    with open(path, "wb") as f:
        f.write(f"PF\n{width} {height}\n-1.0\n".encode("ascii"))
        f.write(bytes(data))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "fixtures", "atrium")
    os.makedirs(out, exist_ok=True)
    scene = build()
    scene.write(os.path.join(out, "atrium.obj"), "atrium.mtl")
    write_mtl(os.path.join(out, "atrium.mtl"))
    with open(os.path.join(out, "camera.json"), "w", encoding="utf-8") as f:
        json.dump(CAMERA, f, indent=2)
        f.write("\n")
    lights = {
        "sun": {
            "direction_to_sun": list(_unit(SUN_TOWARDS)),
            "irradiance_rgb": list(SUN_IRRADIANCE),
        },
        "sky": {
            "file": "sky.pfm",
            "mapping": "equirectangular, Mitsuba envmap convention: u = phi/(2 pi), v = theta/pi, "
            "direction = (sin(phi) sin(theta), cos(theta), -cos(phi) sin(theta)), row 0 = zenith",
            "scale": 1.0,
        },
        "units": "linear RGB radiance; PSNR peak 1.0 at exposure 1 (no scaling)",
    }
    with open(os.path.join(out, "lights.json"), "w", encoding="utf-8") as f:
        json.dump(lights, f, indent=2)
        f.write("\n")
    write_sky_pfm(os.path.join(out, "sky.pfm"))
    print(f"wrote {out}: {len(scene.vertices)} vertices, {sum(len(f) for _, _, f in scene.objects)} faces")


if __name__ == "__main__":
    main()
