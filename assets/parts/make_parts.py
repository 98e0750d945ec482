#!/usr/bin/env python3
"""Writes the OBJ meshes of the shipped scenarios' generated parts.

    python3 assets/parts/make_parts.py [OUT_DIR]     (default: this folder)

Millimetres. Every mesh is made of closed shells of outward-facing
(counter-clockwise seen from outside) triangles; a part may be several shells
that touch or overlap (a brick and its studs, a rod running into its eye). The script checks both before writing:
every edge of a shell is used once in each direction, and every shell's signed
volume is positive. Plain Python 3, no dependencies; the output is the same
bytes on every run.

Parts (their frames):
  bolt.obj            M10 hex bolt: head top at z = 0, shank along +z to z = 37
  nut.obj             M10 hex nut, 8 thick, from z = 0 to 8, 10.5 bore
  bracket.obj         angle bracket 24 wide: 6 mm flange (y = 0..6, x = -40..12)
                      with a 10.5 hole at the origin, a leg 50 mm down from its
                      -x edge
  splined_shaft.obj   shaft along +z: collar z = 0..10, six straight-sided
                      splines z = 10..50
  splined_gear.obj    24-tooth gear 12 thick (z = 0..12) with a splined bore
  brick_2x4.obj       2x4 brick, y up: bottom at y = 0, top at 9.6, studs to 11.3
  baseplate.obj       6x4 plate, y up: bottom at y = 0, top at 3.2, studs to 4.9
  piston_rod.obj      stand-in piston (93 mm) and connecting rod: crown at z = 0,
                      skirt at z = 80, rod along +z to a big-end eye
"""

import math
import os
import sys

TAU = 2 * math.pi


class Mesh:
    def __init__(self, name):
        self.name = name
        self.vertices = []
        self.triangles = []
        self.shells = []  # (first triangle, end) per shell

    def vertex(self, p):
        self.vertices.append(tuple(float(c) for c in p))
        return len(self.vertices) - 1

    def begin_shell(self):
        self.shells.append([len(self.triangles), None])

    def end_shell(self):
        self.shells[-1][1] = len(self.triangles)

    def tri(self, a, b, c):
        self.triangles.append((a, b, c))

    def quad(self, a, b, c, d):
        self.tri(a, b, c)
        self.tri(a, c, d)

    def transform(self, f):
        self.vertices = [f(p) for p in self.vertices]


# ---- 2D loops: lists of (u, v) counter-clockwise around the origin, each
# star-shaped from it (every ray from the origin crosses the loop once).

def angle_of(p):
    return math.atan2(p[1], p[0]) % TAU


def circle(radius, sides, phase=0.0, circumscribed=False):
    """A regular polygon; `circumscribed` puts its flats (not its corners) on the radius."""
    r = radius / math.cos(math.pi / sides) if circumscribed else radius
    return [(r * math.cos(phase + TAU * k / sides), r * math.sin(phase + TAU * k / sides))
            for k in range(sides)]


def ray_hit(loop, theta):
    """The point where the ray from the origin at angle theta crosses the loop."""
    d = (math.cos(theta), math.sin(theta))
    best = None
    n = len(loop)
    for i in range(n):
        a, b = loop[i], loop[(i + 1) % n]
        e = (b[0] - a[0], b[1] - a[1])
        den = d[0] * e[1] - d[1] * e[0]
        if abs(den) < 1e-15:
            continue
        t = (a[0] * e[1] - a[1] * e[0]) / den   # distance along the ray
        s = (a[0] * d[1] - a[1] * d[0]) / den   # position along the edge
        if t > 0 and -1e-12 <= s <= 1 + 1e-12 and (best is None or t < best):
            best = t
    assert best is not None, "loop is not star-shaped from the origin"
    return (best * d[0], best * d[1])


def resample(loop, angles):
    """The loop with extra points on its edges where the rays at `angles` cross it."""
    points = {round(angle_of(p), 12): p for p in loop}
    for theta in angles:
        key = round(theta % TAU, 12)
        if key not in points:
            points[key] = ray_hit(loop, theta)
    return [points[k] for k in sorted(points)]


def area(loop):
    return 0.5 * sum(loop[i][0] * loop[(i + 1) % len(loop)][1] -
                     loop[(i + 1) % len(loop)][0] * loop[i][1] for i in range(len(loop)))


def orient(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def start_at_smallest_angle(loop):
    k = min(range(len(loop)), key=lambda i: angle_of(loop[i]))
    return loop[k:] + loop[:k]


def fit_loops(outer, inner):
    """Both loops resampled at each other's angles and started at their smallest angle,
    so that a ring face between them (band) spans thin sectors only. Build the rings of
    vertices on these loops."""
    outer2 = start_at_smallest_angle(resample(outer, [angle_of(p) for p in inner]))
    inner2 = start_at_smallest_angle(resample(inner, [angle_of(p) for p in outer]))
    return outer2, inner2


def band(outer, inner):
    """Triangles (as index pairs ('o', i) / ('i', j)) covering the ring between two fitted
    loops (fit_loops), counter-clockwise; the cover is checked (all triangles positive,
    areas adding up to the ring's)."""
    assert (outer, inner) == fit_loops(outer, inner), "band: fit the loops first"
    no, ni = len(outer), len(inner)
    po = lambda k: outer[k % no]
    pi = lambda k: inner[k % ni]
    unwrap = lambda loop, k: angle_of(loop[k % len(loop)]) + TAU * (k // len(loop))
    tris = []
    i = j = 0
    while i < ni or j < no:
        # Advance on the loop whose next point comes first around the origin.
        next_o = unwrap(outer, j + 1) if j < no else math.inf
        next_i = unwrap(inner, i + 1) if i < ni else math.inf
        if next_o <= next_i:
            t = (('o', j), ('o', j + 1), ('i', i))
            assert orient(po(j), po(j + 1), pi(i)) > 0, "band: a triangle turned over"
            j += 1
        else:
            t = (('i', i), ('o', j), ('i', i + 1))
            assert orient(pi(i), po(j), pi(i + 1)) > 0, "band: a triangle turned over"
            i += 1
        tris.append(t)
    total = sum(orient(*[po(k) if w == 'o' else pi(k) for w, k in t]) / 2 for t in tris)
    assert abs(total - (area(outer) - area(inner))) < 1e-6 * area(outer), "band: not a cover"
    return outer, inner, [tuple((w, k % (no if w == 'o' else ni)) for w, k in t) for t in tris]


def fan_ok(loop):
    for k in range(len(loop)):
        assert orient((0, 0), loop[k], loop[(k + 1) % len(loop)]) > 0, "not star-shaped"


# ---- shells

def add_loop(mesh, loop, z):
    return [mesh.vertex((u, v, z)) for u, v in loop]


def add_cap(mesh, ring, z, up):
    """A cap over one ring of vertices, fanned from a centre vertex on the axis."""
    c = mesh.vertex((0.0, 0.0, z))
    n = len(ring)
    for k in range(n):
        a, b = ring[k], ring[(k + 1) % n]
        mesh.tri(c, a, b) if up else mesh.tri(c, b, a)


def add_wall(mesh, lower, upper, outward=True):
    """Side quads between two rings of equal length (lower below upper)."""
    n = len(lower)
    for k in range(n):
        a, b = lower[k], lower[(k + 1) % n]
        c, d = upper[(k + 1) % n], upper[k]
        mesh.quad(a, b, c, d) if outward else mesh.quad(a, d, c, b)


def add_band(mesh, outer, inner, outer_ring, inner_ring, up):
    """A flat ring face between two rings of vertices built on fitted loops."""
    assert len(outer_ring) == len(outer) and len(inner_ring) == len(inner)
    _, _, tris = band(outer, inner)
    for t in tris:
        a, b, c = [(outer_ring if w == 'o' else inner_ring)[k] for w, k in t]
        mesh.tri(a, b, c) if up else mesh.tri(a, c, b)


def solid_loft(mesh, stations):
    """A closed solid through loops of equal length at increasing z: [(loop, z), ...]."""
    mesh.begin_shell()
    for loop, _ in stations:
        fan_ok(loop)
    rings = [add_loop(mesh, loop, z) for loop, z in stations]
    add_cap(mesh, rings[0], stations[0][1], up=False)
    for lower, upper in zip(rings, rings[1:]):
        add_wall(mesh, lower, upper)
    add_cap(mesh, rings[-1], stations[-1][1], up=True)
    mesh.end_shell()


def prism_with_hole(mesh, outer, inner, z0, z1):
    """A closed prism from z0 to z1 between an outer and an inner loop (a bore through)."""
    mesh.begin_shell()
    outer, inner = fit_loops(outer, inner)
    bo, bi = add_loop(mesh, outer, z0), add_loop(mesh, inner, z0)
    to, ti = add_loop(mesh, outer, z1), add_loop(mesh, inner, z1)
    add_band(mesh, outer, inner, bo, bi, up=False)
    add_band(mesh, outer, inner, to, ti, up=True)
    add_wall(mesh, bo, to, outward=True)
    add_wall(mesh, bi, ti, outward=False)
    mesh.end_shell()


def box(mesh, lo, hi):
    mesh.begin_shell()
    v = [mesh.vertex((hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1],
                      hi[2] if i & 4 else lo[2])) for i in range(8)]
    for a, b, c, d in ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3),
                       (0, 4, 6, 2), (1, 3, 7, 5)):
        mesh.quad(v[a], v[b], v[c], v[d])
    mesh.end_shell()


def y_up(p):
    """Turns a mesh made along z to stand along y: (x, y, z) -> (x, z, -y)."""
    return (p[0], p[2], -p[1])


def moved(offset):
    return lambda p: (p[0] + offset[0], p[1] + offset[1], p[2] + offset[2])


# ---- profiles

def hexagon(across_flats):
    return circle(across_flats / math.sqrt(3), 6, phase=math.pi / 6)


def spline_profile(root, major, width, keys, arc_step_deg=4.0):
    """Straight-sided splines: `keys` keys of `width` (flanks parallel to the key's
    centre line) from a root circle up to a major circle, counter-clockwise. Arcs are
    chords of at most arc_step_deg (their sag, under 0.01 mm, is left as it is)."""
    def arc(r, a0, a1):  # from a0 (included) towards a1 (excluded)
        n = max(1, math.ceil((a1 - a0) / math.radians(arc_step_deg)))
        return [(r * math.cos(a0 + (a1 - a0) * k / n), r * math.sin(a0 + (a1 - a0) * k / n))
                for k in range(n)]
    a_root = math.asin(width / 2 / root)    # a flank's angle off its key's centre line
    a_major = math.asin(width / 2 / major)  # at the root and at the major circle
    loop = []
    for k in range(keys):
        c = TAU * k / keys
        loop += arc(major, c - a_major, c + a_major)
        loop += arc(root, c + a_root, c + TAU / keys - a_root)
    return loop


def gear_profile(teeth, root_r, tip_r, base_frac=0.55, tip_frac=0.3):
    """Trapezoid teeth: per pitch, a tooth `base_frac` of the pitch wide at the root
    circle and `tip_frac` wide at the tip circle, then a root land."""
    pitch = TAU / teeth
    loop = []
    for k in range(teeth):
        c = pitch * k
        for a, r in ((-base_frac / 2, root_r), (-tip_frac / 2, tip_r),
                     (tip_frac / 2, tip_r), (base_frac / 2, root_r)):
            loop.append((r * math.cos(c + a * pitch), r * math.sin(c + a * pitch)))
    return loop


# ---- the parts

def bolt():
    """One shell: hex head (16 across flats, 7 high), 10 mm shank with a chamfered tip.
    The shank points along +z, so the head's top faces -z."""
    m = Mesh("bolt")
    m.begin_shell()
    head, shank = fit_loops(hexagon(16), circle(5.0, 48))
    tip = [(0.84 * u, 0.84 * v) for u, v in shank]
    fan_ok(head)
    fan_ok(tip)
    head_top = add_loop(m, head, 0.0)
    add_cap(m, head_top, 0.0, up=False)
    head_bottom = add_loop(m, head, 7.0)
    add_wall(m, head_top, head_bottom)
    shank_top = add_loop(m, shank, 7.0)
    add_band(m, head, shank, head_bottom, shank_top, up=True)
    shank_end = add_loop(m, shank, 36.2)
    tip_ring = add_loop(m, tip, 37.0)
    add_wall(m, shank_top, shank_end)
    add_wall(m, shank_end, tip_ring)
    add_cap(m, tip_ring, 37.0, up=True)
    m.end_shell()
    return m


def nut():
    m = Mesh("nut")
    prism_with_hole(m, hexagon(16), circle(5.25, 48, circumscribed=True), 0.0, 8.0)
    return m


def bracket():
    m = Mesh("bracket")
    # Flange in the plan (x, -z) made along +z, then stood up: plan y becomes -z.
    outline = [(-40.0, -12.0), (12.0, -12.0), (12.0, 12.0), (-40.0, 12.0)]
    hole = circle(5.25, 48, circumscribed=True)
    prism_with_hole(m, outline, hole, 0.0, 6.0)
    m.transform(y_up)
    leg = Mesh("leg")
    box(leg, (-40.0, -50.0, -12.0), (-34.0, 0.0, 12.0))
    merge(m, leg)
    return m


def merge(into, other):
    base = len(into.vertices)
    into.vertices += other.vertices
    first = len(into.triangles)
    into.triangles += [(a + base, b + base, c + base) for a, b, c in other.triangles]
    into.shells += [[s + first, e + first] for s, e in other.shells]


SPLINE = dict(root=8.5, major=10.0, width=5.0, keys=6)
BORE = dict(root=8.75, major=10.25, width=5.5, keys=6)


def splined_shaft():
    """One shell: a 30 mm collar (z = 0..10) and the splines above it, their top
    chamfered 0.8 mm."""
    m = Mesh("splined_shaft")
    m.begin_shell()
    collar, spline = fit_loops(circle(15.0, 64), spline_profile(**SPLINE))
    chamfer = [(0.92 * u, 0.92 * v) for u, v in spline]
    fan_ok(collar)
    fan_ok(chamfer)
    c0 = add_loop(m, collar, 0.0)
    add_cap(m, c0, 0.0, up=False)
    c1 = add_loop(m, collar, 10.0)
    add_wall(m, c0, c1)
    s0 = add_loop(m, spline, 10.0)
    add_band(m, collar, spline, c1, s0, up=True)
    s1 = add_loop(m, spline, 49.2)
    s2 = add_loop(m, chamfer, 50.0)
    add_wall(m, s0, s1)
    add_wall(m, s1, s2)
    add_cap(m, s2, 50.0, up=True)
    m.end_shell()
    return m


def splined_gear():
    m = Mesh("splined_gear")
    prism_with_hole(m, gear_profile(24, 26.875, 32.5),
                    spline_profile(**BORE), 0.0, 12.0)
    return m


def studs(mesh, centres, z0, radius=2.4, height=1.7, sides=24):
    for cx, cy in centres:
        ring = [(cx + u, cy + v) for u, v in circle(radius, sides)]
        mesh.begin_shell()
        bottom = [mesh.vertex((u, v, z0)) for u, v in ring]
        top = [mesh.vertex((u, v, z0 + height)) for u, v in ring]
        cb = mesh.vertex((cx, cy, z0))
        ct = mesh.vertex((cx, cy, z0 + height))
        for k in range(sides):
            a, b = (k, (k + 1) % sides)
            mesh.tri(cb, bottom[b], bottom[a])
            mesh.tri(ct, top[a], top[b])
            mesh.quad(bottom[a], bottom[b], top[b], top[a])
        mesh.end_shell()


def brick_2x4():
    """Outer 31.8 x 15.8 x 9.6 with a cavity open at the bottom (walls 1.2, top 1.0):
    the studs of the brick below (8 mm pitch) fit inside with 0.3 mm to the walls."""
    m = Mesh("brick_2x4")
    m.begin_shell()
    hx, hy, h = 15.9, 7.9, 9.6
    ix, iy, ih = 14.7, 6.7, 8.6
    o = [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
    i = [(-ix, -iy), (ix, -iy), (ix, iy), (-ix, iy)]
    ob = add_loop(m, o, 0.0)
    ot = add_loop(m, o, h)
    ib = add_loop(m, i, 0.0)
    it = add_loop(m, i, ih)
    add_wall(m, ob, ot)                      # outer sides
    m.quad(*ot)                              # top, facing +z
    add_wall(m, ib, it, outward=False)       # cavity sides, facing the cavity
    m.quad(it[0], it[3], it[2], it[1])       # cavity ceiling, facing -z
    for k in range(4):                       # bottom rim, facing -z
        a, b = k, (k + 1) % 4
        m.quad(ob[a], ib[a], ib[b], ob[b])
    m.end_shell()
    studs(m, [(x, y) for x in (-12.0, -4.0, 4.0, 12.0) for y in (-4.0, 4.0)], h)
    m.transform(y_up)
    return m


def baseplate():
    m = Mesh("baseplate")
    box(m, (-23.9, -15.9, 0.0), (23.9, 15.9, 3.2))
    studs(m, [(x, y) for x in (-20.0, -12.0, -4.0, 4.0, 12.0, 20.0)
              for y in (-12.0, -4.0, 4.0, 12.0)], 3.2)
    m.transform(y_up)
    return m


def piston_rod():
    """A 93 mm piston (its crown's edge chamfered) and a rod 18 x 12 running into a
    big-end eye, as shells of one part: they come out of a cylinder together."""
    m = Mesh("piston_rod")
    solid_loft(m, [(circle(45.5, 96), 0.0), (circle(46.5, 96), 1.0),
                   (circle(46.5, 96), 80.0)])
    box(m, (-9.0, -6.0, 80.0), (9.0, 6.0, 232.0))
    eye = Mesh("eye")
    prism_with_hole(eye, circle(26.0, 48), circle(15.0, 48), -8.0, 8.0)
    # Its axis along y: swapping y and z mirrors, so the triangles are turned back.
    eye.transform(lambda p: (p[0], p[2], p[1]))
    eye.triangles = [(a, c, b) for a, b, c in eye.triangles]
    eye.transform(moved((0.0, 0.0, 256.0)))
    merge(m, eye)
    return m


# ---- checks and output

def check(mesh):
    for first, end in mesh.shells:
        edges = {}
        volume = 0.0
        for a, b, c in mesh.triangles[first:end]:
            assert len({a, b, c}) == 3, mesh.name + ": a triangle repeats a vertex"
            for e in ((a, b), (b, c), (c, a)):
                assert e not in edges, mesh.name + ": an edge is used twice the same way"
                edges[e] = True
            p, q, r = mesh.vertices[a], mesh.vertices[b], mesh.vertices[c]
            volume += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
                       p[2] * (q[0] * r[1] - q[1] * r[0])) / 6
        for a, b in edges:
            assert (b, a) in edges, mesh.name + ": a shell is not closed"
        assert volume > 0, mesh.name + ": a shell faces inward"
    assert sum(e - s for s, e in mesh.shells) == len(mesh.triangles), mesh.name + ": stray faces"
    assert len(mesh.triangles) < 20000


def fmt(x):
    s = "%.6f" % x
    s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def write(mesh, folder):
    check(mesh)
    path = os.path.join(folder, mesh.name + ".obj")
    with open(path, "w", newline="\n") as f:
        f.write("# %s: written by make_parts.py (millimetres); %d vertices, %d triangles\n"
                % (mesh.name, len(mesh.vertices), len(mesh.triangles)))
        f.write("o %s\n" % mesh.name)
        for p in mesh.vertices:
            f.write("v %s %s %s\n" % tuple(fmt(c) for c in p))
        for a, b, c in mesh.triangles:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
    print("%-22s %6d triangles, %d shell(s)" % (mesh.name + ".obj", len(mesh.triangles),
                                               len(mesh.shells)))


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    for make in (bolt, nut, bracket, splined_shaft, splined_gear, brick_2x4, baseplate,
                 piston_rod):
        write(make(), folder)


if __name__ == "__main__":
    main()
