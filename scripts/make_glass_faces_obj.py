#!/usr/bin/env python3
"""A facade of many glass panes for timing `glassdb mask` (docs/performance.md).

Writes DIR/facade.obj, DIR/facade.mtl and DIR/camera.json: FACES glass panes (material
Glass, each its own face with its own corners, so each is a pane) in a square grid on PLANES
parallel planes (z = 0, -0.5, -1, ...; the grid's rows go round-robin to the planes), in
front of an opaque wall, and a 1920x1080 camera looking at the whole facade. With the default
--size 0.8 every pane covers a few pixels; with --size above 1 the panes are large and
overlap, each set back by a small depth of its own (1e-3 times its index modulo 997), so most
of each is hidden behind others (heavy overdraw). --sides N makes round (or, with --star,
star-shaped) panes of N corners instead of squares.

    python3 scripts/make_glass_faces_obj.py DIR [--faces 100000] [--size 55] [--planes 1]
"""

import argparse
import json
import math
import os


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--faces", type=int, default=100_000)
    ap.add_argument("--planes", type=int, default=1)
    ap.add_argument(
        "--sides",
        type=int,
        default=4,
        help="corners of each pane: 4 (a square) or more (a round window)",
    )
    ap.add_argument(
        "--star",
        type=float,
        default=0.0,
        help="with --sides: every other corner this fraction closer to the centre (not convex)",
    )
    ap.add_argument(
        "--size",
        type=float,
        default=0.8,
        help="pane width in grid cells (above 1 the panes overlap, each on its own depth)",
    )
    args = ap.parse_args()
    if args.faces < 1 or args.planes < 1 or args.sides < 3:
        ap.error("--faces and --planes must be at least 1, --sides at least 3")
    os.makedirs(args.dir, exist_ok=True)
    cols = math.ceil(math.sqrt(args.faces * 16 / 9))
    rows = math.ceil(args.faces / cols)
    pitch, pane = 1.0, args.size
    width, height = cols * pitch, rows * pitch
    lines = ["# glassdb: a facade of glass panes (scripts/make_glass_faces_obj.py)", "mtllib facade.mtl"]
    # The wall behind the glass.
    z_wall = -0.5 * args.planes
    lines += [
        "o wall",
        "usemtl Wall",
        f"v 0 0 {z_wall}",
        f"v {width} 0 {z_wall}",
        f"v {width} {height} {z_wall}",
        f"v 0 {height} {z_wall}",
        "f 1 2 3 4",
        "o glass",
        "usemtl Glass",
    ]
    n = 4
    for k in range(args.faces):
        r, c = divmod(k, cols)
        z = -0.5 * (r % args.planes)
        if args.size > 1:
            # Overlapping panes lie one behind the other.
            z -= 1e-3 * (k % 997)
        x0, y0 = c * pitch + 0.1, r * pitch + 0.1
        if args.sides == 4:
            corners = [(x0, y0), (x0 + pane, y0), (x0 + pane, y0 + pane), (x0, y0 + pane)]
        else:
            cx, cy, rad = x0 + pane / 2, y0 + pane / 2, pane / 2
            # A round window, or with --star a star (not convex: ear-clipped).
            corners = [
                (cx + rad * (1 - args.star * (i % 2)) * math.cos(2 * math.pi * i / args.sides),
                 cy + rad * (1 - args.star * (i % 2)) * math.sin(2 * math.pi * i / args.sides))
                for i in range(args.sides)
            ]
        lines += [f"v {x:.6f} {y:.6f} {z}" for x, y in corners]
        lines.append("f " + " ".join(str(n + 1 + i) for i in range(len(corners))))
        n += len(corners)
    with open(os.path.join(args.dir, "facade.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(args.dir, "facade.mtl"), "w") as f:
        f.write("newmtl Glass\nKd 0.1 0.1 0.1\nd 0.1\n\nnewmtl Wall\nKd 0.5 0.5 0.5\n")
    # A 70-degree lens far enough back to see the whole facade.
    fov = 70.0
    dist = 0.55 * max(width, height * 16 / 9) / math.tan(math.radians(fov / 2))
    camera = {
        "origin": [width / 2, height / 2, dist],
        "target": [width / 2, height / 2, 0.0],
        "up": [0, 1, 0],
        "fov_x_deg": fov,
        "width": 1920,
        "height": 1080,
    }
    with open(os.path.join(args.dir, "camera.json"), "w") as f:
        json.dump(camera, f)
    print(f"{args.faces} glass panes ({cols}x{rows}) on {args.planes} plane(s) -> {args.dir}")


if __name__ == "__main__":
    main()
