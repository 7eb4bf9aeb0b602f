"""Writes scenes/hall-glossy.toml and scenes/hall-mirror.toml (issue 14): one procedural hall,
two floors. The scene format has no includes, so the shared geometry is written into both files
from here; edit this script, not the TOML files, and rerun:

    python3 tools/scenes/make_hall.py scenes
"""
import sys

from floor_materials import floor_materials


def hall(kind):
    glossy = kind == "glossy"
    out = []
    w = out.append
    if glossy:
        w('''# A procedural hall with a glossy floor and a camera fly-through (issue 14): the model is
# Voorhuis' SponzaGlossyFloor (seed 001, section 3.2), built from boxes so it needs no data. A
# nave 10 m wide, 24 m long and 6 m high: two arcades of seven columns under long lintels,
# coloured panels on the side walls and the back wall so that reflections have structure, and
# four area lights set into the ceiling along the nave. The floor is a glossy layer over a
# diffuse one (hardness 0.3: Blinn-Phong exponent 308, about a Beckmann roughness of 0.08),
# so it shows blurred reflections of the columns, the panels and the lights.
# scenes/hall-mirror.toml is the same hall with a mirror floor and a mirror orb.
#
#     render scenes/hall-glossy.toml --frames 0..120 --spp 1 -o 'hall/f_{frame:03}.png'
#     render scenes/hall-glossy.toml --camera fixed --frames 0..60 --spp 1 -o 'fixed/f_{frame:03}.png'
#
# Cameras: `main` flies down the nave in 5 s (120 frames at 24 fps); `fixed` stands still at
# the entrance (the fixed-camera 60-frame temporal-error measurement).
# Units: metres, +y up; keys are in seconds. The hall is closed: no environment light.
# Written by tools/scenes/make_hall.py (edit that, not this file).
''')
    else:
        w('''# A procedural hall with a mirror floor and a mirror orb (issue 14): the model is Voorhuis'
# SponzaPureSpeculars (seed 001, section 3.2). The hall is that of scenes/hall-glossy.toml (the
# scene format has no includes: one script writes both files, see the end of this comment): a
# nave 10 m wide, 24 m long and 6 m high, two arcades of seven columns under long lintels,
# coloured panels on the walls and four area lights in the ceiling. The floor is a perfect
# mirror (hardness 1) and a mirror orb 1.8 m across stands in the nave, left of the camera's
# path, so every pixel of the floor and the orb is a pure specular reflection.
#
#     render scenes/hall-mirror.toml --frames 0..120 --spp 1 -o 'hall/f_{frame:03}.png'
#     render scenes/hall-mirror.toml --camera fixed --frames 0..60 --spp 1 -o 'fixed/f_{frame:03}.png'
#
# Cameras: `main` flies down the nave in 5 s (120 frames at 24 fps); `fixed` stands still at
# the entrance (the fixed-camera 60-frame temporal-error measurement).
# Units: metres, +y up; keys are in seconds. The hall is closed: no environment light.
# Written by tools/scenes/make_hall.py (edit that, not this file).
''')
    w('''
[render]
spp = 4
max_depth = 6

[environment]
color = [0.0, 0.0, 0.0]

[[camera]]
name = "main"
position = [0.0, 1.7, 10.5]
look_at = [0.0, 1.4, 0.0]
fov = 60.0
resolution = [256, 256]

[[camera]]
name = "fixed"
position = [0.3, 2.2, 11.2]
look_at = [-0.3, 1.2, -4.0]
fov = 60.0
resolution = [256, 256]

# The fly-through: down the nave right of centre, then a turn towards the left-hand arcade.
[[animation]]
target = "main"
keys = [ { time = 0.0, position = [0.0, 1.7, 10.5], look_at = [0.0, 1.4, 0.0] },
         { time = 2.5, position = [1.0, 1.6, 3.0], look_at = [0.0, 1.3, -6.0] },
         { time = 5.0, position = [0.8, 1.7, -5.5], look_at = [-3.0, 1.2, -9.0] } ]
''')
    w('''
# --- Materials --------------------------------------------------------------------------------''')
    w(floor_materials(kind))
    w('''
[[material]]
name = "stone"
color = [0.7, 0.66, 0.6]

[[material]]
name = "column"
color = [0.78, 0.74, 0.68]

[[material]]
name = "red"
color = [0.7, 0.1, 0.08]

[[material]]
name = "blue"
color = [0.1, 0.2, 0.65]

[[material]]
name = "green"
color = [0.12, 0.5, 0.15]

[[material]]
name = "gold"
color = [0.8, 0.6, 0.15]

[[material]]
name = "lamp"
color = [0.0, 0.0, 0.0]
emission = [14.0, 13.0, 11.5]

# --- The shell: x in [-5, 5], y in [0, 6], z in [-12, 12]; walls and ceiling are boxes 0.3 m
# thick outside that volume, so there are no cracks at the corners ----------------------------
[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-5, 0, 12], [5, 0, 12], [5, 0, -12], [-5, 0, -12]]   # counter-clockwise from above
material = "floor"

[[geometry]]
name = "wall-left"
shape = "box"
min = [-5.3, 0.0, -12.3]
max = [-5.0, 6.3, 12.3]
material = "stone"

[[geometry]]
name = "wall-right"
shape = "box"
min = [5.0, 0.0, -12.3]
max = [5.3, 6.3, 12.3]
material = "stone"

[[geometry]]
name = "wall-back"
shape = "box"
min = [-5.3, 0.0, -12.3]
max = [5.3, 6.3, -12.0]
material = "stone"

[[geometry]]
name = "wall-front"
shape = "box"
min = [-5.3, 0.0, 12.0]
max = [5.3, 6.3, 12.3]
material = "stone"

[[geometry]]
name = "ceiling"
shape = "box"
min = [-5.3, 6.0, -12.3]
max = [5.3, 6.3, 12.3]
material = "stone"

# The ceiling lights: four panels 1.6 m x 2.4 m along the nave, 1 cm below the ceiling,
# facing down (corners counter-clockwise seen from below).
''')
    for i, z in enumerate([-9.0, -3.0, 3.0, 9.0]):
        z0, z1 = z - 1.2, z + 1.2
        w(f'''[[geometry]]
name = "light-{i + 1}"
shape = "quad"
vertices = [[-0.8, 5.99, {z0}], [0.8, 5.99, {z0}], [0.8, 5.99, {z1}], [-0.8, 5.99, {z1}]]
material = "lamp"

''')
    w('''# --- The arcades: a column prototype (a plinth-wide shaft) placed fourteen times, two lintels
# and a cornice along each side ------------------------------------------------------------
[[geometry]]
name = "column"
shape = "box"
min = [-0.25, 0.0, -0.25]
max = [0.25, 4.0, 0.25]
material = "column"

[[geometry]]
name = "plinth"
shape = "box"
min = [-0.4, 0.0, -0.4]
max = [0.4, 0.3, 0.4]
material = "stone"

''')
    for side, x in (("l", -2.8), ("r", 2.8)):
        for j, z in enumerate(range(-9, 10, 3)):
            w(f'''[[instance]]
name = "column-{side}{j + 1}"
geometry = "column"
transform = {{ translate = [{x}, 0, {z}] }}

[[instance]]
name = "plinth-{side}{j + 1}"
geometry = "plinth"
transform = {{ translate = [{x}, 0, {z}] }}

''')
    w('''[[geometry]]
name = "lintel-left"
shape = "box"
min = [-3.1, 4.0, -9.4]
max = [-2.5, 4.7, 9.4]
material = "column"

[[geometry]]
name = "lintel-right"
shape = "box"
min = [2.5, 4.0, -9.4]
max = [3.1, 4.7, 9.4]
material = "column"

# Arches between the columns: stepped blocks under the lintels, tallest at the columns (three
# steps on each side of each opening, instances of one block scaled in height).
[[geometry]]
name = "arch-step"
shape = "box"
min = [-0.3, 0.0, -0.25]
max = [0.3, 0.25, 0.25]
material = "column"

''')
    k = 0
    for x in (-2.8, 2.8):
        for z in range(-9, 9, 3):
            for s, (dz, y, h) in enumerate([(0.45, 3.25, 3), (0.7, 3.5, 2), (0.95, 3.75, 1)]):
                for zz in (z + dz, z + 3 - dz):
                    k += 1
                    w(f'''[[instance]]
name = "arch-{k}"
geometry = "arch-step"
transform = {{ translate = [{x}, {y}, {zz:.2f}], scale = [1, {h}, 1] }}

''')
    w('''# --- Coloured panels on the side walls (between the columns) and a tapestry on the back wall
''')
    cols = ["red", "blue", "green", "gold"]
    n = 0
    for x0, x1 in ((-4.99, -4.9), (4.9, 4.99)):
        for j, z in enumerate([-7.5, -1.5, 4.5]):
            n += 1
            c = cols[(n) % 4]
            w(f'''[[geometry]]
name = "panel-{n}"
shape = "box"
min = [{x0}, 0.8, {z - 1.0}]
max = [{x1}, 3.4, {z + 1.0}]
material = "{c}"

''')
    w('''[[geometry]]
name = "tapestry"
shape = "box"
min = [-2.0, 1.0, -11.99]
max = [2.0, 4.2, -11.9]
material = "red"

[[geometry]]
name = "tapestry-band"
shape = "box"
min = [-2.0, 2.3, -11.9]
max = [2.0, 2.7, -11.85]
material = "gold"
''')
    if not glossy:
        w('''
# --- The mirror orb, left of the fly-through's path --------------------------------------------
[[geometry]]
name = "orb"
shape = "sphere"
center = [-1.3, 0.9, -2.5]
radius = 0.9
subdivisions = 4
material = "orb"
''')
    return "".join(out)

open(sys.argv[1] + "/hall-glossy.toml", "w").write(hall("glossy"))
open(sys.argv[1] + "/hall-mirror.toml", "w").write(hall("mirror"))
