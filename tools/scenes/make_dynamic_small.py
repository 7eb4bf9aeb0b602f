"""Writes scenes/dynamic-small.toml (issue 14): the orbit and the bounce are sampled into keys
here (keys interpolate linearly). Edit this script, not the TOML file, and rerun:

    python3 tools/scenes/make_dynamic_small.py scenes/dynamic-small.toml
"""
import math, sys
out=[]; w=out.append
w('''# A small dynamic scene for real-time path tracing (issue 14; seed 002's kind of scene: a
# Cornell-box-like living room of about 1,700 triangles with rigidly moving objects). A room
# 6 m square and 3 m high with a red and a green wall, a ceiling lamp and a small wall lamp;
# a box slides to and fro, a tall block turns about its axis, a ball bounces (a parabola
# sampled every 1/8 s; keys interpolate linearly), and the camera orbits the room's centre
# once in 8 s. Every moving object is an animated geometry, so `clusters` (the default for a
# moving scene) only updates its top level per frame. Meant for `render view` and
# `--frame-budget` at 256x256 and 1 spp:
#
#     render scenes/dynamic-small.toml --frames 0..192 --spp 1 -o 'dyn/f_{frame:03}.png'
#
# Cameras: `main` orbits (radius 2.5 m, eye height 1.5 m); `fixed` stands in a corner.
# Units: metres, +y up; keys are in seconds.
# Written by tools/scenes/make_dynamic_small.py (edit that, not this file).

[render]
spp = 1
max_depth = 4

[environment]
color = [0.0, 0.0, 0.0]

[[camera]]
name = "main"
position = [0.0, 1.5, 2.5]
look_at = [0.0, 0.5, 0.0]
fov = 65.0
resolution = [256, 256]

[[camera]]
name = "fixed"
position = [2.6, 2.0, 2.6]
look_at = [-0.2, 0.4, -0.2]
fov = 60.0
resolution = [256, 256]

''')
keys=[]
for i in range(17):
    t=i*0.5; a=2*math.pi*i/16
    keys.append(f"{{ time = {t}, position = [{2.5*math.sin(a):.4f}, 1.5, {2.5*math.cos(a):.4f}] }}")
w('''# The orbit: 16 chords of the circle of radius 2.5 m around the y axis, counter-clockwise seen
# from above, looking at the room's centre.
[[animation]]
target = "main"
keys = [ ''' + ",\n         ".join(keys) + " ]\n")
w('''
[[material]]
name = "white"
color = [0.73, 0.73, 0.7]

[[material]]
name = "red"
color = [0.63, 0.065, 0.05]

[[material]]
name = "green"
color = [0.14, 0.45, 0.091]

[[material]]
name = "floor"
color = [0.55, 0.45, 0.35]

[[material]]
name = "orange"
color = [0.8, 0.4, 0.1]

[[material]]
name = "blue"
color = [0.15, 0.3, 0.7]

[[material]]
name = "glossy-white"
type = "plastic"
color = [0.7, 0.7, 0.68]
hardness = 0.8

[[material]]
name = "lamp"
color = [0.0, 0.0, 0.0]
emission = [15.0, 14.0, 12.0]

[[material]]
name = "wall-lamp"
color = [0.0, 0.0, 0.0]
emission = [6.0, 5.0, 3.5]

# --- The room: x and z in [-3, 3], y in [0, 3]; walls are boxes outside it --------------------
[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]]
material = "floor"

[[geometry]]
name = "ceiling"
shape = "box"
min = [-3.2, 3.0, -3.2]
max = [3.2, 3.2, 3.2]
material = "white"

[[geometry]]
name = "wall-left"
shape = "box"
min = [-3.2, 0.0, -3.2]
max = [-3.0, 3.2, 3.2]
material = "red"

[[geometry]]
name = "wall-right"
shape = "box"
min = [3.0, 0.0, -3.2]
max = [3.2, 3.2, 3.2]
material = "green"

[[geometry]]
name = "wall-back"
shape = "box"
min = [-3.2, 0.0, -3.2]
max = [3.2, 3.2, -3.0]
material = "white"

[[geometry]]
name = "wall-front"
shape = "box"
min = [-3.2, 0.0, 3.0]
max = [3.2, 3.2, 3.2]
material = "white"

# The ceiling lamp: 1.2 m square, facing down; the wall lamp: a small panel on the back wall,
# facing the room (+z).
[[geometry]]
name = "lamp"
shape = "quad"
vertices = [[-0.6, 2.99, -0.6], [0.6, 2.99, -0.6], [0.6, 2.99, 0.6], [-0.6, 2.99, 0.6]]
material = "lamp"

[[geometry]]
name = "wall-lamp"
shape = "quad"
vertices = [[-0.3, 1.6, -2.99], [0.3, 1.6, -2.99], [0.3, 2.0, -2.99], [-0.3, 2.0, -2.99]]
material = "wall-lamp"

# --- Static furniture along the walls ---------------------------------------------------------
[[geometry]]
name = "sideboard"
shape = "box"
min = [-2.0, 0.0, -2.95]
max = [-0.6, 0.8, -2.45]
material = "glossy-white"

[[geometry]]
name = "bench"
shape = "box"
min = [2.45, 0.0, -1.0]
max = [2.95, 0.45, 1.5]
material = "blue"

# --- The moving objects -----------------------------------------------------------------------
# A box that slides to and fro along x in front of the centre (4 s there and back, twice).
[[geometry]]
name = "slider"
shape = "box"
min = [-0.3, 0.0, -0.3]
max = [0.3, 0.5, 0.3]
material = "orange"

[[animation]]
target = "slider"
keys = [ { time = 0.0, translate = [-1.0, 0, 0.9] }, { time = 2.0, translate = [1.0, 0, 0.9] },
         { time = 4.0, translate = [-1.0, 0, 0.9] }, { time = 6.0, translate = [1.0, 0, 0.9] },
         { time = 8.0, translate = [-1.0, 0, 0.9] } ]

# A tall block that turns about its vertical axis, a quarter turn a second.
[[geometry]]
name = "spinner"
shape = "box"
min = [-0.2, 0.0, -0.35]
max = [0.2, 1.2, 0.35]
material = "white"

''')
keys=[f"{{ time = {t}.0, translate = [0.9, 0, -0.8], rotate = [0, {90*t}, 0] }}" for t in range(9)]
w('''[[animation]]
target = "spinner"
keys = [ ''' + ",\n         ".join(keys) + " ]\n")
w('''
# A ball that bounces, 1 s per bounce up to 0.8 m, drifting along z and back.
[[geometry]]
name = "ball"
shape = "sphere"
center = [0.0, 0.25, 0.0]
radius = 0.25
subdivisions = 3
material = "glossy-white"

''')
keys=[]
for i in range(65):
    t=i*0.125; ph=(t%1.0)
    y=0.8*4*ph*(1-ph)
    z=-0.6+0.5*math.sin(2*math.pi*t/8)
    keys.append(f"{{ time = {t}, translate = [-0.9, {y:.4f}, {z:.4f}] }}")
w('''[[animation]]
target = "ball"
keys = [ ''' + ",\n         ".join(keys) + " ]\n")
open(sys.argv[1],'w').write("".join(out))
