"""Writes scenes/shared-data/sponza-glossy.toml and sponza-mirror.toml (issue 14): Sponza from
../shared/data with a glossy or mirror floor. Edit this script, not the TOML files, and rerun:

    python3 tools/scenes/make_sponza.py scenes/shared-data
"""
import sys

from floor_materials import floor_materials


def sponza(kind):
    glossy = kind=="glossy"
    o=[]; w=o.append
    if glossy:
        w('''# Sponza with a glossy floor and a camera fly-through (issue 14): Voorhuis' SponzaGlossyFloor
# (seed 001, section 3.2) on Marko Dabrovic's Sponza atrium (66,454 triangles; see
# ../../../shared/data/README.md: no origin or licence is given with the file). The mesh is read
# from the shared data folder next to the repository, not copied here; without it this scene
# does not load (scenes/hall-glossy.toml is the procedural stand-in). The OBJ has no materials:
# every surface is one warm stone, except the ground floor, which [[assign]] makes glossy (its
# eight triangles are 10686..10693 of the file, in the group `floors`). The atrium is lit
# through its open roof by a sky panel just above it.
# sponza-mirror.toml is the same with a mirror floor and a mirror orb.
#
#     render scenes/shared-data/sponza-glossy.toml --frames 0..120 --spp 1 -o 'sponza/f_{frame:03}.png'
#     render scenes/shared-data/sponza-glossy.toml --camera fixed --frames 0..60 --spp 1 -o 'fixed/f_{frame:03}.png'
#
# Cameras: `main` flies along the atrium in 5 s; `fixed` stands still at its east end.
# Units: the file's, about metres (the atrium is 23 m long), +y up; keys are in seconds.
# Written by tools/scenes/make_sponza.py (edit that, not this file).
''')
    else:
        w('''# Sponza with a mirror floor and a mirror orb (issue 14): Voorhuis' SponzaPureSpeculars (seed
# 001, section 3.2) on Marko Dabrovic's Sponza atrium (66,454 triangles; see
# ../../../shared/data/README.md: no origin or licence is given with the file). The mesh is read
# from the shared data folder next to the repository, not copied here; without it this scene
# does not load (scenes/hall-mirror.toml is the procedural stand-in). The OBJ has no materials:
# every surface is one warm stone, except the ground floor, which [[assign]] makes a mirror (its
# eight triangles are 10686..10693 of the file, in the group `floors`), and a mirror orb stands
# in the atrium beside the camera's path. The atrium is lit through its open roof by a sky
# panel just above it. sponza-glossy.toml is the same with a glossy floor and no orb.
#
#     render scenes/shared-data/sponza-mirror.toml --frames 0..120 --spp 1 -o 'sponza/f_{frame:03}.png'
#     render scenes/shared-data/sponza-mirror.toml --camera fixed --frames 0..60 --spp 1 -o 'fixed/f_{frame:03}.png'
#
# Cameras: `main` flies along the atrium in 5 s; `fixed` stands still at its east end.
# Units: the file's, about metres (the atrium is 23 m long), +y up; keys are in seconds.
# Written by tools/scenes/make_sponza.py (edit that, not this file).
''')
    w('''
[render]
spp = 4
max_depth = 6

[environment]
color = [0.0, 0.0, 0.0]

[[camera]]
name = "main"
position = [10.0, 1.8, 0.8]
look_at = [0.0, 2.5, 0.0]
fov = 65.0
resolution = [256, 256]

[[camera]]
name = "fixed"
position = [10.5, 2.2, -1.0]
look_at = [-4.0, 2.0, 0.5]
fov = 65.0
resolution = [256, 256]

# The fly-through: along the atrium from its east end, then a turn towards the south arcade.
[[animation]]
target = "main"
keys = [ { time = 0.0, position = [10.0, 1.8, 0.8], look_at = [0.0, 2.5, 0.0] },
         { time = 2.5, position = [3.0, 2.0, 1.2], look_at = [-6.0, 2.8, 0.0] },
         { time = 5.0, position = [-5.0, 2.2, 0.6], look_at = [-11.5, 1.2, -1.5] } ]

[[material]]
name = "stone"
color = [0.7, 0.66, 0.6]
''')
    w(floor_materials(kind))
    w('''
[[material]]
name = "sky"
color = [0.0, 0.0, 0.0]
emission = [9.0, 9.5, 10.5]

[[geometry]]
name = "sponza"
file = "../../../shared/data/scenes/sponza-dabrovic/sponza.obj"
material = "stone"

# The ground floor (y = 0.09, x in [-16.2, 16.2], z in [-7.2, 7.2]): triangles 10686..10693.
[[assign]]
geometry = "sponza"
triangles = [10686, 10694]
material = "floor"

# The sky: a panel over the open roof (y 15.7), larger than the opening, facing down.
[[geometry]]
name = "sky"
shape = "quad"
vertices = [[-12.5, 16.0, -4.0], [12.5, 16.0, -4.0], [12.5, 16.0, 4.0], [-12.5, 16.0, 4.0]]
material = "sky"
''')
    if not glossy:
        w('''
# The mirror orb, south of the fly-through's path.
[[geometry]]
name = "orb"
shape = "sphere"
center = [0.5, 1.2, -1.6]
radius = 1.1
subdivisions = 4
material = "orb"
''')
    return "".join(o)
d=sys.argv[1]
open(d+"/sponza-glossy.toml","w").write(sponza("glossy"))
open(d+"/sponza-mirror.toml","w").write(sponza("mirror"))
